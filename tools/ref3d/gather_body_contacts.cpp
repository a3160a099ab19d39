// See gather_body_contacts.hpp.
#include "ref3d/gather_body_contacts.hpp"

#include "common/parallel.hpp"
#include "common/progress.hpp"
#include "common/support_map.hpp"
#include "common/table_contact_shape.hpp"
#include "ref3d/gather.hpp"
#include "ref3d/pairs.hpp"

#include <algorithm>
#include <chrono>

namespace statsim::tools::ref3d {

void gather_body_contacts(GatherResult& r)
{
  const GatherOptions& o = r.options;
  const ShapeModel& m = r.model;
  BodyContactData& c = r.contact;
  c.dims = 3;
  // Body point = R (mesh point - com), R = the principal axes' transpose: R's rows are the axes.
  const Eigen::Matrix3d& axes = m.mass.principal_axes;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) c.mesh_frame.push_back(axes(j, i));
  for (int i = 0; i < 3; ++i) c.mesh_frame.push_back(m.mass.com[i]);

  const auto t0 = std::chrono::steady_clock::now();
  const PairDistances pd =
      pair_distances(m, o.height_ratios, o.pair_trials, o.speed, o.reference.margin, o.seed, o.threads, o.progress);
  c.pair_mean = pd.mean;
  c.pair_std = pd.std;
  c.pair_flights = pd.flights;
  c.pair_seconds = seconds_since(t0);

  const SupportMap3 map = SupportMap3::build(m.hull, o.support_size);
  c.support_size = o.support_size;
  c.support = map.values;
  c.support_bound = map.error_bound(m.hull);
  const std::vector<Eigen::Vector3d> normals = faces_by_area(m);
  const std::vector<double> offsets = face_offsets(m, normals);
  c.hull_faces = static_cast<int>(normals.size());
  const std::size_t k = std::min(normals.size(), static_cast<std::size_t>(o.contact_faces));
  // The packing ratio of each face (its last number) is measured below; 1 until then.
  for (std::size_t i = 0; i < k; ++i)
    c.faces.insert(c.faces.end(), {normals[i].x(), normals[i].y(), normals[i].z(), offsets[i], 1.0});

  // The table's own body-body data, as the runtime reads it from the header being written.
  const TableContactShape<3> table(c, o.i16);

  // Packing: the reference piles and bins, then d / estimate by angle bin.
  const auto t1 = std::chrono::steady_clock::now();
  PairOptions drop;
  drop.shape = o;
  drop.pile_count = o.packing_count;
  PairOptions bin = drop;
  bin.bin = kPackingBinHalfWidth;
  c.piles = o.packing_piles;
  c.bins = o.packing_bins;
  const std::size_t runs = static_cast<std::size_t>(c.piles + c.bins);
  std::vector<ReferencePile> piles(runs);
  Progress progress("packing piles", runs, o.progress);
  parallel_for(
      runs,
      [&](std::size_t i) {
        const bool is_bin = i >= static_cast<std::size_t>(c.piles);
        const std::uint64_t seed = is_bin ? i - static_cast<std::size_t>(c.piles) + 1 : i + 1;
        piles[i] = reference_pile(m, is_bin ? bin : drop, seed);
        progress.add(1);
      },
      o.threads);
  progress.finish();
  std::vector<PackingSample> samples;
  for (const ReferencePile& p : piles) {
    c.asleep += p.asleep ? 1 : 0;
    c.pile_steps += p.steps;
    for (const PileContact& pc : p.contacts) {
      Body<3> a{}, b{};
      a.orientation = pc.a.orientation.cast<Scalar>().normalized();
      b.orientation = pc.b.orientation.cast<Scalar>().normalized();
      samples.push_back(packing_sample(table.shape(), a, b, Eigen::Vector3d(pc.b.position - pc.a.position)));
    }
  }
  packing_statistics(samples, c);
  c.packing_seconds = seconds_since(t1);
}

}  // namespace statsim::tools::ref3d
