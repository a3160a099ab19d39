#include <doctest/doctest.h>

#include "statsim/world2.hpp"
#include "statsim/world3.hpp"

#include <cstring>

using namespace statsim;

TEST_CASE("sphere-plane contact: normal is the planes - depth is the overlap")
{
  const Plane<3> ground{Vector3(0, 0, 1), 0};
  Contact<3> c;
  CHECK(sphere_plane_contact<3>(Vector3(1, 2, 0.25f), 0.5f, ground, c));
  CHECK(c.normal == Vector3(0, 0, 1));
  CHECK(c.depth == doctest::Approx(0.25));
  CHECK_FALSE(sphere_plane_contact<3>(Vector3(0, 0, 0.5f), 0.5f, ground, c));  // touching is not overlap
  CHECK_FALSE(sphere_plane_contact<3>(Vector3(0, 0, 0.6f), 0.5f, ground, c));
  // Behind the plane entirely: still a contact, so nothing tunnels through a plane.
  CHECK(sphere_plane_contact<3>(Vector3(0, 0, -3), 0.5f, ground, c));
  CHECK(c.depth == doctest::Approx(3.5));
  const Vector3 n = Vector3(1, 1, 0).normalized();
  const Plane<3> wall{n, 2};
  CHECK(sphere_plane_contact<3>(n * 2.1f, 0.3f, wall, c));
  CHECK(c.depth == doctest::Approx(0.2).epsilon(1e-5));
  const Plane<2> line{Vector2(0, 1), 1};
  Contact<2> c2;
  CHECK(sphere_plane_contact<2>(Vector2(5, 1.5f), 1, line, c2));
  CHECK(c2.depth == doctest::Approx(0.5));
}

TEST_CASE("sphere-sphere contact: normal from a to b on the line of centres - depth is the overlap")
{
  Contact<3> c;
  CHECK(sphere_sphere_contact<3>(Vector3(0, 0, 0), 1, Vector3(1.5f, 0, 0), 1, c));
  CHECK(c.normal.isApprox(Vector3(1, 0, 0)));
  CHECK(c.depth == doctest::Approx(0.5));
  CHECK(sphere_sphere_contact<3>(Vector3(1, 1, 1), 0.5f, Vector3(1, 1.6f, 1.8f), 0.6f, c));
  CHECK(c.normal.isApprox(Vector3(0, 0.6f, 0.8f)));
  CHECK(c.depth == doctest::Approx(0.1).epsilon(1e-4));
  CHECK_FALSE(sphere_sphere_contact<3>(Vector3(0, 0, 0), 1, Vector3(2, 0, 0), 1, c));
  // Coincident centres: defined, deterministic normal (world up).
  CHECK(sphere_sphere_contact<3>(Vector3(1, 2, 3), 1, Vector3(1, 2, 3), 1, c));
  CHECK(c.normal == Vector3(0, 0, 1));
  CHECK(c.depth == doctest::Approx(2));
  Contact<2> c2;
  CHECK(sphere_sphere_contact<2>(Vector2(0, 0), 1, Vector2(0, 0), 2, c2));
  CHECK(c2.normal == Vector2(0, 1));
}

namespace {
template <int D>
typename Space<D>::Vec random_vec(Pcg32& g, float scale)
{
  typename Space<D>::Vec v;
  for (int i = 0; i < D; ++i) v[i] = g.uniform(-scale, scale);
  return v;
}
template <int D>
typename Space<D>::Spin random_spin(Pcg32& g, float scale);
template <>
Vector3 random_spin<3>(Pcg32& g, float scale)
{
  return random_vec<3>(g, scale);
}
template <>
float random_spin<2>(Pcg32& g, float scale)
{
  return g.uniform(-scale, scale);
}

template <int D>
void check_energy_never_increases()
{
  Pcg32 g(77, D);
  int responded = 0;
  for (int trial = 0; trial < 10000; ++trial) {
    typename Space<D>::Vec va = random_vec<D>(g, 5), vb = random_vec<D>(g, 5);
    typename Space<D>::Spin wa = random_spin<D>(g, 30), wb = random_spin<D>(g, 30);
    const float ma = g.uniform(0.1f, 10), mb = trial % 4 == 0 ? 1e30f : g.uniform(0.1f, 10);
    const float ra = g.uniform(0.05f, 1), rb = g.uniform(0.05f, 1);
    typename Space<D>::Vec n = random_vec<D>(g, 1);
    if (n.norm() < 1e-3f) continue;
    n.normalize();
    Material m;
    m.restitution = g.uniform(0, 1);
    m.friction = g.uniform(0, 2);
    const double before = double(kinetic_energy<D>(va, wa, ma, ra)) + (mb < 1e29f ? kinetic_energy<D>(vb, wb, mb, rb) : 0);
    const float imb = mb < 1e29f ? 1 / mb : 0;
    if (imb == 0) {
      vb.setZero();
      wb = Space<D>::zero_spin();
    }
    const bool hit = particle_response<D>({va, wa, 1 / ma, ra}, {vb, wb, imb, rb}, n, m, 0.1f);
    responded += hit;
    const double after = double(kinetic_energy<D>(va, wa, ma, ra)) + (imb > 0 ? kinetic_energy<D>(vb, wb, mb, rb) : 0);
    REQUIRE(after <= before * (1 + 1e-5) + 1e-9);
    if (hit) {
      // After the impulse the bodies no longer approach along the normal.
      const typename Space<D>::Vec u = (vb + detail::cross(wb, typename Space<D>::Vec(n * -rb))) - (va + detail::cross(wa, typename Space<D>::Vec(n * ra)));
      REQUIRE(u.dot(n) >= -1e-4f * (1 + va.norm() + vb.norm()));
    }
  }
  CHECK(responded > 2500);
}
}  // namespace

