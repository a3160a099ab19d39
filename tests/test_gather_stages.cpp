// The stages of `statsim gather` (3D) and `statsim gather2d` (2D), each called alone on a small
// made-up input with a known answer: the rest-pose stage, the response fit, the statistics and
// the table's own body-body data that both share. No reference engine runs here.
#include "common/body_contacts.hpp"
#include "common/sample_stats.hpp"
#include "common/stored_values.hpp"
#include "common/support_map.hpp"
#include "common/table_contact_shape.hpp"
#include "ref2d/polygon2d.hpp"
#include "ref2d/rest_poses2d.hpp"
#include "ref3d/gather_options.hpp"
#include "ref3d/gather_trials.hpp"
#include "ref3d/model.hpp"
#include "ref3d/response_fit.hpp"
#include "ref3d/rest_poses.hpp"

#include <doctest/doctest.h>

#include <cmath>
#include <vector>

using namespace statsim::tools;

TEST_CASE("gather stages: mean and sample standard deviation")
{
  const MeanStd s = mean_std(std::vector<double>{1.0, 2.0, 3.0, 6.0});
  CHECK(s.mean == 3.0);
  CHECK(s.std == doctest::Approx(std::sqrt(14.0 / 3.0)));
  CHECK(mean_std(std::vector<double>{5.0}).std == 0.0);
  CHECK(mean_std(std::vector<double>{}).mean == 0.0);
}

TEST_CASE("gather stages: stored values at 16 bits read back within their error")
{
  const std::vector<float> v = to_float({-0.0, 0.25, -1.5, 3.0});
  CHECK(!std::signbit(v[0]));  // a header never writes -0
  const Quantized q = quantize(v);
  REQUIRE(q.q.size() == v.size());
  for (std::size_t i = 0; i < v.size(); ++i)
    CHECK(std::fabs(q.offset + q.scale * static_cast<float>(q.q[i]) - v[i]) <= q.worst_error);
  CHECK(q.worst_error < 1e-4);
}

TEST_CASE("gather stages: 3D rest poses from given drops (a 0.2 m cube)")
{
  using namespace statsim::tools::ref3d;
  const ShapeModel m = make_box_model(Eigen::Vector3d(0.2, 0.2, 0.2), 1000.0);
  GatherOptions o;
  std::vector<DropTrial> drops;
  // 60 drops on the -z face, 30 on the -x face (tilted by up to 2 degrees), 10 not settled.
  for (int i = 0; i < 100; ++i) {
    DropTrial d;
    const double tilt = 0.03 * std::sin(i);
    d.up = i < 60 ? Eigen::Vector3d(tilt, 0, 1).normalized() : Eigen::Vector3d(1, tilt, 0).normalized();
    d.height = 0.1 + 0.001 * std::cos(i);
    d.time = 2.0;
    d.settled = i < 90;
    drops.push_back(d);
  }
  const RestPoseFit fit = fit_rest_poses(m, drops, o);
  CHECK(fit.settled == 90);
  CHECK(fit.unsettled == 10);
  CHECK(fit.mean_settle_time == 2.0);
  REQUIRE(fit.rest.size() == 2);
  CHECK(fit.rest_rare.empty());
  CHECK(fit.rest_families == 1);  // the cube's faces are one family
  CHECK(fit.rest[0].count == 60);
  CHECK(fit.rest[0].frequency == doctest::Approx(60.0 / 90.0));
  for (const RestPose& p : fit.rest) {
    CHECK(p.snapped);
    CHECK(p.height == doctest::Approx(0.1));  // the face's offset, not the measured mean
    CHECK(p.normal.cwiseAbs().maxCoeff() == doctest::Approx(1.0));
  }
  CHECK(fit.rest[0].normal.z() == doctest::Approx(1.0));
  CHECK(fit.rest[1].normal.x() == doctest::Approx(1.0));
}

TEST_CASE("gather stages: 3D response fit pools every cos phi at spin ratio 0")
{
  using namespace statsim::tools::ref3d;
  // 1 cos theta x 2 cos phi x 1 speed x spin ratios {0, 1}, 2 trials a cell: cell = ip * 2 + is.
  std::vector<ResponseTrial> all(8);
  for (std::size_t i = 0; i < all.size(); ++i) all[i].value = {static_cast<double>(i), 0, 0, 0, 0, 1.0};
  all[5].time_limited = true;
  all[6].max_penetration = 0.004;
  const ResponseFit fit = fit_responses(all, 2, 1, 2, 1, {0.0, 1.0});
  REQUIRE(fit.response_mean.size() == 4 * 6);
  REQUIRE(fit.cell_outcomes.size() == 4);
  // Spin 0 (cells 0 and 2): the trials of both phi, 0 1 4 5; spin 1: the cell's own.
  CHECK(fit.cell_outcomes[0].size() == 4);
  CHECK(fit.cell_outcomes[2].size() == 4);
  CHECK(fit.response_mean[0 * 6] == 2.5);
  CHECK(fit.response_mean[2 * 6] == 2.5);
  CHECK(fit.response_mean[1 * 6] == 2.5);  // trials 2 and 3
  CHECK(fit.response_mean[3 * 6] == 6.5);  // trials 6 and 7
  CHECK(fit.response_std[1 * 6] == doctest::Approx(std::sqrt(0.5)));
  CHECK(fit.response_std[0 * 6] == doctest::Approx(std::sqrt(17.0 / 3.0)));
  CHECK(fit.response_mean[3 * 6 + 5] == 1.0);
  CHECK(fit.response_std[3 * 6 + 5] == 0.0);
  CHECK(fit.response_trials == 8);
  CHECK(fit.time_limited == 1);
  CHECK(fit.max_penetration == 0.004);
}

