// Tuning to specifications: settings of an MPC, DMC or PID controller chosen
// from a model for a target closed-loop response time and overshoot, checked
// against model error and reviewed before the controller runs.
//
// Specification: response time t_r (10-90 % rise time, or 2 % settling time),
// maximum overshoot OS (percent), aggressiveness a in [0, 1] (0 robust,
// 1 aggressive, as the single slider of MATLAB's tuners) and input limits.
// Without t_r, MPC and DMC aim at the fastest design that passes the
// robustness rows below (t_r = t* = the response time of lambda_f), as fast
// as the model, the horizons, the input limits and the robustness demanded
// allow; PID takes t_r from the model's FOPDT description K, tau, theta
// (tuning.hpp, FopdtFromModel), about the open-loop time constant:
//   rise:      t_r = tau + theta        (2.2 times faster than open loop)
//   settling:  t_r = 2 tau + theta
// The knob shifts the response time aimed at and the robustness demanded:
//   t* = t_r 1.5^(1 - 2a)               (a = 0.5: t* = t_r; a given t_r only)
//   OS_rob = OS (1 + 4a) + 0.05         (overshoot allowed under model error:
//                                        3 OS at a = 0.5)
//   t_rob = (1.5 + a) t*                (response time allowed under model error)
//
// Evaluation: a set-point step on the model itself (LinearPlant, exact zoh;
// SimulateClosedLoop of closed_loop.hpp) in deviation variables: a unit step
// without input limits, otherwise from 40 % to 60 % of the output range the
// limits reach at steady state, [K u_min, K u_max]: a set-point change of a
// fifth of the range, in which the response time is the loop's and not only
// the actuator's (a step across most of the range saturates the input and
// is as slow as the input at its limit makes it, whatever the tuning). Robustness rows repeat it
// with the plant's gain +20 %, -20 % and one more sample of dead time; a row
// passes when the loop settles, overshoots at most OS_rob and responds within
// t_rob. The window is 10 max(t*, tau + theta) after the step.
//
// MPC and DMC [3, 4, 5]: P by Shridhar-Cooper from the model's settling time,
// P = round(5 tau/Ts + theta/Ts + 1), M = 5 (M <= P) [5]; then the move
// suppression lambda by a search in log lambda on the closed-loop simulation:
//   feasible(lambda) = nominal OS <= OS and every robustness row settles
//              within OS_rob; for the fastest robust design (no t_r given)
//              also each row responds within (1.5 + a) times the
//              candidate's own nominal response (t_rob of that design) and
//              the QP Hessian's condition is at most 1e8, the review's two
//              other demands (without them a sopdt with tau 1 s and 0.5 s
//              at Ts = 0.01 s got lambda = 1.9e-5, cond 1.1e8 and a failed
//              review);
//   lambda_f = the smallest feasible lambda (a scan of 4 points per decade over
//              lambda_0 10^-6 .. lambda_0 10^4, lambda_0 = lambda_max(A'A)/500
//              the Shridhar-Cooper value, refined by bisection of log lambda);
//   lambda* = argmin_{lambda >= lambda_f} |ln(t(lambda) / t*)|, by bisection
//             of log lambda on t(lambda) = t* (t grows with lambda) when
//             t(lambda_f) < t*, else lambda_f (the fastest that is robust).
// Each candidate is the controller MakeController (controller_factory.hpp)
// builds for its P, M and lambda with the evaluation's input limits (dmc:
// QDMC when a limit is finite, or when the options ask for it; mpc: the
// disturbance model and the Kalman filter's noise variances of the
// options), designed on the model sampled once at Ts (PredictionModel).
// The rule auto of MakeController deploys that same controller: a dmc tuned
// with a finite input limit runs as a QDMC.
// Garriga and Soroush [4] review the rules; Maciejowski [3, ch. 7] the
// trade-off that lambda sets between speed and robustness.
//
// PID [1, 2], as MATLAB's pidtune: a crossover frequency and a phase margin
//   wc = 2 / t*  (t* as a rise time; a settling time counts as 2 rise times),
//   PM = 75 - 30 a degrees (60 at a = 0.5),
// and the discrete loop L(z) = C(z) G(z) of the controller as PidController
// computes it (backward differences, integral of the previous errors,
// derivative on y filtered with N = 10) and the model sampled with a
// zero-order hold:
//   C(z) = Kc [1 + (Ts/Ti) z^-1/(1 - z^-1) + (N Td/(Td + N Ts)) (1 - z^-1)/(1 - beta z^-1)],
//   beta = Td/(Td + N Ts),
// solved for |L(e^{j wc Ts})| = 1 and arg L(e^{j wc Ts}) = -180 + PM: PI when
// the phase C must supply, phi_C = -180 + PM - arg G(e^{j wc Ts}), is at most
// -10 degrees (Ti from arg C = phi_C by bisection, then Kc = 1/|C_1 G| with
// C_1 = C/Kc), else PID with Td = Ti/4 [1, sec. 4.4]. The set-point weight b
// (P = Kc (b r - y)) does not change L; it is the largest b in [0, 1] whose
// step meets OS [1, sec. 3.4] (b = 1 when the loop itself does).
// On a lag-dominant model (tau >> theta) that loop's integral time comes out
// below tau, and its slow closed-loop pole near the PI zero, which b keeps
// from overshooting, leaves a long tail: on the IPA's Hammerstein model
// (tau 0.217 s, theta 0.01 s) Ti = 0.098 s, the steps settled in 1.35 s
// and the commissioned loop overshot 8-10 % on the actuator. The SIMC PI
// [6] for the same t* is designed too (pid.hpp: Ti = min(tau, 4 (tau_c +
// theta)), the pole cancelled, the loop about exp(-theta s)/(tau_c s + 1)):
//   tau_c = t* / 2.2 (rise)   or   (t* - theta) / 3.9 (settling),
// at least theta + Ts/2 (SIMC's bound for robustness), with its own
// set-point weight, and it replaces the shaped design when it passes
// (nominal OS, settled, every robustness row) and settles sooner or the
// shaped one does not pass; when neither passes, when it settles on the
// model and the shaped one does not (AutoTuneOptions::pid_simc; the
// review's "loop shaping" item then names it and both settling times).
//
// Design review (AutoTuneResult::review): nominal stability (the step
// settles), offset-free steady state (a constant output disturbance of 20 %
// of the step is removed: |steady-state error| <= 1e-3 of it), the condition
// number of the QP Hessian (A'A + lambda I for DMC, the MPC's H; ok <= 1e4,
// warning <= 1e8), constraint conflicts (the step must lie in the reachable
// set-point range), robustness and the specification. A fail in any check
// makes the termination kSpecNotMet (or kFailure when no stable design was
// found) with a message that says why.
//
// [1] K. J. Astrom, T. Hagglund, Advanced PID Control, ISA, 2006, ch. 3-4.
// [2] O. Garpinger, T. Hagglund, "Software-based optimal PID design with
//     robustness and noise sensitivity constraints", J. Process Control 33
//     (2015) 90-101.
// [3] J. M. Maciejowski, Predictive Control with Constraints, Prentice Hall,
//     2002.
// [4] J. L. Garriga, M. Soroush, "Model predictive control tuning methods: a
//     review", Ind. Eng. Chem. Res. 49 (2010) 3505-3515.
// [5] R. Shridhar, D. J. Cooper, "A tuning strategy for unconstrained SISO
//     model predictive control", Ind. Eng. Chem. Res. 36 (1997) 729-746.
// [6] S. Skogestad, "Simple analytic rules for model reduction and PID
//     controller tuning", J. Process Control 13 (2003) 291-309.
#pragma once

