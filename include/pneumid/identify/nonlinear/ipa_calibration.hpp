// Grey-box identification ("calibration") of the IPA simulator's physical
// parameters from measured experiments: the digital twin of one actuator.
//
// Model: the IPA simulator itself (plant/ipa_simulator.hpp: the chamber
// energy equation, ISO 6358 valve flows, valve timing, PWM in switching or
// averaged mode), noise-free and without ADC quantization, driven by each
// experiment's measured input u(k) and started from that experiment's own
// initial state. Free parameters theta (physical units, named by their TOML
// keys) are estimated by nonlinear least squares of the output error [1]:
//
//   min_theta  sum_e  w_e sum_k  ( (ysim_e(k; theta) - y_e(k)) / ||y_e - mean(y_e)|| )^2
//   subject to lower_i <= theta_i <= upper_i,
//
// so every experiment counts by its relative fit, fit_e = 100 (1 - ||ysim_e - y_e|| /
// ||y_e - mean(y_e)||) %, whatever its amplitude, times its weight w_e (default 1). Ceres Solver
// (Levenberg- Marquardt, bounds) works on the scaled variables z_i = theta_i / s_i with s_i =
// |start_i| (or the width of the range when the start is 0); the Jacobian is formed by central
// differences of the simulation (one-sided at a bound), its columns simulated on worker threads.
// The bounds default to the physical ranges of IpaParameterTable (docs/simulator.md states their
// sources).
//
// Uncertainty [1, ch. 9]: Cov(theta) = s^2 (J^T J)^+ in physical units, s^2 =
// 2 cost / (N - p). A parameter is reported as not determined by the data when
// it has a component above 0.3 in a right singular vector of J whose singular
// value is below 1e-4 of the largest (an unidentifiable combination, e.g. the
// valve conductances and the chamber volume scaled together, which leaves the
// pressure dynamics of a fixed rod unchanged), or when its relative standard
// deviation exceeds 10 %; pairs with |correlation| >= 0.95 are listed.
//
// [1] L. Ljung, System Identification: Theory for the User, 2nd ed., 1999,
//     sections 4.5 (grey-box models), 7.3 and 9.2.
// [2] T. Bohlin, Practical Grey-box Process Identification, Springer, 2006.
#pragma once

#include <functional>
#include <map>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Core>

#include "pneumid/common/termination.hpp"
#include "pneumid/data/dataset.hpp"
#include "pneumid/plant/ipa_simulator.hpp"

namespace pneumid {

/// How each experiment's simulation starts.
/// measured: from the state the first output sample shows (force mode: the
///   chamber-A pressure of the first force reading, chamber B at supply;
///   position mode: the piston at the first position reading, pressures as
///   after Reset), averaged over the leading samples with the first input.
/// steady: from the steady state the first input value reaches, by simulating
///   it for `warmup` seconds before the record.
enum class CalibrationInitialState { kMeasured, kSteady };
/// "measured", "steady".
std::string ToString(CalibrationInitialState s);
/// Inverse of ToString; throws InvalidArgument listing the valid names.
CalibrationInitialState CalibrationInitialStateFromString(const std::string& name);

/// One measured experiment: input 0 is the PWM duty in %, output 0 the force
/// in N (force mode) or position in m (position mode), uniformly sampled.
struct CalibrationExperiment {
  Dataset data;  ///< duty (%) in input 0, force (N) or position (m) in output 0
  std::string name;  ///< shown in reports; empty: data.source()
  /// Weight w_e > 0 of the experiment's term in the cost (default 1): its
  /// residuals are multiplied by sqrt(w_e).
  double weight = 1.0;
};

/// What CalibrateIpa estimates, from where, and how the Levenberg-Marquardt solve runs.
struct IpaCalibrationOptions {
  /// Starting values of the free parameters and values of all the others
  /// (mode and PWM mode included).
  IpaParameters start;
  /// Names of the free parameters (TOML keys or unique last parts, see
  /// FindIpaParameter); empty: DefaultCalibrationParameters(start).
  std::vector<std::string> free;
  /// Bounds that replace the physical range of a parameter, by name.
  std::map<std::string, std::pair<double, double>> bounds;
  /// How each experiment's simulation starts (default: from the measured first sample).
  CalibrationInitialState initial_state = CalibrationInitialState::kMeasured;
  double warmup = 2.0;  ///< s of constant first input before the record (steady)
  /// Relative and absolute odeint tolerance of the calibration's simulations
  /// (tighter than the simulator's default, so that the finite differences
  /// see the parameters and not the step-size control). Default 1e-8.
  double integration_tolerance = 1e-8;
  /// Finite-difference step relative to the scaled variable (default 1e-4).
  double relative_step = 1e-4;
  int max_iterations = 100;             ///< Levenberg-Marquardt iterations
  double function_tolerance = 1e-10;    ///< relative cost change to stop
  double parameter_tolerance = 1e-9;    ///< relative step to stop
  int num_threads = 2;                  ///< threads for the Jacobian's simulations
  double correlation_threshold = 0.95;  ///< |rho| from which a pair is reported
  /// A calibrated experiment fitted by less than this NRMSE (%) gets a
  /// warning: the twin does not reproduce it (units, initial state, free
  /// parameters or a structure the simulator lacks). Default 90.
  double fit_warning_percent = 90.0;
  /// Called after every iteration with its number and cost (may be empty).
  std::function<void(int iteration, double cost)> progress;

