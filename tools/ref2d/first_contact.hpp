// The exact first contact of a body's core shape with the line y = 0 as measured in Box2D
// (`measure_first_contact`, box2d_util.hpp): one drop of the paper's Figure 3 (fig3.hpp) and one
// height trial of `statsim gather2d`. Box2D-free, so that headers of results need not include it.
#pragma once

namespace statsim::tools {

/// What one drop measured.
struct FirstContact {
  double height = 0.0;        ///< Centre height at the first contact of the core shape (the
                              ///< result), m.
  double report_gap = 0.0;    ///< Core gap (lowest core vertex above the line) in Box2D's state
                              ///< at the start of the step after which it first reported
                              ///< touching: the state its narrow phase judged, m.
  double naive_height = 0.0;  ///< Centre height Box2D shows after that step: what one would
                              ///< record without the refinement, m.
  double float_drift = 0.0;   ///< |height from the refinement - height of the exact free flight
                              ///< from the initial state|: Box2D's float32 state rounding, m
                              ///< (0 when `missed` or `grazing`).
  double free_flight_error = 0.0;  ///< Largest deviation of a Box2D step without contact from
                                   ///< the analytic motion (position m, angle rad, velocities).
  int steps = 0;              ///< Box2D steps taken.
  bool late = false;          ///< The core touched during the step before the one Box2D reported
                              ///< (Box2D noticed one step late; the search window covers it).
  bool missed = false;        ///< The core touched even earlier, before the search window, and
                              ///< Box2D did not notice (a fast corner dipped through the line and
                              ///< out again between steps): the analytic cross-check from the
                              ///< initial state caught it, and its height is used.
  bool grazing = false;       ///< The refinement from Box2D's state and the exact free flight from
                              ///< the initial state disagree by more than 10 micrometres of travel:
                              ///< a corner grazes the line by less than Box2D's float32 noise in
                              ///< one of them only. The earlier contact is used.
};

}  // namespace statsim::tools
