// Closed-loop evaluation: a controller driving any Plant (the controller's
// model need not be the plant) through a set-point profile, with load
// disturbance steps, measurement noise and actuator limits, and the metrics
// engineers compare controllers by.
//
// Loop at sample k = 0 .. n-1 (t_k = k Ts, n = round(duration / Ts)):
//   d_k applied with plant.SetLoadDisturbance (sum of the load steps with at <= t_k)
//   y_k = plant.Measure();  y_meas = y_k + v_k   (v Gaussian, std noise_std)
//   u_k = actuator.Clip(controller.Update(r_k, y_meas))   (options.actuator within
//         the plant's input range; controller.Applied(u_k) when clipped)
//   plant.Advance(u_k)
// The controller is Reset(u0, y_0) first, with r_{-1} = setpoint(-Ts) the
// operating point the run starts from.
//
// Metrics (errors e = r - y use the plant output without the added noise):
//   per set-point change (`steps`): rise_time, overshoot_percent,
//     settling_time of the response over the samples until the next change
//     or a load step, whichever comes first
//     (ComputeStepInfo of lti/response.hpp with y_initial = the previous
//     set-point, y_final = the new one; times from the change), NaN when the
//     response never settles in the window;
//   the summary: overshoot_percent and settling_time are the WORST over the
//     steps (the largest overshoot; the longest settling time, NaN when a step
//     did not settle), worst_overshoot_step and worst_settling_step name the
//     step (index into `steps`; the first unsettled one when one did not
//     settle), worst_steady_state_error is the steps' steady-state error of
//     largest magnitude (signed) and worst_steady_state_error_step its step
//     (steady_state_error stays the final segment's), settled says that every step settled,
//     settling_band is that of the worst-settling step; rise_time and first_move are those of the
//     first step (steps[0] holds all of the first step's metrics). All are
//     NaN (settled false) when the set-point never changes;
//   settling_band: the half-width of the band |y - r| <= band the settling
//     time refers to, max(settling_threshold |step|, ripple) (and
//     ClosedLoopOptions::settling_band_floor at the new set-point, if set), where the ripple
//     is the measured ripple/noise band of the segment's last quarter (at
//     least 8 samples): the largest peak-to-peak range max - min of 4
//     consecutive samples there (so a ripple centred up to half its
//     peak-to-peak off the set-point still counts as settled). A PWM ripple or
//     noise wider than 2 % of the step thus widens the band instead of hiding
//     a settled response; a slow oscillation does not (4 samples see little of
//     it). settled: the output entered the band before the last 10 % of the
//     segment (at least 5 samples) and stayed in it; otherwise the settling
//     time is NaN;
//   steady_state_error: r - y averaged over the last 5 % (at least 1, at most
//     50 samples) of the final set-point segment;
//   iae = sum |e| Ts, ise = sum e^2 Ts, itae = sum t |e| Ts;
//   tv_u = sum |u_k - u_{k-1}| (u_{-1} = u0); u_min, u_max;
//   first_move = u_k - u_{k-1} at the first set-point change;
//   load_peak_deviation: the largest |y - r| after the first load step (signed),
//   load_recovery_time: time from the load step until |y - r| stays within
//     max(2 % of |load size|, 3 noise_std) (NaN if it never does before the
//     next set-point change or the end).
// Per set-point change the same step metrics are listed in `steps`.
#pragma once

#include <atomic>
#include <cstdint>
#include <functional>
#include <limits>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <nlohmann/json_fwd.hpp>

#include "pneumid/control/controller.hpp"
#include "pneumid/plant/plant.hpp"
#include "pneumid/plant/signal.hpp"

