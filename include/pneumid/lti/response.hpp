// Time responses and step-response metrics (python-control timeresp.py,
// MATLAB step/impulse/lsim/stepinfo).
//
// Continuous models are simulated exactly on the sample grid for inputs held
// constant between samples (zero-order hold discretization with the input
// delay, see conversion.hpp); discrete models are run as difference equations
// at their own sample time.
#pragma once

#include <limits>
#include <string>

#include <Eigen/Core>

#include "pneumid/lti/state_space.hpp"
#include "pneumid/lti/transfer_function.hpp"

namespace pneumid {

/// A sampled response y(t) of a model (Step, Impulse).
struct TimeResponse {
  Eigen::VectorXd t;  ///< seconds
  Eigen::VectorXd y;  ///< output at t
};

/// Time at which the sampled signal x(t) first reaches `level` from below,
/// searching from index `start`: t[k-1] + (level - x[k-1]) / (x[k] - x[k-1])
/// (t[k] - t[k-1]) for the first k with x[k] >= level (t[start] when x[start]
/// already does); NaN when it never does. `index`, when given, receives that
/// k (x.size() when the level is never reached). A falling signal is handled
/// by passing the normalized response (x - x0) / (x_final - x0).
/// @throws InvalidArgument when t and x differ in size.
double FirstCrossing(const Eigen::VectorXd& t, const Eigen::VectorXd& x, double level,
                     Eigen::Index start = 0, Eigen::Index* index = nullptr);

/// Unit step response on t = 0, dt, ..., >= t_final. dt = 0 chooses Ts for a
/// discrete model, otherwise about 1/200 of the slowest time constant (plus
/// delay); t_final = 0 chooses about 7 slowest time constants (plus delay).
/// Automatic choices are bounded to 200000 samples and about 2e9 multiply-adds
/// (samples x (order + 1)^2): the horizon of a slow or high-order discrete
/// model is shortened, the step of a continuous one lengthened.
/// @throws InvalidArgument for a chosen grid of more than 1e8 samples or 1e11
///         multiply-adds, or when the response is not finite (an ill-conditioned
///         or overflowing model), naming the time and the model order.
TimeResponse Step(const TransferFunction& g, double t_final = 0.0, double dt = 0.0);
/// Unit impulse response (a discrete impulse of area 1 for discrete models).
TimeResponse Impulse(const TransferFunction& g, double t_final = 0.0, double dt = 0.0);

/// Response to samples u[k] at t = k dt held constant over each interval,
/// starting from rest (zero state, and u = 0 for t < 0 in the delay line).
/// A continuous model is discretized once by zoh with its delay (exact at the
/// samples), then run in O(N nx^2) without allocation per sample.
/// @throws InvalidArgument for dt <= 0, a non-finite input, or a discrete
///   model whose Ts differs from dt.
Eigen::VectorXd Lsim(const TransferFunction& g, const Eigen::VectorXd& u, double dt);
/// State-space version: u is N x nu, returns N x ny; x0 has nx entries (or is
/// empty for zero). Input delay in the delay line starts at zero input.
Eigen::MatrixXd Lsim(const StateSpace& g, const Eigen::MatrixXd& u, double dt,
                     const Eigen::VectorXd& x0 = Eigen::VectorXd());

/// MATLAB stepinfo definitions
/// (https://www.mathworks.com/help/control/ref/dynamicsystem.stepinfo.html):
///   rise_time      time from 10 % to 90 % of the way from y0 to y_final
///   settling_time  first time after which |y - y_final| <= 2 % of |y_final - y0| (from t0)
///   overshoot      percent over y_final relative to |y_final - y0|
///   undershoot     percent below y0 in the opposite direction
///   peak, peak_time  max |y| and when it occurs
struct StepInfo {
  double rise_time = 0.0;      ///< s, rise_low to rise_high of the step (NaN if not reached)
  double settling_time = 0.0;  ///< s from t[0] (NaN when not settled by the last sample)
  double settling_min = 0.0;   ///< min of y once it reached rise_high (whole record if never)
  double settling_max = 0.0;   ///< max of y once it reached rise_high (whole record if never)
  double overshoot = 0.0;      ///< percent
  double undershoot = 0.0;     ///< percent
  double peak = 0.0;           ///< max |y|, output units
  double peak_time = 0.0;      ///< s from t[0] to the peak
  double steady_state = 0.0;   ///< y_final used
};

/// Levels and reference values of ComputeStepInfo.
struct StepInfoOptions {
  double settling_threshold = 0.02;  ///< fraction of the step
  double rise_low = 0.1;             ///< fraction
  double rise_high = 0.9;            ///< fraction
  /// Initial value y0 and final value; NaN means y(0) / last sample.
  double y_initial = std::numeric_limits<double>::quiet_NaN();
  double y_final = std::numeric_limits<double>::quiet_NaN();  ///< final value; NaN: last y
  /// True for settling_threshold in (0, 1), 0 <= rise_low < rise_high <= 1 and y_initial,
  /// y_final finite or NaN; otherwise false with the reason in *error (when not null).
  bool IsValid(std::string* error) const;
};

/// Metrics of a sampled response; crossing times are linearly interpolated
/// between samples, times are measured from t[0]. Rise and settling times are
/// NaN when the response never reaches the level / has not settled by the last
/// sample; with y_final == y_initial they are NaN and the percentages 0.
/// Note: y_initial defaults to y[0] here, where MATLAB's stepinfo(y, t)
/// assumes 0; ComputeStepInfo(g) uses 0 like stepinfo(sys).
/// @throws InvalidArgument for invalid options, sizes that differ, fewer than
///   2 samples, NaN/Inf, or t not strictly increasing.
StepInfo ComputeStepInfo(const Eigen::VectorXd& t, const Eigen::VectorXd& y,
                         const StepInfoOptions& options = {});
/// Metrics of the model's unit step response on the default grid of Step()
/// (y_initial = 0, final value = DcGain()). An unstable model gives NaN metrics.
StepInfo ComputeStepInfo(const TransferFunction& g, const StepInfoOptions& options = {});

}  // namespace pneumid