TEST_CASE("gather stages: 2D rest poses from given drops (the unit square)")
{
  const Shape2 square = square_shape();
  Gather2dOptions o;
  std::vector<Point2> ups;
  std::vector<char> settled;
  // 30 drops on one side, 15 on the next (tilted by up to 2 degrees), 5 not settled.
  for (int i = 0; i < 50; ++i) {
    const double tilt = 0.03 * std::sin(i);
    ups.push_back(i < 30 ? Point2{tilt, 1.0} : Point2{1.0, tilt});
    const double n = std::hypot(ups.back().x, ups.back().y);
    ups.back() = {ups.back().x / n, ups.back().y / n};
    settled.push_back(i < 45 ? 1 : 0);
  }
  const RestPoses2d poses = cluster_rest_poses(square, ups, settled, o);
  REQUIRE(poses.clusters.size() == 2);
  CHECK(poses.dropped == 0.0);
  CHECK(poses.clusters[0].count == 30);
  CHECK(poses.clusters[0].frequency == doctest::Approx(30.0 / 50.0));  // of all drops
  for (const RestCluster& c : poses.clusters) {
    CHECK(c.kept);
    CHECK(c.snap_degrees >= 0.0);
    CHECK(c.height == doctest::Approx(0.5));
    CHECK(c.family == 0);  // the square's sides are one family
  }
  CHECK(poses.clusters[0].normal.y == doctest::Approx(1.0));
  CHECK(poses.clusters[1].normal.x == doctest::Approx(1.0));
}

namespace {

// A side-2a square's or cube's body-body data: support map and faces (normal, offset, packing 1).
template <int D>
BodyContactData cube_contact(double a)
{
  BodyContactData c;
  c.dims = D;
  c.support_size = 5;
  if constexpr (D == 3) {
    std::vector<Eigen::Vector3d> hull;
    for (int i = 0; i < 8; ++i) hull.emplace_back(i & 1 ? a : -a, i & 2 ? a : -a, i & 4 ? a : -a);
    c.support = SupportMap3::build(hull, c.support_size).values;
    for (int k = 0; k < 3; ++k)
      for (double s : {1.0, -1.0}) {
        Eigen::Vector3d n = Eigen::Vector3d::Zero();
        n[k] = s;
        c.faces.insert(c.faces.end(), {n.x(), n.y(), n.z(), a, 1.0});
      }
  } else {
    const std::vector<Eigen::Vector2d> hull = {{-a, -a}, {a, -a}, {a, a}, {-a, a}};
    c.support = SupportMap2::build(hull, c.support_size).values;
    for (const Eigen::Vector2d& n : {Eigen::Vector2d(1, 0), Eigen::Vector2d(0, 1), Eigen::Vector2d(-1, 0),
                                     Eigen::Vector2d(0, -1)})
      c.faces.insert(c.faces.end(), {n.x(), n.y(), a, 1.0});
  }
  return c;
}

template <int D>
void check_face_to_face_packing(bool i16)
{
  const double a = 0.1;
  const BodyContactData c = cube_contact<D>(a);
  const TableContactShape<D> table(c, i16);
  CHECK(table.shape().signature.contact.face_count == 2 * D);
  statsim::Body<D> x{}, y{};
  x.orientation = y.orientation = statsim::Space<D>::identity();
  // Face to face, side by side: d is exactly the hulls' distance, 2a.
  Eigen::Matrix<double, D, 1> ab = Eigen::Matrix<double, D, 1>::Zero();
  ab[0] = 2 * a;
  const PackingSample side = packing_sample(table.shape(), x, y, ab);
  CHECK(side.ratio == doctest::Approx(1.0).epsilon(1e-3));
  CHECK(side.up == 0.0);
  // Stacked: the line of centres is vertical.
  ab = Eigen::Matrix<double, D, 1>::Zero();
  ab[D - 1] = 2 * a;
  const PackingSample stacked = packing_sample(table.shape(), x, y, ab);
  CHECK(stacked.ratio == doctest::Approx(1.0).epsilon(1e-3));
  CHECK(stacked.up == 1.0);
  CHECK(packing_bin(stacked.up, 1.0) == 0);
}

}  // namespace

TEST_CASE("gather stages: the table's own body-body data and its packing samples, 2D and 3D")
{
  check_face_to_face_packing<2>(false);
  check_face_to_face_packing<3>(false);
  check_face_to_face_packing<3>(true);
}
