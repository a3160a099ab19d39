#include <doctest/doctest.h>

#include "statsim/random.hpp"

#include <cmath>

using statsim::Pcg32;

TEST_CASE("pcg32: same seed and stream give the same sequence - streams differ")
{
  Pcg32 a(42, 7), b(42, 7), c(42, 8), d(43, 7);
  int same_c = 0, same_d = 0;
  for (int i = 0; i < 1000; ++i) {
    const std::uint32_t x = a.next_u32();
    CHECK(x == b.next_u32());
    same_c += x == c.next_u32();
    same_d += x == d.next_u32();
  }
  CHECK(same_c < 3);
  CHECK(same_d < 3);
}

TEST_CASE("pcg32: matches the reference implementations first outputs")
{
  // pcg32_srandom_r(&rng, 42u, 54u) from the PCG reference (pcg32-demo): first six outputs.
  Pcg32 g(42, 54);
  const std::uint32_t expected[] = {0xa15c02b7u, 0x7b47f409u, 0xba1d3330u, 0x83d2f293u, 0xbfa4784bu, 0xcbed606eu};
  for (std::uint32_t e : expected) CHECK(g.next_u32() == e);
}

TEST_CASE("pcg32: resume continues a saved stream")
{
  Pcg32 g(1, 2);
  for (int i = 0; i < 10; ++i) g.next_u32();
  Pcg32 r = Pcg32::resume(g.state(), 2);
  for (int i = 0; i < 10; ++i) CHECK(g.next_u32() == r.next_u32());
}

TEST_CASE("uniform lies in the unit interval with mean 1/2")
{
  Pcg32 g(3, 4);
  double sum = 0;
  const int n = 200000;
  for (int i = 0; i < n; ++i) {
    const float u = g.uniform();
    REQUIRE(u >= 0.0f);
    REQUIRE(u < 1.0f);
    sum += u;
  }
  CHECK(sum / n == doctest::Approx(0.5).epsilon(0.005));
}

TEST_CASE("gaussian has mean 0 - variance 1 and normal tails")
{
  Pcg32 g(5, 6);
  const int n = 400000;
  double s1 = 0, s2 = 0, s4 = 0;
  int beyond2 = 0;
  for (int i = 0; i < n; ++i) {
    const double x = g.gaussian();
    s1 += x;
    s2 += x * x;
    s4 += x * x * x * x;
    beyond2 += std::fabs(x) > 2.0;
  }
  const double mean = s1 / n, var = s2 / n - mean * mean;
  // Standard errors: mean 1/sqrt(n) = 0.0016, variance sqrt(2/n) = 0.0022, fourth moment ~0.007.
  CHECK(std::fabs(mean) < 0.008);
  CHECK(std::fabs(var - 1.0) < 0.011);
  CHECK(std::fabs(s4 / n - 3.0) < 0.05);
  CHECK(double(beyond2) / n == doctest::Approx(0.0455).epsilon(0.05));
  Pcg32 h(5, 6);
  CHECK(h.gaussian(10.0f, 2.0f) == doctest::Approx(10.0 + 2.0 * Pcg32(5, 6).gaussian()));
}

TEST_CASE("portable_log agrees with std::log")
{
  for (float x : {1e-30f, 1e-7f, 0.001f, 0.3f, 0.70710677f, 0.99999f, 1.0f, 1.41421f, 2.0f, 3.14159f, 1e5f, 3e38f}) {
    const double ref = std::log(double(x));
    CHECK(statsim::detail::portable_log(x) == doctest::Approx(ref).epsilon(1e-6).scale(1.0));
  }
}

TEST_CASE("body streams are distinct per body and per seed")
{
  CHECK(statsim::body_stream(1, 0) != statsim::body_stream(1, 1));
  CHECK(statsim::body_stream(1, 0) != statsim::body_stream(2, 0));
  CHECK(statsim::body_stream(9, 3) == statsim::body_stream(9, 3));
}
