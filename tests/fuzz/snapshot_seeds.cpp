// Writes the seed corpus of fuzz_snapshot (tests/fuzz/corpus/fuzz_snapshot/): valid snapshots
// of small piles in 2D and 3D, each after the input's first byte (fuzz_snapshot.cpp), which asks
// for mutations to be resealed.
//   build/bin/snapshot_seeds tests/fuzz/corpus/fuzz_snapshot
#include "snapshot_worlds.hpp"

#include <cstdio>
#include <memory>
#include <string>

namespace {
template <int D, class World>
bool write_seed(const std::string& dir, const char* name, const statsim::WorldDef<D>& def, std::uint32_t bodies,
                int steps)
{
  auto w = std::make_unique<World>();
  if (!statsim::fuzz::build_seed_world<D>(*w, def, bodies, steps)) return false;
  static unsigned char buf[16384];
  buf[0] = (D == 2 ? 1 : 0) | 8;  // 8: the fuzzer reseals mutations (fuzz_snapshot.cpp)
  std::size_t n = 0;
  if (statsim::save(*w, buf + 1, sizeof buf - 1, &n) != statsim::Status::ok) return false;
  std::FILE* f = std::fopen((dir + "/" + name).c_str(), "wb");
  if (f == nullptr) return false;
  const bool ok = std::fwrite(buf, 1, n + 1, f) == n + 1;
  return std::fclose(f) == 0 && ok;
}
}  // namespace

int main(int argc, char** argv)
{
  using namespace statsim;
  if (argc != 2) {
    std::fprintf(stderr, "usage: snapshot_seeds DIR\n");
    return 2;
  }
  const std::string dir = argv[1];
  // Every value of the options that change the format's bytes: the defaults (automatic body
  // contacts, islands), hulls asked for with each sleep rule, collision spheres.
  WorldDef3 d3;
  WorldDef3 islands;
  islands.body_contacts = BodyContacts::hulls;
  islands.broad_phase = BroadPhase::grid;
  WorldDef3 hulls = islands;
  hulls.sleep_islands = false;
  WorldDef3 spheres;
  spheres.body_contacts = BodyContacts::collision_spheres;
  WorldDef2 d2;
  WorldDef2 hulls2;
  hulls2.body_contacts = BodyContacts::hulls;
  const bool ok = write_seed<3, fuzz::SnapWorld3>(dir, "seed_3d", d3, 30, 60) &&
                  write_seed<3, fuzz::SnapWorld3>(dir, "seed_3d_hulls_grid", hulls, 30, 150) &&
                  write_seed<3, fuzz::SnapWorld3>(dir, "seed_3d_islands", islands, 30, 150) &&
                  write_seed<3, fuzz::SnapWorld3>(dir, "seed_3d_small", spheres, 5, 20) &&
                  write_seed<2, fuzz::SnapWorld2>(dir, "seed_2d", d2, 30, 60) &&
                  write_seed<2, fuzz::SnapWorld2>(dir, "seed_2d_hulls", hulls2, 30, 150);
  if (!ok) std::fprintf(stderr, "snapshot_seeds: failed\n");
  return ok ? 0 : 1;
}
