// Paper Figure 7: one bunny dropped twice from the same state, without and with resting
// conditions (paper 3.4). Without them it stops in whatever orientation it has, on a sphere of
// radius h_coll, so it floats above the floor; with them it turns into a rest pose and settles at
// that pose's h_rest.
//   rest_conditions [--seed S] [--frames FILE.csv] [--frames-without FILE.csv]
//     --frames          frames of the run with resting conditions
//     --frames-without  frames of the run without them
#include "demo.hpp"
#include "tables/bunny.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace {
statsim::World3<1> worlds[2];
}

int main(int argc, char** argv)
{
  demo::Options o;
  const char* frames_without = nullptr;
  for (int i = 1; i + 1 < argc; ++i)
    if (!std::strcmp(argv[i], "--frames-without")) {
      frames_without = argv[i + 1];
      for (int j = i; j + 2 < argc; ++j) argv[j] = argv[j + 2];  // drop the pair before demo::parse
      argc -= 2;
      break;
    }
  const char* usage = "rest_conditions [--seed S] [--frames FILE.csv] [--frames-without FILE.csv]";
  if (!demo::parse(argc, argv, o, usage)) return 2;
  if (o.spheres) {  // one body: nothing touches it, so --spheres would change nothing
    std::fprintf(stderr, "usage: %s\n", usage);
    return 2;
  }
  const statsim::SignatureView<3> sig = statsim::tables::bunny.view();
  for (int k = 0; k < 2; ++k) {
    statsim::WorldDef3 def;
    def.seed = o.seed;
    def.rest_conditions = k == 1;
    statsim::World3<1>& w = worlds[k];
    // One bunny on the cylinder's axis at 0.6 m.
    statsim::ShapeId shape{};
    if (!demo::drop("rest_conditions", w, def, sig, {1, 0.0f, 0.6f, 0.0f}, 7, shape)) return 1;
    int steps = 0;
    demo::Options run = o;
    run.steps = 60 * 30;
    if (k == 0) run.frames = frames_without;
    if (demo::run(w, run, steps) < 0) return 1;
    const statsim::Body3& b = w.body(0);
    const statsim::Vector3 up = b.orientation.conjugate() * statsim::Vector3(0, 0, 1);  // world up in the body frame
    const std::uint32_t pose = statsim::nearest_rest_pose<3>(sig, b.orientation, statsim::Vector3(0, 0, 1));
    const float off = std::acos(std::min(1.0f, (b.orientation * sig.rest.normal(pose)).z())) * 57.29578f;
    std::printf("%s resting conditions: asleep %s after %.2f s; up in body frame (%+.3f %+.3f %+.3f), %.1f deg from "
                "rest pose %u; centre height %.4f m (pose h_rest %.4f m, collision radius %.4f m)\n",
                k ? "with   " : "without", b.state == statsim::MotionState::asleep ? "yes" : "no", double(steps) / 60,
                double(up.x()), double(up.y()), double(up.z()), double(off), pose, double(b.position.z()),
                double(sig.rest.heights[pose]), double(b.radius));
  }
  return 0;
}
