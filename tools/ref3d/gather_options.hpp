// The options of `statsim gather` (the shape, the axes, the trials, the reference's settings,
// the body-body, landing and settling data) with their defaults and checks, and the shape they
// name. Every stage of the gathering reads them; tools/ref3d/README.md documents the command
// line that sets them.
#pragma once

#include "common/table_writer.hpp"
#include "ref3d/model.hpp"
#include "ref3d/reference.hpp"
#include "statsim/signature.hpp"
#include "statsim/world_def.hpp"

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
std::vector<double> default_landing_froude();  ///< 4 Froude numbers |V-|^2 / (g L): 0, 1, 4, 16

/// The spin measure of the response table (--response-spin): statsim::ResponseSpin, or, by
/// default, length or, where the runtime's draws by gyration match the trials' spins measurably
/// better, energy (gather_spin.hpp); `gyration` and `energy` need the landing data, which a
/// table holds before them.
enum class SpinOption { automatic, length, gyration, energy };

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
  /// What the response table's spin components measure (--response-spin): see SpinOption.
  SpinOption response_spin = SpinOption::automatic;
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
  // Landing data (5., statsim/signature_landing.hpp): a table of format 2.2; false
  // (--no-landing), or without the body-body data it follows in a table: 2.1 or 2.0.
  bool landing = true;
  int landing_trials = 24;           ///< impacts with gravity per landing cell
  std::vector<double> landing_froude = default_landing_froude();
  double landing_hop = 0.05;         ///< rise over L below which an impact counts as a stay
  double landing_time = 1.0;         ///< s: an impact not flown off by then counts as a stay
  /// Response trials under gravity, each to the first flight whose centre rises landing_hop L
  /// (the chain of contacts a drop's first flight ends), as `statsim fidelity` measures a drop's
  /// first impact; a trial with no such flight within landing_time keeps the gravity-free outcome.
  bool response_flight = false;
  // Settling data (6., statsim/signature_settle.hpp, gather_settle.hpp): a table of format 2.3,
  // when asked for (--settle) and with the landing data it follows in a table.
  bool settle = false;
  int settle_quantiles = 8;  ///< quantiles of the settling time per rest pose
  /// m/s: the last time a drop was this fast starts its settling time; the runtime's default, at
  /// which it starts settling a body.
  double settle_speed = static_cast<double>(WorldDef<3>{}.settle_speed);
  double quiet_speed = 0.01;  ///< m/s: a drop slower than this for good has settled
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

/// The command-line name of a response model ("paper", "correlated", "empirical").
const char* response_model_name(ResponseModel model);
/// The model of a command-line name; throws std::runtime_error listing the names.
ResponseModel parse_response_model(const std::string& name);

}  // namespace statsim::tools::ref3d
