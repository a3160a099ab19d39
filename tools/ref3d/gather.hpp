// `statsim gather`: a shape's statistical signature (paper 3.2) measured with the 3D reference,
// and its C++ table (tables/NAME.hpp) and JSON dump.
//
// What is measured (all in the canonical frame of paper Figure 4a: normal +z, V- in the xz plane
// with a non-negative x component; statsim/signature.hpp and statsim/statistical.hpp read it):
// 1. h_coll: the centre-of-mass height above the plane at the first contact of the true geometry,
//    from the exact torque-free flight (no stepping): straight down at |v|, uniform random
//    orientation, uniform random spin axis, |w| = s |v| / L, L the bounding radius; the flight
//    starts with the centre at L above the plane (uniform orientation there makes the contact
//    phase uniform). Mean and sample standard deviation per spin-ratio sample s.
// 2. Responses: per cell (cos theta, cos phi, [|V-|,] s), `trials` impacts in Bullet without
//    gravity, each from a uniform random orientation at the exact first contact of its free
//    flight (V- = |V-| (sin theta, 0, -cos theta); W- at angle phi to V-, at a uniform random
//    azimuth about V-, except at cos theta = 1 where the azimuth is the one the runtime's frame
//    takes (W-'s tangential part along +x)), until the body leaves the ground for good.
//    Per cell: mean and std of W+ L / |V-| and (V_rigid+ - V_particle+) / |V-|, V_particle+ from
//    statsim::point_particle_velocity. At s = 0 phi does not matter, and the cells of all phi
//    share the statistics of all their trials.
// 3. Rest poses: `rest_drops` drops with gravity from random poses and velocities until the body
//    is still; body-frame up vectors clustered within `rest_tolerance_deg`. A body at rest stands
//    on a face of its convex hull, so a cluster's mean normal within 3 degrees of a hull face's
//    is replaced by the face's, and its height by the face's distance from the centre of mass:
//    the exact rest height of the true geometry standing on that face, which the runtime's
//    snapped orientation needs (the measured mean, in the JSON, is of bodies tilted by up to
//    the clustering angle). Clusters snapped to the same face are one pose. Which poses are kept
//    (common/rest_families.hpp): poses are grouped into families equivalent under the shape's
//    symmetry (hull faces with the same rest height, face area, face shape, centre projection,
//    moment of inertia about the up axis and hull vertex heights, within 1e-3 of the bounding
//    radius); every member of a family seen in more than `rest_min_frequency` of the settled
//    drops together is kept; then, while more than `rest_max_dropped` of the settled drops are
//    in poses not kept, the most frequent remaining family seen in at least 5 drops is kept too.
//    A hexagonal nut's six side faces, each rarer than the cut, are thus one family above it; a
//    shape's few rare poses of different kinds are kept while together they would be a visible
//    part of its rest-pose distribution (tools/ref3d/README.md has the measurements). The header
//    and the JSON give each pose's family and the dropped share.
#pragma once

#include "common/body_contacts.hpp"
#include "common/table_writer.hpp"
#include "ref3d/model.hpp"
#include "ref3d/reference.hpp"
#include "statsim/signature.hpp"

#include <array>
#include <cstdint>
#include <string>
#include <vector>

