// libFuzzer target: the runtime's public API driven by arbitrary call sequences, in 2D and 3D.
//
// The first byte picks the dimension and the broad phase; then each call is one opcode byte and
// its arguments (see fuzz_input.hpp for how numbers are read): configure, add_shape (sphere or
// one of the committed signatures), add_plane, add_body, set_velocity, set_transform, step.
// Checked after every call:
//  - a call that fails changes nothing (state_hash and the counts are unchanged);
//  - a step with a bad dt is rejected with invalid_time_step and changes nothing;
//  - while every accepted call used ordinary values (no NaN, infinity or huge magnitude: see
//    Input::special), every body stays finite after every step.
// The world is small (16 bodies, 4 planes, 24 pairs) so capacity limits and pair overflow are hit.
#include "fuzz_input.hpp"

#include "scenes/synthetic_signatures.hpp"
#include "statsim/world2.hpp"
#include "statsim/world3.hpp"
#include "tables/box.hpp"
#include "tables/bunny.hpp"
#include "tables/lshape.hpp"
#include "tables/lshape2d.hpp"
#include "tables/square2d.hpp"

#include <cstddef>
#include <cstdint>
#ifdef STATSIM_FUZZ_TRACE
#include <cstdio>
#endif

namespace statsim::fuzz {
namespace {

template <int D>
typename Space<D>::Vec vec(Input& in, float scale)
{
  typename Space<D>::Vec v;
  for (int k = 0; k < D; ++k) v[k] = in.value(scale);
  return v;
}

Quaternion rot(Input& in, Space<3>)
{
  // Mostly unit (normalised here), sometimes as read (zero, non-unit, non-finite).
  Quaternion q(in.value(1), in.value(1), in.value(1), in.value(1));
  if (in.below(4) != 0 && q.coeffs().squaredNorm() > 1e-6f) q.normalize();
  return q;
}
Rot2 rot(Input& in, Space<2>)
{
  Rot2 r{in.value(1), in.value(1)};
  const float n2 = r.c * r.c + r.s * r.s;
  if (in.below(4) != 0 && n2 > 1e-6f) {
    const float n = std::sqrt(n2);
    r = Rot2{r.c / n, r.s / n};
  }
  return r;
}

Vector3 spin(Input& in, Space<3>, float scale) { return vec<3>(in, scale); }
Scalar spin(Input& in, Space<2>, float scale) { return in.value(scale); }

SignatureView<3> table(std::uint32_t k, Space<3>)
{
  switch (k % 4) {
    case 0: return tables::bunny.view();
    case 1: return tables::box.view();
    case 2: return tables::lshape.view();
    default: return testing::cube_synthetic.view();
  }
}
SignatureView<2> table(std::uint32_t k, Space<2>)
{
  switch (k % 3) {
    case 0: return tables::square2d.view();
    case 1: return tables::lshape2d.view();
    default: return testing::square2d_synthetic.view();
  }
}

template <int D>
bool body_finite(const Body<D>& b)
{
  return detail::finite(b.position) && detail::finite(b.orientation) && detail::finite(b.linear_velocity) &&
         detail::finite(b.angular_velocity) && std::isfinite(b.radius);
}

template <int D>
void run(Input& in, BroadPhase broad_phase)
{
  using Vec = typename Space<D>::Vec;
  WorldDef<D> def;
  def.broad_phase = broad_phase;
  World<D, 16, 4, 24, 4> world(def);  // a few KB: fine on the stack

  bool ordinary = true;  // every accepted call used ordinary values
  for (int op = 0; op < 256 && !in.empty(); ++op) {
    const std::uint64_t before = world.state_hash();
    const std::uint32_t bodies = world.body_count(), planes = world.plane_count(), shapes = world.shape_count();
    in.clear_special();
    Status s = Status::ok;
    switch (in.below(8)) {
      case 0: {  // configure: a few parameters away from their defaults
        WorldDef<D> d = world.def();
        d.gravity = vec<D>(in, 20);
        d.restitution_threshold = in.value(2);
        d.sleep_speed = in.value(0.2f);
        d.sleep_time = in.value(2);
        d.linear_damping = in.value(2);
        d.allowed_overlap = in.value(0.6f);
        d.overlap_correction = in.value(1.2f);
        d.rest_turn_time = in.value(0.5f);
        d.support_iterations = int(in.below(10));
        d.pair_response = in.below(2) ? PairResponse::momentum : PairResponse::independent;
        d.nearest_radius = in.below(2) != 0;
        d.shock_propagation = in.below(2) != 0;
        s = world.configure(d);
        break;
      }
      case 1: {  // plain sphere shape
        ShapeDef sd;
        sd.radius = in.value(1);
        sd.bounding_radius = in.below(2) ? 0 : in.value(2);
        sd.material.restitution = in.value(1.2f);
        sd.material.friction = in.value(1.5f);
        sd.material.rolling_resistance = in.value(0.2f);
        s = world.add_shape(sd).status;
        break;
      }
      case 2: s = world.add_shape(table(in.below(8), Space<D>{})).status; break;
      case 3: s = world.add_plane(vec<D>(in, 1), in.value(10)).status; break;
      case 4:
      case 5: {
        BodyDef<D> b;
        b.position = vec<D>(in, 10);
        b.orientation = rot(in, Space<D>{});
        b.linear_velocity = vec<D>(in, 50);
        b.angular_velocity = spin(in, Space<D>{}, 200);
        b.shape = ShapeId(std::uint16_t(in.below(5)));
        b.mass = in.value(10);
        b.asleep = in.below(8) == 0;
        s = world.add_body(b).status;
        break;
      }
      case 6: {
        const BodyId id = in.below(20);
        if (in.below(2)) {
          const Vec v = vec<D>(in, 50);
          s = world.set_velocity(id, v, spin(in, Space<D>{}, 200));
        } else {
          const Vec x = vec<D>(in, 10);
          s = world.set_transform(id, x, rot(in, Space<D>{}));
        }
        break;
      }
      default: {
        const float dt = in.value(0.1f);
        const int steps = 1 + int(in.below(16));
        for (int k = 0; k < steps; ++k) {
          const StepResult r = world.step(dt);
          s = r.status;
          if (s != Status::ok) {
            if (s != Status::invalid_time_step) fail("step failed with an unexpected status");
            break;
          }
          if (ordinary && !in.special())
            for (std::uint32_t i = 0; i < world.body_count(); ++i)
              if (!body_finite(world.body(i))) fail("a body became non-finite from ordinary input");
        }
        break;
      }
    }
#ifdef STATSIM_FUZZ_TRACE
    std::printf("op %d: %s%s bodies %u planes %u shapes %u\n", op, to_string(s), in.special() ? " (special)" : "",
                world.body_count(), world.plane_count(), world.shape_count());
    for (std::uint32_t i = 0; i < world.body_count(); ++i) {
      const Body<D>& b = world.body(i);
      std::printf("  body %u x %g %g v %g %g r %g\n", i, double(b.position[0]), double(b.position[1]),
                  double(b.linear_velocity[0]), double(b.linear_velocity[1]), double(b.radius));
    }
#endif
    if (s != Status::ok) {
      if (world.state_hash() != before || world.body_count() != bodies || world.plane_count() != planes ||
          world.shape_count() != shapes)
        fail("a rejected call changed the world");
    } else if (in.special()) {
      ordinary = false;
    }
  }
}

}  // namespace
}  // namespace statsim::fuzz

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size)
{
  statsim::fuzz::Input in(data, size);
  const std::uint8_t mode = in.byte();
  const statsim::BroadPhase bp = (mode & 2) ? statsim::BroadPhase::sweep_and_prune : statsim::BroadPhase::grid;
  if (mode & 1) statsim::fuzz::run<2>(in, bp);
  else statsim::fuzz::run<3>(in, bp);
  return 0;
}
