// query_bench: the cost of statsim's queries (statsim/queries.hpp) through the broad phase's
// records against testing every body slot (`detail::*_scan`), in one run, in a world of 10,000
// spheres dropped on the ground. See tools/bench/README.md ("Queries").
//
//   query_bench [--bodies N] [--rays N] [--repeat R] [--settle STEPS]
//
// Prints, for the grid and for sweep-and-prune: microseconds for the rays (nearest hit, a
// picking ray down onto the pile) and for as many sphere overlaps, searched and scanned, the
// least of R repeats, and the bodies each query examined.
#include "statsim/queries.hpp"
#include "statsim/random.hpp"
#include "statsim/world3.hpp"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <functional>
#include <memory>
#include <vector>

using namespace statsim;

namespace {

constexpr std::uint32_t kMaxBodies = 10000;
using BigWorld = World3<kMaxBodies>;

struct Query {
  Vector3 origin, direction;
};

double min_us(int repeat, const std::function<void()>& f)
{
  double best = 1e300;
  for (int r = 0; r < repeat; ++r) {
    const auto t0 = std::chrono::steady_clock::now();
    f();
    const double us = std::chrono::duration<double, std::micro>(std::chrono::steady_clock::now() - t0).count();
    best = std::min(best, us);
  }
  return best;
}

}  // namespace

int main(int argc, char** argv)
{
  std::uint32_t bodies = kMaxBodies;
  int rays = 1000, repeat = 5, settle = 180;
  for (int i = 1; i + 1 < argc; i += 2) {
    const char* v = argv[i + 1];
    if (!std::strcmp(argv[i], "--bodies")) bodies = std::min<std::uint32_t>(kMaxBodies, std::uint32_t(std::atoi(v)));
    else if (!std::strcmp(argv[i], "--rays")) rays = std::atoi(v);
    else if (!std::strcmp(argv[i], "--repeat")) repeat = std::atoi(v);
    else if (!std::strcmp(argv[i], "--settle")) settle = std::atoi(v);
    else {
      std::fprintf(stderr, "usage: query_bench [--bodies N] [--rays N] [--repeat R] [--settle STEPS]\n");
      return 2;
    }
  }
  // Spheres of 5 cm in a 10 m square, dropped from up to 2 m: a pile one or two bodies deep.
  const float half = 5.0f;
  Pcg32 g(42, 1);
  std::vector<Query> queries(static_cast<std::size_t>(rays));
  for (Query& q : queries) {
    q.origin = Vector3(g.uniform(-1.2f * half, 1.2f * half), g.uniform(-1.2f * half, 1.2f * half), 3);
    q.direction = Vector3(g.uniform(-0.3f, 0.3f), g.uniform(-0.3f, 0.3f), -1);
  }
  std::printf("%u spheres, %d rays (length 5 m, down onto the pile) and %d overlaps (radius 0.2 m), least of %d\n",
              bodies, rays, rays, repeat);
  std::printf("%-16s %12s %12s %8s %14s %14s\n", "broad phase", "search us", "scan us", "ratio", "examined/query",
              "any scanned");
  for (const BroadPhase phase : {BroadPhase::grid, BroadPhase::sweep_and_prune}) {
    WorldDef3 def;
    def.broad_phase = phase;
    auto w = std::make_unique<BigWorld>(def);
    if (!w->add_plane(Vector3(0, 0, 1), 0).ok()) return 1;
    ShapeDef ball;
    ball.radius = 0.05f;
    BodyDef3 bd;
    bd.shape = w->add_shape(ball).id;
    Pcg32 place(7, 3);
    for (std::uint32_t i = 0; i < bodies; ++i) {
      bd.position = Vector3(place.uniform(-half, half), place.uniform(-half, half), place.uniform(0.05f, 2.0f));
      if (!w->add_body(bd).ok()) return 1;
    }
    for (int s = 0; s < settle; ++s)
      if (w->step(1.0f / 60).status != Status::ok) return 1;
    for (const bool overlap : {false, true}) {
      QueryStats st;
      std::uint64_t sink = 0;
      const double search = min_us(repeat, [&] {
        st = QueryStats{};
        for (const Query& q : queries) {
          if (overlap) {
            (void)overlap_sphere(*w, Vector3(q.origin - Vector3(0, 0, 2.9f)), 0.2f,
                                 [&sink](const QueryHit<3>& h) { return sink += h.body, true; }, &st);
          } else {
            QueryHit<3> h;
            (void)ray_cast(*w, q.origin, q.direction, 5, h, &st);
            sink += h.body;
          }
        }
      });
      const double scan = min_us(repeat, [&] {
        QueryStats s2;
        for (const Query& q : queries) {
          if (overlap) {
            detail::overlap_sphere_scan(detail::CoreAccess::data(*w), Vector3(q.origin - Vector3(0, 0, 2.9f)), 0.2f,
                                        [&sink](const QueryHit<3>& h) { return sink += h.body, true; }, s2);
          } else {
            QueryHit<3> best;
            detail::ray_cast_all_scan(detail::CoreAccess::data(*w), q.origin, Vector3(q.direction.normalized()), 5,
                                      [&best](const QueryHit<3>& h) {
                                        if (!best.hit() || h.distance < best.distance) best = h;
                                        return true;
                                      },
                                      s2);
            sink += best.body;
          }
        }
      });
      std::printf("%-16s %12.0f %12.0f %8.1f %14.1f %14s   %s\n",
                  phase == BroadPhase::grid ? "grid" : "sweep-and-prune", search, scan, scan / search,
                  double(st.bodies_examined) / double(rays), st.scanned ? "some" : "none",
                  overlap ? "overlaps" : "rays");
      volatile std::uint64_t keep = sink;  // the hits are used: nothing is optimised away
      (void)keep;
    }
  }
  return 0;
}