TEST_CASE("a particle collision never increases kinetic energy (2D and 3D - body-body and body-static)")
{
  check_energy_never_increases<3>();
  check_energy_never_increases<2>();
}

TEST_CASE("particle response against a plane: restitution on the normal - friction bounded by Coulomb")
{
  Material m;
  m.restitution = 0.5f;
  m.friction = 0.2f;
  m.rolling_resistance = 0;
  Vector3 v(1, 0, -4), w = Vector3::Zero();
  CHECK(particle_plane_response<3>(v, w, 0.5f, Vector3(0, 0, 1), m, 0.1f));
  CHECK(v.z() == doctest::Approx(2.0));
  // Normal impulse per unit mass is 6 m/s, so friction removes at most 0.2 * 6 = 1.2 m/s of slip,
  // but sticking needs only 1 * k / (1 + k) = 2/7 m/s for a solid sphere.
  CHECK(v.x() == doctest::Approx(1.0 - 2.0 / 7.0));
  CHECK(w.y() * 0.5f == doctest::Approx(v.x()));  // rolls without slipping: w r = v_t
  // Below the restitution threshold the contact is inelastic.
  Vector3 slow(0, 0, -0.05f), ws = Vector3::Zero();
  CHECK(particle_plane_response<3>(slow, ws, 0.5f, Vector3(0, 0, 1), m, 0.1f));
  CHECK(slow.z() == doctest::Approx(0.0));
  // Separating bodies are left alone.
  Vector3 up(0, 0, 1), wu = Vector3::Zero();
  CHECK_FALSE(particle_plane_response<3>(up, wu, 0.5f, Vector3(0, 0, 1), m, 0.1f));
  CHECK(up == Vector3(0, 0, 1));
  // Rolling resistance slows a rolling body: both its speed and spin shrink by one factor.
  m.rolling_resistance = 0.1f;
  Vector3 roll(1, 0, -0.05f), wr(0, 2, 0);  // rolling without slip at r = 0.5
  CHECK(particle_plane_response<3>(roll, wr, 0.5f, Vector3(0, 0, 1), m, 0.1f));
  CHECK(roll.x() == doctest::Approx(1.0 - 0.1 * 0.05));
  CHECK(wr.y() * 0.5f == doctest::Approx(roll.x()));
}

namespace {
template <class T>
bool same_bits(const T& x, const T& y)
{
  return std::memcmp(&x, &y, sizeof(T)) == 0;
}

/// particle_point_response against particle_response with both radii 0 on random contacts:
/// velocities, spins, the result and the return value equal bit for bit.
template <int D>
void check_point_response_bits(std::uint64_t seed)
{
  using Vec = typename Space<D>::Vec;
  using Spin = typename Space<D>::Spin;
  Pcg32 g(seed, 3);
  const auto vec = [&g](float s) {
    Vec v;
    for (int k = 0; k < D; ++k) v[k] = g.uniform(-s, s);
    return v;
  };
  const auto spin = [&g]() {
    if constexpr (D == 3) {
      const float x = g.uniform(-9, 9), y = g.uniform(-9, 9), z = g.uniform(-9, 9);
      return Spin(x, y, z);
    } else {
      return Spin(g.uniform(-9, 9));
    }
  };
  int applied = 0;
  for (int i = 0; i < 20000; ++i) {
    Vec va = vec(4), vb = vec(4);
    Spin wa = spin(), wb = spin();
    const Vec n = vec(1).normalized();
    // Some sides static, some materials without friction or rolling resistance.
    const Scalar ima = i % 7 == 0 ? Scalar(0) : g.uniform(0.01f, 3);
    const Scalar imb = i % 11 == 0 ? Scalar(0) : g.uniform(0.01f, 3);
    Material m;
    m.restitution = g.uniform(0, 1);
    m.friction = i % 5 == 0 ? Scalar(0) : g.uniform(0, 1.5f);
    m.rolling_resistance = i % 3 == 0 ? Scalar(0) : g.uniform(0, 0.3f);
    const Scalar threshold = g.uniform(0, 2);
    Vec va2 = va, vb2 = vb;
    Spin wa2 = wa, wb2 = wb;
    const bool r1 = particle_response<D>({va, wa, ima, 0}, {vb, wb, imb, 0}, n, m, threshold);
    const bool r2 = particle_point_response<D>({va2, wa2, ima, 0}, {vb2, wb2, imb, 0}, n, m, threshold);
    REQUIRE(r1 == r2);
    REQUIRE(same_bits(va, va2));
    REQUIRE(same_bits(vb, vb2));
    REQUIRE(same_bits(wa, wa2));
    REQUIRE(same_bits(wb, wb2));
    applied += r1;
  }
  CHECK(applied > 5000);  // the contacts do approach: the impulse path is exercised
}
}  // namespace

TEST_CASE("particle_point_response is bit for bit particle_response with both radii 0 (2D and 3D)")
{
  check_point_response_bits<2>(41);
  check_point_response_bits<3>(42);
}