#include <limits>
#include <string>
#include <vector>

#include <nlohmann/json_fwd.hpp>

#include "pneumid/control/controller.hpp"
#include "pneumid/control/mpc.hpp"
#include "pneumid/control/pid.hpp"
#include "pneumid/control/prediction_model.hpp"
#include "pneumid/control/tuning.hpp"
#include "pneumid/lti/transfer_function.hpp"

namespace pneumid {

/// What the response time of a specification measures.
enum class ResponseMeasure { kRise, kSettling };
/// "rise" (10-90 %), "settling" (2 %).
std::string ToString(ResponseMeasure measure);
/// Inverse of ToString; throws InvalidArgument listing the valid names.
ResponseMeasure ResponseMeasureFromString(const std::string& name);

/// Outcome of one design-review check: passed, passed with a warning (e.g. a Hessian
/// condition number above 1e4), or failed (the termination is then not kConverged).
enum class ReviewStatus { kOk, kWarning, kFail };
/// "ok", "warning", "fail".
std::string ToString(ReviewStatus status);

/// How AutoTune ended.
enum class AutoTuneTermination {
  kConverged,   ///< every check passed
  kSpecNotMet,  ///< the best design found misses the specification (review says why)
  kFailure,     ///< no stable design was found
};
/// "converged", "spec_not_met", "failure".
std::string ToString(AutoTuneTermination termination);

/// Specification of AutoTune: controller type, response time, overshoot, aggressiveness
/// and input limits.
struct AutoTuneOptions {
  /// mpc, dmc or pid (gpc is not tuned this way).
  ControllerType controller = ControllerType::kMpc;
  /// Target response time (s, > 0); NaN = from the model (file comment).
  double response_time = std::numeric_limits<double>::quiet_NaN();
  /// Whether response_time is a 10-90 % rise time (default) or a 2 % settling time.
  ResponseMeasure measure = ResponseMeasure::kRise;
  /// Maximum overshoot of a set-point step (percent, >= 0).
  double max_overshoot = 5.0;
  /// 0 robust .. 1 aggressive (file comment).
  double aggressiveness = 0.5;
  /// Input limits of the controller (and the evaluation).
  InputLimits limits;
  /// Control horizon for mpc/dmc (0 = 5).
  int M = 0;
  /// mpc: the estimator's disturbance model, used in the evaluation as in
  /// the controller it designs (mpc.hpp).
  DisturbanceModel disturbance = DisturbanceModel::kInput;
  /// mpc: the Kalman filter's noise variances (MpcOptions::measurement_noise,
  /// state_noise, disturbance_noise), used in the evaluation as in the
  /// controller it designs; NaN = MpcOptions' defaults (1, 0, 1).
  double measurement_noise = std::numeric_limits<double>::quiet_NaN();
  double state_noise = std::numeric_limits<double>::quiet_NaN();  ///< mpc: see measurement_noise
  double disturbance_noise = std::numeric_limits<double>::quiet_NaN();  ///< mpc: ditto
  /// dmc: QDMC (the moves optimized under the limits) also when no input
  /// limit is finite (ControllerSpec::constrained); with a finite limit the
  /// dmc is a QDMC anyway (file comment).
  bool constrained = false;
  /// pid: also design the SIMC PI for the same response time (file comment)
  /// and keep it when it passes and settles sooner than the loop shaped to
  /// crossover and phase margin, or passes or settles where that loop does
  /// not; false: loop shaping only.
  bool pid_simc = true;
  /// True when the options are usable (controller not gpc, response_time NaN or > 0,
  /// max_overshoot >= 0, aggressiveness in [0, 1], valid limits with u_min < u_max, M >= 0;
  /// mpc: the noise variances NaN or as MpcOptions::IsValid wants them); otherwise false
  /// and *error says why (when error is not null).
  bool IsValid(std::string* error) const;
};

/// Step metrics of one closed-loop simulation (NaN when they do not exist).
struct PredictedMetrics {
  double rise_time = std::numeric_limits<double>::quiet_NaN();          ///< s, 10-90 %
  double overshoot_percent = std::numeric_limits<double>::quiet_NaN();  ///< %
  double settling_time = std::numeric_limits<double>::quiet_NaN();      ///< s, 2 %
  /// The one the specification measures (rise or settling time).
  double response_time = std::numeric_limits<double>::quiet_NaN();
  /// Smallest applied input (deviation from the start, input units).
  double u_min = 0.0, u_max = 0.0;  ///< applied input range (deviation from the start)
  bool settled = false;  ///< the output settled in the 2 % band within the window (finite)
};

/// The evaluation step repeated on a perturbed plant (model error).
struct RobustnessRow {
  std::string name;          ///< "gain +20%", "gain -20%", "dead time +1 sample"
  PredictedMetrics metrics;  ///< step metrics on the perturbed plant
  /// The loop settles, overshoots at most OS_rob and responds within t_rob.
  bool pass = false;
};

/// One check of the design review.
struct ReviewItem {
  std::string check;                        ///< e.g. "nominal stability"
  ReviewStatus status = ReviewStatus::kOk;  ///< ok, warning or fail
  std::string message;  ///< what was measured and, for a warning or fail, why it matters
};

/// Settings chosen by AutoTune, the specification as used, the predicted closed-loop
/// behaviour, the robustness rows and the design review.
struct AutoTuneResult {
  ControllerType controller = ControllerType::kMpc;  ///< the type designed (mpc, dmc or pid)
  double Ts = 0.0;                                   ///< sample time of the design, s
  /// mpc/dmc settings.
  int P = 0;
  int M = 0;  ///< control horizon, samples (mpc/dmc)
  /// Move suppression lambda* (mpc/dmc; NaN for pid), see the file comment.
  double lambda = std::numeric_limits<double>::quiet_NaN();
  /// pid settings (Ti infinite = no integral action).
  PidGains pid;
  double setpoint_weight = 1.0;     ///< b
  double derivative_filter = 10.0;  ///< N
  /// pid design targets and what the discrete loop achieves.
  double crossover_target = std::numeric_limits<double>::quiet_NaN();     ///< rad/s
  double phase_margin_target = std::numeric_limits<double>::quiet_NaN();  ///< deg
  double crossover = std::numeric_limits<double>::quiet_NaN();            ///< rad/s
  double phase_margin = std::numeric_limits<double>::quiet_NaN();         ///< deg
  double gain_margin = std::numeric_limits<double>::quiet_NaN();          ///< absolute
  /// Specification as used.
  double response_time_target = 0.0;  ///< t_r (given, from the model, or the fastest)
  /// mpc/dmc without a given response time: t_r = t* is the response time of
  /// the fastest robust design (JSON specification.response_time_source).
  bool fastest = false;
  double response_time_aimed = 0.0;                  ///< t* after the knob
  ResponseMeasure measure = ResponseMeasure::kRise;  ///< rise or settling time, as given
  double max_overshoot = 0.0;                        ///< OS, percent, as given
  double aggressiveness = 0.0;                       ///< a in [0, 1], as given
  double robust_overshoot = 0.0;                     ///< OS_rob
  double robust_response_time = 0.0;                 ///< t_rob
  FopdtEstimate fopdt;  ///< K, tau, theta of the model (FopdtFromModel)
  /// The evaluation step (deviation from the operating point at the start).
  double step_from = 0.0, step_to = 1.0;  ///< set-point after the step (output units)
  PredictedMetrics predicted;             ///< nominal step metrics of the chosen settings
  std::vector<RobustnessRow> robustness;  ///< gain +20 %, gain -20 %, dead time +1 sample
  std::vector<ReviewItem> review;         ///< the checks of the design review (file comment)
  double hessian_condition = std::numeric_limits<double>::quiet_NaN();   ///< mpc/dmc
  double steady_state_error = std::numeric_limits<double>::quiet_NaN();  ///< after the load step
  int evaluations = 0;                                              ///< closed-loop simulations run
  AutoTuneTermination termination = AutoTuneTermination::kFailure;  ///< see the review
  /// "specification met (N closed-loop simulations)", or the failed checks.
  std::string message;