namespace pneumid {

/// A step of load disturbance added to the plant output from time `at` on.
struct LoadStep {
  double at = 0.0;    ///< s
  double size = 0.0;  ///< output units, added to the disturbance from `at` on
};

/// The load disturbance at time t (s): the sum of the sizes of the steps with
/// at <= t (to 1e-9 of the sample time Ts, so a step at a sample instant
/// acts on that sample).
double LoadAt(const std::vector<LoadStep>& steps, double t, double Ts);
/// A load step from its spec "at=T,size=D" (the `--load-step` syntax).
/// @throws InvalidArgument naming `what` and the spec when a key is missing,
/// unknown or not a number, or at is negative or not finite.
LoadStep ParseLoadStep(const std::string& what, const std::string& spec);

/// Duration, disturbances, noise and actuator limits of a closed-loop simulation.
struct ClosedLoopOptions {
  double duration = 1.0;             ///< s (> 0)
  std::vector<LoadStep> load_steps;  ///< load disturbance steps (none by default)
  double noise_std = 0.0;            ///< measurement noise standard deviation (output units)
  std::uint64_t seed = 1;            ///< noise seed
  /// Actuator limits applied after the controller (infinite = none).
  InputLimits actuator;
  /// Also limit the input to the plant's physical range (PlantActuator of
  /// plant/actuator.hpp: the IPA's duty 0..100 %; linear plants are
  /// unbounded), the default. The controller is told the applied input
  /// (Controller::Applied) whenever a limit changed it.
  bool plant_range = true;
  double u0 = 0.0;  ///< input before t = 0
  /// Settling band as a fraction of the step (and rise 10-90 %).
  double settling_threshold = 0.02;
  /// Least half-width of the settling band at a set-point (output units):
  /// the band is then max(settling_threshold |step|, ripple, floor(to)).
  /// For an actuator that cannot hold some outputs more steadily than a
  /// known ripple (commission passes 1.25 x the ripple its experiment's
  /// levels showed near `to`, workflow/commission.hpp). Empty: none.
  std::function<double(double to)> settling_band_floor;
  /// Record the wall-clock time of every Update() call.
  bool time_updates = false;
  /// When set and true, the simulation throws Cancelled at the next sample
  /// (a caller that no longer wants the result, e.g. a server whose client left).
  const std::atomic<bool>* stop = nullptr;
  /// True when duration > 0, the load steps have finite at >= 0 and size, noise_std >= 0,
  /// u0 is finite, settling_threshold is in (0, 1) and actuator is valid; otherwise false
  /// with the reason in *error (when error is not null).
  bool IsValid(std::string* error) const;
  /// The samples the simulation takes at Ts: round(duration / Ts), at least 2.
  Eigen::Index Samples(double Ts) const;
};

/// Response metrics of one set-point change (see the file comment).
struct StepMetrics {
  double time = 0.0;  ///< s, when the set-point changed
  double from = 0.0;  ///< set-point before the change (output units)
  double to = 0.0;    ///< set-point after the change (output units)
  /// 10-90 % rise time, s from the change (NaN when not reached).
  double rise_time = std::numeric_limits<double>::quiet_NaN();
  /// Peak beyond `to` in percent of |to - from| (0 without overshoot).
  double overshoot_percent = std::numeric_limits<double>::quiet_NaN();
  /// Time from the change until |y - r| stays within settling_band, s; NaN when unsettled.
  double settling_time = std::numeric_limits<double>::quiet_NaN();
  double steady_state_error = std::numeric_limits<double>::quiet_NaN();  ///< end of the segment
  /// u_k - u_{k-1} at the change (input units): the first move the controller makes.
  double first_move = std::numeric_limits<double>::quiet_NaN();
  double settling_band = std::numeric_limits<double>::quiet_NaN();  ///< output units (see above)
  double ripple = std::numeric_limits<double>::quiet_NaN();  ///< measured ripple peak-to-peak
  /// The mean applied input over the window whose ripple is measured (the
  /// last quarter of the step's hold, ending at a load step inside it): the
  /// input that holds `to`; NaN when the hold is too short.
  double steady_input = std::numeric_limits<double>::quiet_NaN();
  /// The output entered the band before the last 10 % of the segment and stayed in it.
  bool settled = false;
  /// The overshoot beyond half the step's steady ripple, percent of the step:
  /// max(0, overshoot_percent - 50 ripple / |to - from|), overshoot_percent
  /// itself when the ripple is not measured. At a level the actuator holds
  /// only by modulation (a force inside a valve's input gap) the output
  /// ripples around the set-point by itself; on a step small against that
  /// ripple the peak is the ripple's, not the response's, and this is the
  /// part of it the response adds (what `pneumid commission` judges when the
  /// ripple is within its limit).
  double overshoot_beyond_ripple_percent = std::numeric_limits<double>::quiet_NaN();

