// See gather2d_body_contacts.hpp.
#include "ref2d/gather2d_body_contacts.hpp"

#include "common/parallel.hpp"
#include "common/progress.hpp"
#include "common/support_map.hpp"
#include "common/table_contact_shape.hpp"
#include "ref2d/compare2d.hpp"
#include "ref2d/gather2d.hpp"
#include "ref2d/pairs2d.hpp"

#include <algorithm>
#include <chrono>

namespace statsim::tools {

// 4. Body-body data (statsim::ContactView): pair distance, support map, hull edges, packing.
void body_contacts_experiment(const Gather2dContext& ctx, Gather2dResult& r)
{
  const Gather2dOptions& o = r.options;
  const Shape2& sh = ctx.shape;
  BodyContactData& c = r.contact;
  c.dims = 2;
  // The body frame is the input's frame moved to its centroid, unrotated: R = I, c = offset.
  c.mesh_frame = {1, 0, 0, 1, sh.offset.x, sh.offset.y};

  const auto t0 = std::chrono::steady_clock::now();
  const PairDistances2d pd = pair_distances2d(sh, o.height_ratios, o.pair_trials, o.height_speed, o.seed, o.threads);
  c.pair_mean = pd.mean;
  c.pair_std = pd.std;
  c.pair_flights = pd.flights;
  c.pair_seconds = seconds_since(t0);

  std::vector<Eigen::Vector2d> hull;
  for (const Point2& p : sh.hull) hull.emplace_back(p.x, p.y);
  const SupportMap2 map = SupportMap2::build(hull, o.support_size);
  c.support_size = o.support_size;
  c.support = map.values;
  c.support_bound = map.error_bound(hull);
  // Hull edges (counter-clockwise), longest first; equal lengths in the hull's order.
  std::vector<std::pair<double, Eigen::Vector3d>> edges;
  for (std::size_t k = 0; k < hull.size(); ++k) {
    const Eigen::Vector2d d = hull[(k + 1) % hull.size()] - hull[k];
    const Eigen::Vector2d n = Eigen::Vector2d(d.y(), -d.x()).normalized();
    edges.emplace_back(d.norm(), Eigen::Vector3d(n.x(), n.y(), support(hull, n)));
  }
  std::stable_sort(edges.begin(), edges.end(), [](const auto& x, const auto& y) { return x.first > y.first; });
  c.hull_faces = static_cast<int>(edges.size());
  const std::size_t k = std::min(edges.size(), static_cast<std::size_t>(o.contact_faces));
  // The packing ratio of each edge (its last number) is measured below; 1 until then.
  for (std::size_t i = 0; i < k; ++i)
    c.faces.insert(c.faces.end(), {edges[i].second.x(), edges[i].second.y(), edges[i].second.z(), 1.0});

  // The table's own body-body data, as the runtime reads it from the header being written.
  const TableContactShape<2> table(c, false);

  // Packing: the piles of `statsim compare2d` with this table's material.
  const auto t1 = std::chrono::steady_clock::now();
  statsim::SignatureView<2> material{};
  material.material = ctx.material;
  material.restitution_threshold = ctx.threshold;
  c.piles = o.packing_piles;
  std::vector<std::vector<Pile2dContact>> piles(static_cast<std::size_t>(c.piles));
  std::vector<char> asleep(piles.size(), 0);
  parallel_for(
      piles.size(),
      [&](std::size_t i) {
        bool all = false;
        piles[i] = box2d_pile_contacts(sh, material, o.packing_count, o.packing_steps, i + 1, all);
        asleep[i] = all ? 1 : 0;
      },
      o.threads);
  std::vector<PackingSample> samples;
  for (std::size_t i = 0; i < piles.size(); ++i) {
    c.asleep += asleep[i];
    c.pile_steps += o.packing_steps;
    for (const Pile2dContact& pc : piles[i]) {
      statsim::Body<2> a{}, b{};
      a.orientation = statsim::Rot2::from_angle(static_cast<statsim::Scalar>(pc.angle_a));
      b.orientation = statsim::Rot2::from_angle(static_cast<statsim::Scalar>(pc.angle_b));
      samples.push_back(packing_sample(table.shape(), a, b, Eigen::Vector2d(pc.cb - pc.ca)));
    }
  }
  packing_statistics(samples, c);
  c.packing_seconds = seconds_since(t1);
}

}  // namespace statsim::tools