namespace statsim::tools::ref3d {

/// Default axes.
std::vector<double> default_height_ratios();   ///< 16 spin ratios, dense near zero, 0 .. 64
std::vector<double> default_cos_theta();       ///< 7: 0.1 .. 1
std::vector<double> default_cos_phi();         ///< 10: -1 .. 1
std::vector<double> default_spin_ratios();     ///< 16: 0 .. 8
std::vector<double> default_paper_speeds();    ///< 26 speeds for --layout paper, m/s
std::vector<double> default_coarse_speeds();   ///< the coarse speed axis, m/s

struct GatherOptions {
  std::string shape = "box";  ///< box, lshape, bunny (ignored when mesh_file is set)
  std::string mesh_file;      ///< any closed mesh `load_mesh` reads (btGImpactMeshShape)
  double mesh_scale = 1.0;    ///< metres per unit of mesh_file (--scale, --units)
  bool mesh_units_given = false;  ///< --scale or --units was given: no check of the mesh's size
  std::vector<double> box_size;  ///< non-empty: a generated box of this size (m), btBoxShape
  std::string name;           ///< table name (a C++ identifier)
  TableTarget target;         ///< where the header goes: how it names its paths, its namespace
  bool with_speed = false;    ///< response layout: false = scaled (cos theta, cos phi, s), true = with speed
  int trials = 30;            ///< impacts per response cell
  int height_trials = 1000;   ///< flights per h_coll sample
  int rest_drops = 1000;
  std::uint64_t seed = 1;
  bool i16 = false;           ///< --precision i16
  /// How each cell's spread is stored (--response-model): see statsim::ResponseModel.
  ResponseModel response_model = ResponseModel::independent_gaussian;
  /// Outcomes kept per cell by the empirical model (--empirical-outcomes), 1 to `trials`.
  int empirical_outcomes = 16;
  unsigned threads = 0;       ///< 0 = all hardware threads
  bool progress = false;      ///< progress and ETA on stderr
  double density = default_density;  ///< kg/m^3
  double speed = 2.0;         ///< |V-| of the scaled layout's impacts, m/s
  double rolling_resistance = 0.05;  ///< written to the signature's material (the runtime's spheres)
  double max_impact_time = 2.0;      ///< s of an impact before it counts as time-limited
  double still_speed = 0.005;        ///< m/s: average speeds (centre, farthest point) below this are still
  double still_time = 0.25;          ///< s: a drop has settled after two still windows of this length
  double max_drop_time = 60.0;       ///< s before a drop counts as unsettled
  double rest_tolerance_deg = 10.0;
  double rest_min_frequency = 0.05;  ///< families above this summed frequency are kept
  /// Rare families are kept too while more than this share of the settled drops is in poses not kept.
  double rest_max_dropped = 0.02;
  std::vector<double> height_ratios = default_height_ratios();
  std::vector<double> cos_theta = default_cos_theta();
  std::vector<double> cos_phi = default_cos_phi();
  std::vector<double> spin_ratios = default_spin_ratios();
  std::vector<double> speeds;  ///< empty: default_paper_speeds() when with_speed
  ReferenceSettings reference;
  // Body-body data (4.); false (--no-body-contacts): a table of format 2.0 without it.
  bool body_contacts = true;
  int support_size = 17;    ///< S of the support map (6 S^2 values)
  int contact_faces = 16;   ///< largest hull faces stored (fewer when the hull has fewer)
  int pair_trials = 400;    ///< pair flights per h_coll spin ratio
  int packing_piles = 10;   ///< drop piles (drop_scene3 seeds 1..N)
  int packing_bins = 2;     ///< bins of stacked bodies (seeds 1..N)
  int packing_count = 50;   ///< bodies per pile and per bin
};

/// Checks the options; throws std::runtime_error naming the first problem.
void validate_gather_options(const GatherOptions& o);

/// The shape the options name (box_size, mesh_file or shape); throws on a bad mesh.
ShapeModel build_model(const GatherOptions& o);

struct RestPose {
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();  ///< unit, body frame
  double height = 0.0;      ///< m: the snapped face's offset, else the measured mean
  double measured_height = 0.0;  ///< mean over the drops, m
  double height_std = 0.0;  ///< m
  double frequency = 0.0;   ///< fraction of the settled drops
  int count = 0;
  bool snapped = false;     ///< the normal is a hull face's (the mean was within 3 degrees of it)
  int family = 0;           ///< equivalence family under the shape's symmetry, 0 = most frequent
  double family_frequency = 0.0;  ///< the family's summed frequency
};

/// One impact's normalised outcome: W+ L/|V-| (3), (V+ - V_particle+)/|V-| (3).
using Response = std::array<double, 6>;

struct GatherResult {
  GatherOptions options;
  ShapeModel model;
  std::string ground;  ///< "box" or "plane"
  // h_coll
  std::vector<double> height_mean, height_std;
  long long height_flights = 0;  ///< flights run (0: height samples x height_trials)
  // responses
  std::vector<std::vector<double>> axes;  ///< 3 (scaled) or 4 (with speed) axes, in table order
  std::vector<double> response_mean, response_std;  ///< cells x 6, row-major in the axes
  /// Per cell, the trial outcomes its statistics were taken over (at spin ratio 0, the trials of
  /// every cos phi of its cos theta and speed, pooled).
  std::vector<std::vector<Response>> cell_outcomes;
  long long response_trials = 0;
  long long time_limited = 0;
  double max_penetration = 0.0;
  // rest poses
  std::vector<RestPose> rest;  ///< kept poses, most frequent first
  std::vector<RestPose> rest_rare;  ///< poses not kept
  double rest_dropped = 0.0;  ///< fraction of the settled drops in poses not kept
  int rest_families = 0;      ///< families of all poses, kept or not
  int settled = 0, unsettled = 0;
  double mean_settle_time = 0.0;  ///< s of simulation, over the settled drops
  /// Extra header lines ("// Sized: ..."; "sizing" in the JSON), e.g. how --size-for-scene
  /// chose the table. Empty for a plain gathering.
  std::vector<std::string> notes;
  BodyContactData contact;  ///< when options.body_contacts
  // timings, s
  double height_seconds = 0.0, response_seconds = 0.0, rest_seconds = 0.0;
};

/// Runs the gathering (deterministic for a given options.seed, whatever options.threads).
GatherResult gather(const GatherOptions& options);

/// The command-line name of a response model ("paper", "correlated", "empirical").
const char* response_model_name(ResponseModel model);
/// The model of a command-line name; throws std::runtime_error listing the names.
ResponseModel parse_response_model(const std::string& name);

/// The spread values of every cell (cells x statsim::response_spread_size), by the model of
/// `r.options`, from `r.cell_outcomes` (the paper's model: `r.response_std`):
///  - correlated: the lower triangle, row by row, of the Cholesky factor of the cell's sample
///    covariance (n - 1); a direction without variance gets a zero column.
///  - empirical: `empirical_outcomes` of the cell's outcomes, picked at evenly spaced ranks of
///    the normal velocity offset (so the kept outcomes span its distribution, the other
///    components coming with them), each minus the mean of the kept ones (a draw's mean is then
///    the table's mean).
/// Throws std::runtime_error when a model needs outcomes that `r` lacks.
std::vector<double> response_spread(const GatherResult& r);

/// Lower triangle, row by row, of a Cholesky factor of the symmetric positive semi-definite
/// n x n matrix `a` (row-major); a pivot not above 1e-12 times the largest diagonal is taken
/// as 0 with its column.
std::vector<double> cholesky_lower(const std::vector<double>& a, int n);

/// One response trial (exposed for the checks and tests): cell coordinates, speed, trial index.
struct ResponseTrial {
  Response value{};
  bool time_limited = false;
  double max_penetration = 0.0;
  int steps = 0;
};
ResponseTrial response_trial(const Reference& ref, const GatherOptions& o, double cos_theta, double cos_phi,
                             double speed, double spin_ratio, std::uint64_t stream, std::uint64_t index);

/// One h_coll flight: the centre height at first contact.
double height_trial(const ShapeModel& model, double spin_ratio, std::uint64_t seed, std::uint64_t index);

/// The 16-bit form of the float (Scalar) values written to a header, by statsim::quantize16 (the
/// one rule), and the largest error of reading them back.
struct Quantized {
  float scale = 1.0f, offset = 0.0f;
  std::vector<std::int16_t> q;
  double worst_error = 0.0;  ///< largest |dequantised - float value|, as the runtime computes it
};
Quantized quantize(const std::vector<float>& values);

/// The generated header. `command` is the command line recorded in it.
std::string header_text(const GatherResult& r, const std::string& command);
/// The JSON dump (pretty-printed, 2-space indent, trailing newline).
std::string json_text(const GatherResult& r, const std::string& command);
/// A short human summary for stdout.
std::string summary_text(const GatherResult& r);

/// `gather --speed-check`: normalised response means at several |V-| for a few cells (markdown).
std::string speed_check_report(const GatherOptions& o, const std::vector<double>& speeds, int trials);
/// `gather --step-check`: the statistics of a small gathering at dt and dt/2 (markdown).
std::string step_check_report(const GatherOptions& o);
/// The reference-settings check: a face-down cube at normal incidence, Bullet's defaults vs ours.
std::string settings_check_report(const GatherOptions& o);

}  // namespace statsim::tools::ref3d