  /// The TuningResult of these settings (rule explicit; mpc/dmc), for
  /// MakeController and the like.
  TuningResult ToTuningResult() const;
  /// One line per setting, metric, robustness row and review item.
  std::string FullReport() const;
  /// The JSON form of `pneumid tune --rule auto --json`: rule ("auto"),
  /// controller, P, M, lambda (null for pid), Kc, Ti, Td, b, N (pid),
  /// Ts, specification, predicted, robustness, review, termination, message.
  /// NaN and infinity are written as null.
  nlohmann::ordered_json ToJson() const;
};

/// Settings of options.controller for `model` sampled at Ts (file comment).
/// A specification that cannot be met is not an error: the result holds the
/// best design, a review with status kFail that says why, and termination
/// kSpecNotMet.
/// @throws InvalidArgument for invalid options, Ts <= 0, a discrete model
/// with another sample time, or a model FopdtFromModel rejects (unstable,
/// zero static gain).
AutoTuneResult AutoTune(const TransferFunction& model, double Ts, const AutoTuneOptions& options);
/// AutoTune(model.model(), model.Ts(), options) on a model the design has
/// sampled already: the mpc and dmc candidates are designed on `model`
/// (its sampled transfer function and state space) instead of a second
/// sampling, with the same result.
/// @throws InvalidArgument as above.
AutoTuneResult AutoTune(const PredictionModel& model, const AutoTuneOptions& options);

}  // namespace pneumid