  /// True when `start` is valid, warmup is in 0..1e4 s, integration_tolerance in
  /// 1e-14..1e-3, relative_step in (0, 0.1], max_iterations in 0..100000, the stop
  /// tolerances >= 0, num_threads in 1..256, correlation_threshold in (0, 1] and
  /// fit_warning_percent <= 100; otherwise false with the reason in *error (when not null).
  bool IsValid(std::string* error) const;
};

/// One estimated parameter, physical units.
struct CalibratedParameter {
  std::string name;  ///< TOML key
  std::string unit;   ///< physical unit of value, std, start and the bounds
  double value = 0.0;  ///< calibrated value
  double std = 0.0;  ///< standard deviation; NaN when the covariance is not available
  double start = 0.0;  ///< value in IpaCalibrationOptions::start
  /// Lower end of the search range: the parameter's physical range or the given bound.
  double lower = 0.0, upper = 0.0;  ///< upper end of the search range
  bool at_bound = false;   ///< ended within 1e-6 of the range width from a bound
  bool determined = true;  ///< false: the data do not determine it (see the header comment)
};

/// A pair of calibrated parameters whose estimates are strongly correlated: the data
/// determine mainly a combination of the two.
struct ParameterCorrelation {
  /// TOML key of the first parameter of the pair.
  std::string first, second;  ///< TOML key of the second parameter
  double correlation = 0.0;   ///< correlation coefficient rho of the two estimates, -1..1
};

/// How well the twin reproduces one experiment before and after the calibration.
struct CalibrationExperimentFit {
  std::string name;          ///< CalibrationExperiment::name, or the data's source
  Eigen::Index samples = 0;  ///< samples of the experiment in the cost
  double initial_fit_percent = 0.0;  ///< with the starting parameters
  double fit_percent = 0.0;          ///< with the calibrated parameters
  Eigen::VectorXd simulated;         ///< calibrated twin's output on the samples
};

/// Result of CalibrateIpa: the calibrated parameters, their uncertainty and the fits.
struct IpaCalibrationSummary {
  /// convergence, no_convergence (iteration limit; last iterate kept) or
  /// failure (no usable result: the simulation failed at the start, ...).
  Termination termination = Termination::kFailure;
  std::string message;  ///< Ceres' message, or why no usable result was obtained
  IpaParameters parameters;  ///< start with the free parameters replaced
  std::vector<CalibratedParameter> estimates;  ///< one per free parameter, in their order
  std::vector<CalibrationExperimentFit> experiments;  ///< one per experiment, in input order
  std::vector<ParameterCorrelation> correlations;  ///< |rho| >= correlation_threshold
  std::vector<std::string> warnings;               ///< undetermined parameters, bounds reached, ...
  int iterations = 0;  ///< Levenberg-Marquardt iterations
  /// Cost at the start: 1/2 sum_e w_e (1 - fit_e / 100)^2 (Ceres' cost of the residuals
  /// (yhat - y) sqrt(w_e) / |y - mean y| of each experiment), dimensionless.
  double initial_cost = 0.0, final_cost = 0.0;  ///< cost at the calibrated parameters
  long long simulations = 0;  ///< simulator runs of whole experiments
  double seconds = 0.0;       ///< wall time of the solve
  /// One line: "IPA calibration: convergence, 12 iterations, cost 0.08 -> 0.002, 250
  /// simulations, 3.10 s; step fit 95.20 %" (one fit per experiment).
  std::string BriefReport() const;
};

/// Free parameters when none are named: force mode: inlet and exhaust
/// conductance and critical ratio, bore, open delay; position mode adds mass,
/// viscous and Coulomb friction.
std::vector<std::string> DefaultCalibrationParameters(IpaMode mode);

/// Free parameters when none are named, for a calibration that starts from
/// `start`: DefaultCalibrationParameters(start.mode), and in force mode the
/// sensor filter's time constant when `start` has a sensor filter (> 0; the
/// default twin's 0.216 s): there it is the dominant lag of the force, which
/// no valve parameter can stand in for.
std::vector<std::string> DefaultCalibrationParameters(const IpaParameters& start);

/// The model's output on an experiment's samples: the simulator with
/// `parameters` (noise-free, no quantization) driven by the data's input.
/// @throws InvalidArgument for invalid parameters or non-uniform data;
///         std::runtime_error when the ODE integration fails.
Eigen::VectorXd SimulateIpaOnData(
    const IpaParameters& parameters, const Dataset& data,
    CalibrationInitialState initial_state = CalibrationInitialState::kMeasured, double warmup = 2.0,
    double integration_tolerance = 1e-8);

/// Calibrates the free parameters on the experiments (see the header comment).
/// @throws InvalidArgument (at the API boundary, naming the offending values)
///   for no experiments, invalid options, an unknown or non-calibratable
///   parameter name, bounds that are empty or exclude the start, an
///   experiment whose input never changes ("no excitation"), fewer samples
///   than free parameters, non-uniform sampling, or a data set without a
///   single input/output. Numerical failure is reported in the summary.
IpaCalibrationSummary CalibrateIpa(const std::vector<CalibrationExperiment>& experiments,
                                   const IpaCalibrationOptions& options);

}  // namespace pneumid
