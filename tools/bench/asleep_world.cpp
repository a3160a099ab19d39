// The asleep world of tools/bench/README.md (target bench_asleep_world, build/bin): thread
// CPU time per step of a world of 10,000 bunnies that are all asleep (added asleep in a lattice on
// the ground), 1,000 steps, sweep-and-prune and the grid.
#include "statsim/world3.hpp"
#include "tables/bunny.hpp"
#include <cstdio>
#include <ctime>
#include <memory>
using namespace statsim;
static double cpu_ms()
{
  timespec t;
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return double(t.tv_sec) * 1e3 + double(t.tv_nsec) * 1e-6;
}
int main()
{
  for (int g = 0; g < 2; ++g) {
    WorldDef3 d;
    d.broad_phase = g ? BroadPhase::grid : BroadPhase::sweep_and_prune;
    d.body_contacts = BodyContacts::hulls;
    auto w = std::make_unique<World<3, 16384, 8, 16384 * 32, 2>>(d);
    const ShapeId s = w->add_shape(tables::bunny.view()).id;
    (void)w->add_plane(Vector3::UnitZ(), 0);
    for (int i = 0; i < 10000; ++i) {
      BodyDef3 b;
      b.shape = s;
      b.mass = 1.6f;
      b.position = Vector3(0.34f * float(i % 100), 0.34f * float(i / 100 % 100), 0.2f);
      b.asleep = true;
      if (!w->add_body(b).ok()) return 1;
    }
    for (int k = 0; k < 10; ++k) (void)w->step(1.0f / 60);
    const double t0 = cpu_ms();
    for (int k = 0; k < 1000; ++k) (void)w->step(1.0f / 60);
    const double t1 = cpu_ms();
    std::printf("%s: %zu asleep, %.3f us per step\n", g ? "grid" : "sap", std::size_t(w->count(MotionState::asleep)),
                (t1 - t0) * 1e3 / 1000);
  }
}