  /// {time, from, to, rise_time, overshoot_percent, settling_time,
  /// steady_state_error, first_move, settling_band, settled, ripple,
  /// steady_input, overshoot_beyond_ripple_percent}; NaN is written as null.
  nlohmann::ordered_json ToJson() const;
};

/// Metrics of a whole run: the worst step, the error integrals, the input effort and the
/// load rejection (see the file comment).
struct ClosedLoopMetrics {
  /// 10-90 % rise time of the first set-point step, s.
  double rise_time = std::numeric_limits<double>::quiet_NaN();
  /// Largest overshoot over the steps, percent of the step size.
  double overshoot_percent = std::numeric_limits<double>::quiet_NaN();
  /// Longest settling time over the steps, s (NaN when a step did not settle).
  double settling_time = std::numeric_limits<double>::quiet_NaN();
  /// r - y averaged over the end of the final set-point segment (output units).
  double steady_state_error = std::numeric_limits<double>::quiet_NaN();
  /// u_k - u_{k-1} at the first set-point change (input units).
  double first_move = std::numeric_limits<double>::quiet_NaN();
  double settling_band = std::numeric_limits<double>::quiet_NaN();  ///< of the worst-settling step
  bool settled = false;                                             ///< every step settled
  int worst_overshoot_step = -1;  ///< index into steps of overshoot_percent (-1: none)
  /// Largest StepMetrics::overshoot_beyond_ripple_percent over the steps (NaN: no step).
  double overshoot_beyond_ripple_percent = std::numeric_limits<double>::quiet_NaN();
  int worst_settling_step = -1;  ///< index into steps of settling_time / settled (-1: none)
  /// The steps' steady-state error of largest magnitude, signed (output units; NaN: no step).
  double worst_steady_state_error = std::numeric_limits<double>::quiet_NaN();
  int worst_steady_state_error_step = -1;  ///< index into steps of it (-1: none)
  /// IAE = sum |e| Ts (output units s), with e = r - y without the measurement noise.
  double iae = 0.0, ise = 0.0, itae = 0.0;  ///< ITAE = sum t |e| Ts (output units s^2)
  /// @var ise
  /// ISE = sum e^2 Ts (output units^2 s).
  double tv_u = 0.0;  ///< total variation of the input, sum |u_k - u_{k-1}| (input units)
  /// Smallest applied input over the run (input units).
  double u_min = 0.0, u_max = 0.0;  ///< largest applied input over the run (input units)
  /// Largest |y - r| after the first load step, with its sign (output units).
  double load_peak_deviation = std::numeric_limits<double>::quiet_NaN();
  /// Time from the first load step until |y - r| stays within max(2 % of the load,
  /// 3 noise_std), s; NaN when it never does.
  double load_recovery_time = std::numeric_limits<double>::quiet_NaN();
  std::vector<StepMetrics> steps;  ///< one per set-point change, in time order

  /// The metrics of `pneumid control --json` and `pneumid run --json`:
  /// rise_time, overshoot_percent, settling_time, steady_state_error,
  /// first_move, settling_band, settled, worst_overshoot_step,
  /// worst_settling_step, worst_steady_state_error, worst_steady_state_error_step, iae, ise, itae,
  /// tv_u, u_min, u_max, load_peak_deviation, load_recovery_time and steps (StepMetrics::ToJson);
  /// NaN (a quantity that does not exist in the run) is written as null.
  nlohmann::ordered_json ToJson() const;
};

/// Signals of a closed-loop simulation, one entry per sample, and their metrics.
struct ClosedLoopResult {
  Eigen::VectorXd t;               ///< s
  Eigen::VectorXd r;               ///< set-point
  Eigen::VectorXd y;               ///< plant output (Measure())
  Eigen::VectorXd y_meas;          ///< what the controller saw (y + noise)
  Eigen::VectorXd u;               ///< applied input
  Eigen::VectorXd u_requested;     ///< the controller's input before the actuator limits
  Eigen::VectorXd d;               ///< load disturbance
  Eigen::VectorXd update_seconds;  ///< per Update() (empty unless time_updates)
  ClosedLoopMetrics metrics;       ///< metrics of the run (see the file comment)
  std::string controller;          ///< controller.Describe()
  std::string plant;               ///< plant.Describe()
};

/// Runs the loop described above; the plant is Reset() first. The plant's
/// and the controller's sample times must agree within 1e-9 relative.
/// @throws InvalidArgument for invalid options or mismatched sample times.
ClosedLoopResult SimulateClosedLoop(Controller& controller, Plant& plant, const Signal& setpoint,
                                    const ClosedLoopOptions& options);

/// Metrics of a logged run (t, r, y, u of equal length, uniform step Ts) as
/// defined above; r_before and u_before are the values before t(0).
/// @throws InvalidArgument for inconsistent lengths or fewer than 2 samples.
ClosedLoopMetrics ComputeClosedLoopMetrics(const Eigen::VectorXd& t, const Eigen::VectorXd& r,
                                           const Eigen::VectorXd& y, const Eigen::VectorXd& u,
                                           double r_before, double u_before,
                                           const ClosedLoopOptions& options);

}  // namespace pneumid
