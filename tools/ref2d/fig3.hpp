// Paper Figure 3 (Hsu & Keyser, "Statistical Simulation of Rigid Bodies", section 3.2.1):
// the height of the centre of mass of a 1x1 square at its first contact with a line, as a
// function of the ratio |w|/|v| of its angular to its linear speed, measured with Box2D.
#pragma once

#include "ref2d/first_contact.hpp"

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

namespace statsim::tools {

/// The |w|/|v| values (in rad/m) of the default run: dense near zero, sparse further out (as the
/// paper recommends): 0, 0.05, 0.1, 0.2, 0.35, 0.5, 0.75, 1, 1.5, 2, 3, 4, 6, 8, 12, 16, 24, 32,
/// 48, 64. Up to |w|/|v| ~ 2 the square turns by less than 0.4 rad while its centre falls from
/// sqrt(2)/2 to 0.5, so the heights stay spread over the whole range; beyond, the mean climbs
/// towards sqrt(2)/2 slowly (the centre falls pi/(2 |w|/|v|) per quarter turn), hence the long
/// tail up to 64.
std::vector<double> default_fig3_ratios();

/// Parameters of the experiment.
struct Fig3Options {
  std::vector<double> ratios = default_fig3_ratios();  ///< |w|/|v| values, rad/m, each >= 0.
  int trials = 400;                    ///< Trials per ratio (>= 2).
  std::vector<int> trials_per_ratio;   ///< Optional: one count per ratio, overriding `trials`.
  std::uint64_t seed = 1;              ///< Trial k of ratio i draws from a generator seeded by
                                       ///< (seed, i, k) only: results ignore `threads`.
  double speed = 1.0;                  ///< |v| in m/s (> 0), straight down.
  double dt = 1.0 / 60.0;              ///< Box2D time step in s (> 0).
  unsigned threads = 0;                ///< Worker threads; 0 = hardware concurrency.
  bool progress = false;               ///< Report progress on stderr.
};

/// The random set-up of one drop.
struct Fig3Drop {
  double height = 1.0;  ///< Initial height of the centre above the line, m.
  double angle = 0.0;   ///< Initial orientation, rad.
  double spin = 0.0;    ///< Angular velocity w, rad/s (either sign).
};

/// What one drop measured: the first contact of the square with the line.
using Fig3Trial = FirstContact;
/// Summary of one ratio: statistics of the heights (std is the sample standard deviation).
struct Fig3Row {
  double ratio = 0.0;
  double min = 0.0;
  double mean = 0.0;
  double std = 0.0;
  double max = 0.0;
  int trials = 0;
  int late = 0;    ///< Drops of this ratio that Box2D reported one step late (Fig3Trial::late).
  int missed = 0;  ///< Drops whose first core contact Box2D missed (Fig3Trial::missed).
};

/// Aggregate diagnostics over all trials.
struct Fig3Diagnostics {
  std::uint64_t trials = 0;
  std::uint64_t steps = 0;
  std::uint64_t skin_reports = 0;  ///< Reports judged at a step start with the core gap within
                                   ///< Box2D's skin (0, 2 * b2_polygonRadius]: early reports.
  double mean_skin_gap = 0.0;      ///< Mean core gap of those reports, m.
  double max_skin_gap = 0.0;       ///< Largest core gap of those reports, m.
  std::uint64_t in_step_reports = 0;  ///< Reports of contacts that began inside the step (the
                                      ///< gap at its start exceeded the skin: continuous
                                      ///< collision, fast-turning corners).
  std::uint64_t late = 0;          ///< See Fig3Trial::late.
  std::uint64_t missed = 0;        ///< See Fig3Trial::missed.
  std::uint64_t grazing = 0;       ///< See Fig3Trial::grazing.
  double mean_naive_bias = 0.0;    ///< Mean of naive_height - height over all drops, m.
  double max_float_drift = 0.0;    ///< Largest Fig3Trial::float_drift, m.
  double max_free_flight_error = 0.0;
  double seconds = 0.0;            ///< Wall-clock time of the run.
};

/// The result of run_fig3(): one row per ratio, every measured height, diagnostics.
struct Fig3Result {
  Fig3Options options;
  std::vector<Fig3Row> rows;
  std::vector<std::vector<double>> heights;  ///< heights[i][k]: trial k of ratio i.
  Fig3Diagnostics diagnostics;
};

/// Draws the set-up of trial `trial` of ratio number `ratio_index` (deterministic in
/// (seed, ratio_index, trial)): orientation uniform in [0, 2pi), spin sign random, start height
/// sqrt(2)/2 + 0.1 m + u*|v|*dt with u uniform in [0, 1) (one step's travel of phase).
Fig3Drop fig3_drop(const Fig3Options& options, double ratio, std::size_t ratio_index,
                   std::size_t trial);

/// Runs one drop in Box2D (see fig3.cpp for the method) and returns the exact height of the
/// centre at the first contact of the core square with the line. Throws std::runtime_error if
/// Box2D does not move the body as expected.
Fig3Trial simulate_fig3_drop(const Fig3Drop& drop, double speed, double dt);

/// Throws std::invalid_argument with a readable message if `options` are unusable (see
/// run_fig3()).
void validate_fig3_options(const Fig3Options& options);

/// Runs the whole experiment. Throws std::invalid_argument for bad options (speed or dt not
/// positive, fewer than 2 trials, a negative ratio, a step too long for Box2D's per-step
/// translation or rotation limits).
Fig3Result run_fig3(const Fig3Options& options);

/// The CSV text: header `ratio,min,mean,std,max,trials`, one row per ratio, plain decimals.
std::string fig3_csv(const Fig3Result& result);

/// Writes DIR/fig3.csv (atomically), then draws DIR/fig3.png and DIR/fig3.svg from it with
/// tools/plot/fig3.py. Throws std::runtime_error on I/O errors or when the chart cannot be drawn
/// (see plot::run_script).
void write_fig3_outputs(const Fig3Result& result, const std::filesystem::path& dir);

/// A human-readable summary of the run: the table, how the skin bias was removed, diagnostics.
std::string fig3_summary(const Fig3Result& result);

}  // namespace statsim::tools
