// What drives a plant, described for the layers that drive it without knowing
// its physics: the real-time loop, its safety layer, its logs and status line.
//
// Every actuator has an input u and a measured output y (name and unit), a
// physical input range, and two safe states the loop can leave it in after a
// fault or a stop:
//   hold     stop acting and keep the plant's state where it is
//   release  drive the actuator to rest (its de-energized state)
// A plant names and explains them in its own terms; for the IPA (IpaActuator):
//   hold     "valves-closed": inlet and exhaust valves closed, chamber pressure held
//   release  "exhaust-open":  inlet closed, exhaust open, the chamber vents and
//                             the force falls to its minimum
// with u the PWM duty cycle in % (0..100) and y the force in N (position in m
// in position mode).
#pragma once

#include <cstddef>
#include <limits>
#include <string>
#include <vector>

#include "pneumid/data/dataset.hpp"
#include "pneumid/plant/ipa_simulator.hpp"
#include "pneumid/plant/plant.hpp"

namespace pneumid {

/// An open interval (lo, hi) of inputs the actuator cannot hold; inputs in
/// it act as lo or hi. Input units (IPA: duty in %).
struct InputGap {
  double lo = 0.0;  ///< lower end: the nearest input below the gap that acts as itself
  double hi = 0.0;  ///< upper end: the nearest input above the gap that acts as itself
  bool operator==(const InputGap&) const = default;  ///< same ends
};

/// Description of a plant's actuator for the real-time loop: signals, input range, input
/// gaps and the names and meanings of its hold and release safe states.
struct Actuator {
  Channel input{"u", ""};   ///< name and unit of the input
  Channel output{"y", ""};  ///< name and unit of the measured output
  /// Words for a status line, e.g. "duty" and "force".
  std::string input_label = "u";
  std::string output_label = "y";  ///< word for the output, e.g. "force"
  /// Physical input range (input units; infinite = unbounded).
  double u_min = -std::numeric_limits<double>::infinity();
  double u_max = std::numeric_limits<double>::infinity();  ///< upper end, e.g. 100 % duty
  /// Physical output range (output units; infinite = unbounded), e.g. the
  /// stroke of a positioning cylinder: set-points outside it cannot be reached.
  double y_min = -std::numeric_limits<double>::infinity();
  double y_max = std::numeric_limits<double>::infinity();  ///< upper end of the output range
  /// Inputs the actuator cannot hold (IPA: a PWM pulse shorter than the valves'
  /// minimum width does not open them, so duties below 100 min_pulse_width
  /// pwm_frequency % act as 0 and those as far below 100 % act as 100 %);
  /// empty = none known. control/duty_modulator.hpp modulates across them.
  std::vector<InputGap> input_gaps;
  /// The output integrates the input (a positioning drive): no steady state at
  /// a constant non-zero input and no static gain, so experiments and designs
  /// that need one (commissioning's step probe) take another route.
  bool integrating = false;
  /// The plant's names and meanings of the hold and release safe states.
  std::string hold_name = "hold";
  /// What the hold state does, for logs and messages.
  std::string hold_meaning = "the input is no longer applied; the plant keeps its state";
  /// The plant's name of the release state, e.g. "exhaust-open".
  std::string release_name = "release";
  /// What the release state does, for logs and messages.
  std::string release_meaning = "the actuator is driven to rest (input 0)";
};

/// The IPA's actuator (see the file comment); the output is force (N) in
/// force mode, position (m) in position mode.
Actuator IpaActuator(IpaMode mode = IpaMode::kForce);

/// The actuator of a plant, plant.actuator(): IpaActuator for the IPA
/// simulator (in position mode with the output range 0..stroke, integrating),
/// the generic description (u, y without units, unbounded, hold/release)
/// for a plant that gives none.
Actuator PlantActuator(const Plant& plant);

/// Checks set-points r (sampled every Ts s from t = 0) against the actuator's
/// output range.
/// @throws InvalidArgument naming the first set-point outside it, its time and the range.
void CheckSetpointsInOutputRange(const Actuator& actuator, const double* r, std::size_t n,
                                 double Ts);

}  // namespace pneumid
