// `statsim compare-tables` (tools/ref3d/compare.hpp): a table against itself scaled by 1 is at
// distance 0 in every quantity; against itself at another size, the lengths are off by the
// factor and the scale-free quantities are not; the runtime's scaled view of a table is the
// table scaled, quantity by quantity.
#include "ref3d/compare.hpp"
#include "statsim/signature_scale.hpp"
#include "tables/box.hpp"
#include "tables/bunny.hpp"

#include <doctest/doctest.h>

#include <stdexcept>

using namespace statsim;
using namespace statsim::tools;

TEST_CASE("compare-tables: a table against itself scaled by 1 is at distance 0 in every quantity")
{
  for (const SignatureView<3>& sig : {tables::box.view(), tables::bunny.view()}) {
    const TableComparison c = compare_tables(sig, sig, 1.0);
    REQUIRE(c.quantities.size() >= 20u);
    for (const QuantityDistance& q : c.quantities) {
      CAPTURE(q.name);
      CHECK(q.count > 0);
      CHECK(q.mean == 0.0);
      CHECK(q.max == 0.0);
    }
    REQUIRE(c.find("support map") != nullptr);
    CHECK(c.find("support map")->count == int(sig.contact.support_count()));
  }
}

TEST_CASE("compare-tables: the table against itself at twice the size: lengths off, scale-free quantities not")
{
  const SignatureView<3> sig = tables::bunny.view();
  const TableComparison c = compare_tables(sig, sig, 2.0);
  CHECK(c.find("mass")->max == doctest::Approx(1.0 - 1.0 / 8.0));
  CHECK(c.find("length L")->max == doctest::Approx(0.5));
  CHECK(c.find("h_coll")->mean > 1.0);
  CHECK(c.find("rest heights")->mean == doctest::Approx(0.5));
  CHECK(c.find("support map")->mean > 0.1);
  CHECK(c.find("response (all)")->max == 0.0);
  CHECK(c.find("rest frequencies")->max == 0.0);
}

TEST_CASE("compare-tables: the runtime's scaled view is the table scaled by s, quantity by quantity")
{
  const SignatureView<3> sig = tables::bunny.view();
  for (const double s : {0.1, 10.0}) {
    CAPTURE(s);
    const TableComparison c = compare_tables(sig, scaled_view(sig, Scalar(s)), s);
    for (const QuantityDistance& q : c.quantities) {
      CAPTURE(q.name);
      CHECK(q.max < 1e-5);  // float rounding of the products only
    }
    // Without the factor the comparison sees it.
    CHECK(compare_tables(sig, scaled_view(sig, Scalar(s)), 1.0).find("h_coll")->mean > 1.0);
  }
}

TEST_CASE("compare-tables: tables gathered with other axes are refused")
{
  SignatureView<3> fewer = tables::box.view();
  fewer.height.spin_ratio.size -= 1;
  CHECK_THROWS_AS(compare_tables(tables::box.view(), fewer, 1.0), std::invalid_argument);
  SignatureView<3> other = tables::box.view();
  other.response.axes[2].size -= 1;
  CHECK_THROWS_AS(compare_tables(tables::box.view(), other, 1.0), std::invalid_argument);
  CHECK_THROWS_AS(compare_tables(tables::box.view(), tables::box.view(), 0.0), std::invalid_argument);
}
