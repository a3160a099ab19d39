// The options of `statsim gather2d` (the shape, the axes, the trials, Box2D's steps, the rest-pose
// rule, the body-body data) with their defaults and checks, and the shape they name. Every stage
// of the 2D gathering reads them; tools/ref2d/README.md documents the command line.
#pragma once

#include "common/table_writer.hpp"
#include "ref2d/polygon2d.hpp"

#include <cstdint>
#include <string>
#include <vector>

namespace statsim::tools {

/// Default axes (the runtime clamps outside them).
std::vector<double> default_height_ratios();   ///< 16 spin ratios 0..32, denser near 0
std::vector<double> default_cos_thetas();      ///< 7 values 0.15..1
std::vector<double> default_signed_spins();    ///< 9 values -6..6, denser near 0
std::vector<double> default_speeds();          ///< 5 values 0.5..9 m/s

/// Defaults: 16 x 1000 height drops, 315 cells x 200 response trials, 2000 rest drops. Box2D steps
/// one small body so fast that generous statistics cost seconds per shape (gathering times and the
/// standard errors they give: tools/ref2d/README.md).
struct Gather2dOptions {
  std::string shape = "square";  ///< "square", "lshape" or "polygon"
  std::string polygon;           ///< vertices "x1,y1 x2,y2 ..." when shape == "polygon"
  std::string name = "square2d"; ///< C++ name of the table (an identifier)
  TableTarget target;            ///< where the header goes: how it names its paths, its namespace
  std::uint64_t seed = 1;
  double restitution = 0.3;  ///< of the body and of the ground (Box2D mixes with max: e)
  double friction = 0.5;     ///< of the body and of the ground (Box2D mixes sqrt(mu mu) = mu)

  std::vector<double> height_ratios = default_height_ratios();
  int height_trials = 1000;    ///< drops per spin ratio
  double height_speed = 2.0;   ///< m/s, straight down

  std::vector<double> cos_thetas = default_cos_thetas();
  std::vector<double> signed_spins = default_signed_spins();
  std::vector<double> speeds = default_speeds();
  int trials = 200;                   ///< per response cell
  double response_dt = 1.0 / 480.0;   ///< s (smaller for small fast-spinning shapes, see the header)
  double response_time_limit = 3.0;   ///< s of simulated time per trial

  int rest_drops = 2000;
  double rest_dt = 1.0 / 120.0;
  double rest_time_limit = 30.0;      ///< s of simulated time per drop
  double cluster_degrees = 10.0;      ///< greedy clustering tolerance
  double min_frequency = 0.05;        ///< families kept: summed frequency > this
  double max_dropped = 0.02;          ///< then rarer families kept while the dropped share exceeds this

  // Body-body data (4.); false (--no-body-contacts): a table of format 2.0 without it.
  bool body_contacts = true;
  int support_size = 9;     ///< S of the support map (4 S values)
  int contact_faces = 16;   ///< longest hull edges stored (fewer when the hull has fewer)
  int pair_trials = 2000;   ///< pair flights per height-table spin ratio
  int packing_piles = 10;   ///< Box2D piles of `statsim compare2d` (seeds 1..N)
  int packing_count = 100;  ///< bodies per pile
  int packing_steps = 900;  ///< steps of 1/60 s per pile

  unsigned threads = 0;  ///< 0 = hardware concurrency; does not change the result
  bool progress = false;
};

/// The shape an options object names (throws std::invalid_argument for a bad polygon).
Shape2 gather2d_shape(const Gather2dOptions& options);

/// Throws std::invalid_argument with a readable message for unusable options.
void validate_gather2d_options(const Gather2dOptions& options);

}  // namespace statsim::tools
