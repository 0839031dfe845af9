#include "pneumid/control/auto_tuning.hpp"

#include <algorithm>
#include <cmath>
#include <complex>
#include <functional>
#include <memory>
#include <numbers>

#include <fmt/format.h>
#include <Eigen/Eigenvalues>
#include <nlohmann/json.hpp>

#include "pneumid/common/check.hpp"
#include "pneumid/common/enum_names.hpp"
#include "pneumid/control/closed_loop.hpp"
#include "pneumid/control/dmc.hpp"
#include "pneumid/control/mpc.hpp"
#include "pneumid/control/prediction_model.hpp"
#include "pneumid/lti/frequency.hpp"
#include "pneumid/plant/linear_plant.hpp"
#include "pneumid/plant/signal.hpp"
#include "predictive_controller_design.hpp"

namespace pneumid {

namespace {

constexpr EnumName<ResponseMeasure> kMeasureNames[] = {
    {ResponseMeasure::kRise, "rise"},
    {ResponseMeasure::kSettling, "settling"},
};
constexpr EnumName<ReviewStatus> kStatusNames[] = {
    {ReviewStatus::kOk, "ok"},
    {ReviewStatus::kWarning, "warning"},
    {ReviewStatus::kFail, "fail"},
};
constexpr EnumName<AutoTuneTermination> kTerminationNames[] = {
    {AutoTuneTermination::kConverged, "converged"},
    {AutoTuneTermination::kSpecNotMet, "spec_not_met"},
    {AutoTuneTermination::kFailure, "failure"},
};

constexpr double kPi = std::numbers::pi;
constexpr double kDeg = 180.0 / kPi;
constexpr double kOvershootTolerance = 0.05;  // percentage points
constexpr double kTimeTolerance = 0.2;        // relative, response time vs t*
constexpr double kLoadFraction = 0.2;         // load step / set-point step
constexpr double kOffsetTolerance = 1e-3;     // |steady-state error| / |load|
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kInf = std::numeric_limits<double>::infinity();

/// Names of the robustness rows, for Evaluator::plants[1..3].
constexpr const char* kRobustnessRowNames[] = {"gain +20%", "gain -20%", "dead time +1 sample"};
constexpr int kPlantCount = 4;  // nominal and the three robustness rows

/// A set-point step from 0 to `to` at `at` (deviation variables).
class StepSetpoint final : public Signal {
 public:
  StepSetpoint(double to, double at) : to_(to), at_(at) {}
  double operator()(double t) const override { return t >= at_ - 1e-12 ? to_ : 0.0; }
  std::string ToString() const override { return fmt::format("step:from=0,to={},at={}", to_, at_); }

 private:
  double to_, at_;
};

/// What a closed-loop evaluation needs: the controller for a design, the
/// plant models, the step and the window.
struct Evaluator {
  double Ts = 0.0;
  double step = 1.0;    // set-point step (deviation)
  double t_step = 0.0;  // when it happens
  double window = 1.0;  // s after the step
  InputLimits limits;   // deviation limits
  ResponseMeasure measure = ResponseMeasure::kRise;
  std::vector<TransferFunction> plants;  // nominal, gain +20 %, gain -20 %, dead time +1
  int evaluations = 0;

  PredictedMetrics Run(Controller& controller, int plant_index) {
    ++evaluations;
    LinearPlant plant(plants[plant_index], Ts);
    StepSetpoint setpoint(step, t_step);
    ClosedLoopOptions loop_options;
    loop_options.duration = t_step + window;
    loop_options.actuator = limits;
    const ClosedLoopResult loop = SimulateClosedLoop(controller, plant, setpoint, loop_options);
    PredictedMetrics metrics;
    metrics.rise_time = loop.metrics.rise_time;
    metrics.overshoot_percent = loop.metrics.overshoot_percent;
    metrics.settling_time = loop.metrics.settling_time;
    metrics.settled = loop.metrics.settled && std::isfinite(loop.metrics.settling_time);
    metrics.response_time =
        measure == ResponseMeasure::kRise ? metrics.rise_time : metrics.settling_time;
    metrics.u_min = loop.metrics.u_min;
    metrics.u_max = loop.metrics.u_max;
    // A loop that grows without bound has no meaningful overshoot.
    if (!loop.y.allFinite()) {
      metrics.settled = false;
      metrics.overshoot_percent = kInf;
    }
    return metrics;
  }

  /// Steady-state error after a constant output disturbance of
  /// kLoadFraction * step at constant set-point 0.
  double LoadSteadyStateError(Controller& controller) {
    ++evaluations;
    LinearPlant plant(plants[0], Ts);
    StepSetpoint setpoint(0.0, 0.0);
    ClosedLoopOptions loop_options;
    loop_options.duration = t_step + window;
    loop_options.actuator = limits;
    loop_options.load_steps = {{t_step, -kLoadFraction * step}};
    const ClosedLoopResult loop = SimulateClosedLoop(controller, plant, setpoint, loop_options);
    if (!loop.y.allFinite()) return kInf;
    return loop.metrics.steady_state_error;
  }
};

double OrInf(double v) { return std::isfinite(v) ? v : kInf; }

bool Finite(const InputLimits& l) { return std::isfinite(l.u_min) || std::isfinite(l.u_max); }

std::string Seconds(double t) { return std::isfinite(t) ? fmt::format("{:.4g} s", t) : "none"; }

/// Value of the discrete PID (without Kc) at z = e^{j w Ts}, as PidController computes it.
std::complex<double> PidShape(double Ti, double Td, double N, double Ts, double w) {
  const std::complex<double> zinv = std::exp(std::complex<double>(0.0, -w * Ts));
  std::complex<double> shape = 1.0;
  if (std::isfinite(Ti)) shape += (Ts / Ti) * zinv / (1.0 - zinv);
  if (Td > 0.0) {
    const double beta = Td / (Td + N * Ts);
    shape += (N * Td / (Td + N * Ts)) * (1.0 - zinv) / (1.0 - beta * zinv);
  }
  return shape;
}

struct LoopMargins {
  double crossover = kNaN;
  double phase_margin = kNaN;
  double gain_margin = kInf;
};

/// Crossover, phase and gain margin of Kc C1(z) G(z) on a dense grid up to
/// the Nyquist frequency: the first frequency where |L| falls through 1, the
/// phase margin there, and the smallest 1/|L| where the phase crosses -180.
LoopMargins DiscreteLoopMargins(const TransferFunction& Gd, const PidGains& gains, double N,
                                double Ts) {
  const double wn = kPi / Ts;
  const Eigen::VectorXd w = LogSpace(std::log10(wn) - 5.0, std::log10(wn * 0.9999), 4000);
  const BodeData plant = Bode(Gd, w);
  const int count = static_cast<int>(w.size());
  Eigen::VectorXd mag(count), phase(count);  // of the loop L
  for (int i = 0; i < count; ++i) {
    const std::complex<double> controller = gains.Kc * PidShape(gains.Ti, gains.Td, N, Ts, w(i));
    mag(i) = std::abs(controller) * plant.magnitude(i);
    phase(i) = std::arg(controller) * kDeg + plant.phase_deg(i);
  }
  // The loop's phase at low frequency lies in (-180, 180] (-90 with integral
  // action, 0 without): a reverse-acting plant and controller (K < 0, Kc < 0)
  // each add 180 and put it a turn away, and K = -2 got a phase margin of
  // 433 deg and a gain margin 4.4 times its mirror's (K = +2: 72.8 deg, 5.47).
  const double turns = std::ceil((phase(0) - 180.0) / 360.0);
  phase.array() -= 360.0 * turns;
  LoopMargins margins;
  for (int i = 1; i < count; ++i) {
    if (std::isnan(margins.crossover) && (mag(i - 1) - 1.0) * (mag(i) - 1.0) <= 0.0 &&
        mag(i - 1) > 1.0) {
      const double frac = std::log(mag(i - 1)) / (std::log(mag(i - 1)) - std::log(mag(i)));
      margins.crossover =
          std::exp(std::log(w(i - 1)) + frac * (std::log(w(i)) - std::log(w(i - 1))));
      margins.phase_margin = 180.0 + phase(i - 1) + frac * (phase(i) - phase(i - 1));
    }
    const double above_prev = phase(i - 1) + 180.0, above = phase(i) + 180.0;
    if (above_prev * above <= 0.0 && above_prev != above) {
      const double frac = above_prev / (above_prev - above);
      const double log_mag =
          std::log(mag(i - 1)) + frac * (std::log(mag(i)) - std::log(mag(i - 1)));
      margins.gain_margin = std::min(margins.gain_margin, std::exp(-log_mag));
    }
  }
  return margins;
}

/// Unwrapped phase (deg) and magnitude of Gd at w.
std::pair<double, double> PlantAt(const TransferFunction& Gd, double w) {
  const Eigen::VectorXd grid = LogSpace(std::log10(w) - 4.0, std::log10(w), 400);
  const BodeData bode = Bode(Gd, grid);
  return {bode.magnitude(bode.magnitude.size() - 1), bode.phase_deg(bode.phase_deg.size() - 1)};
}

// ---------------------------------------------------------------------------
// Specification and evaluation set-up

/// The input before and after the evaluation step (absolute input units).
struct InputStep {
  double from = 0.0;
  double to = 1.0;
};

/// The result with the specification as used: t_r (given or from the model's
/// FOPDT description), t* after the knob, OS_rob and t_rob (file comment).
AutoTuneResult SpecificationAsUsed(const TransferFunction& model, double Ts,
                                   const AutoTuneOptions& options) {
  AutoTuneResult result;
  result.controller = options.controller;
  result.Ts = Ts;
  result.measure = options.measure;
  result.max_overshoot = options.max_overshoot;
  result.aggressiveness = options.aggressiveness;
  result.fopdt = FopdtFromModel(model);
  const FopdtEstimate& fopdt = result.fopdt;
  const double a = options.aggressiveness;
  result.response_time_target =
      std::isnan(options.response_time)
          ? (options.measure == ResponseMeasure::kRise ? fopdt.tau + fopdt.theta
                                                       : 2.0 * fopdt.tau + fopdt.theta)
          : options.response_time;
  result.response_time_aimed = result.response_time_target * std::pow(1.5, 1.0 - 2.0 * a);
  result.robust_overshoot = options.max_overshoot * (1.0 + 4.0 * a) + kOvershootTolerance;
  result.robust_response_time = (1.5 + a) * result.response_time_aimed;
  // mpc/dmc without a response time: the fastest robust design (file comment).
  result.fastest = std::isnan(options.response_time) && options.controller != ControllerType::kPid;
  return result;
}

/// The evaluation step in input space: 40 % to 60 % of the input range between
/// two limits, one to two output units inside a single limit, else a unit
/// output step.
InputStep EvaluationInputStep(const InputLimits& limits, double K) {
  InputStep input{0.0, 1.0 / K};
  if (std::isfinite(limits.u_min) && std::isfinite(limits.u_max)) {
    input.from = limits.u_min + 0.4 * (limits.u_max - limits.u_min);
    input.to = limits.u_min + 0.6 * (limits.u_max - limits.u_min);
  } else if (std::isfinite(limits.u_min)) {
    input.from = limits.u_min + 1.0 / std::abs(K);
    input.to = limits.u_min + 2.0 / std::abs(K);
  } else if (std::isfinite(limits.u_max)) {
    input.from = limits.u_max - 2.0 / std::abs(K);
    input.to = limits.u_max - 1.0 / std::abs(K);
  }
  return input;
}

/// Largest evaluation window in samples (AutoTune simulates every candidate over it).
constexpr double kMaxEvaluationSamples = 1e6;

/// The evaluation in deviation variables: the step of `result`, the window of
/// 10 max(t*, tau + theta) after it, the limits relative to the input before
/// the step, and the nominal and perturbed plants of the robustness rows.
Evaluator MakeEvaluator(const TransferFunction& model, double Ts, const AutoTuneOptions& options,
                        const AutoTuneResult& result, double input_before_step) {
  const FopdtEstimate& fopdt = result.fopdt;
  Evaluator evaluator;
  evaluator.Ts = Ts;
  evaluator.step = result.step_to - result.step_from;
  evaluator.t_step = 5.0 * Ts;
  evaluator.window =
      std::max(10.0 * std::max(result.response_time_aimed, fopdt.tau + fopdt.theta), 50.0 * Ts);
  // Every candidate is simulated over the window: a response time or a
  // time constant of thousands of sample times would take minutes and
  // gigabytes, and asks for a longer sample time.
  PNEUMID_CHECK(evaluator.window / Ts <= kMaxEvaluationSamples,
                "the evaluation window, 10 max(t* = {:g} s, tau + theta = {:g} s) = {:g} s, holds "
                "{:.3g} samples of Ts = {:g} s, more than the {:g} the tuner simulates: ask for a "
                "response time of at most {:.3g} s{}",
                result.response_time_aimed, fopdt.tau + fopdt.theta, evaluator.window,
                evaluator.window / Ts, Ts, kMaxEvaluationSamples, kMaxEvaluationSamples * Ts / 10.0,
                fopdt.tau + fopdt.theta > kMaxEvaluationSamples * Ts / 10.0
                    ? " and a longer sample time (the model's time scale needs one)"
                    : " or choose a longer sample time");
  evaluator.limits = options.limits;
  evaluator.limits.u_min -= input_before_step;
  evaluator.limits.u_max -= input_before_step;
  evaluator.measure = options.measure;
  const double ts_model = model.IsContinuous() ? 0.0 : Ts;
  evaluator.plants = {model,
                      TransferFunction(model.num() * 1.2, model.den(), ts_model, model.delay()),
                      TransferFunction(model.num() * 0.8, model.den(), ts_model, model.delay()),
                      model.WithDelay(model.delay() + Ts)};
  return evaluator;
}

/// The nominal step of a candidate: it settles and overshoots at most OS.
bool NominalStepMeetsOvershoot(const PredictedMetrics& metrics, double max_overshoot) {
  return metrics.settled && metrics.overshoot_percent <= max_overshoot + kOvershootTolerance;
}

/// A robustness row during the search: stability and overshoot only.
bool RobustRowStable(const PredictedMetrics& metrics, double robust_overshoot) {
  return metrics.settled && metrics.overshoot_percent <= robust_overshoot;
}

/// A robustness row of the chosen design: it settles, overshoots at most
/// OS_rob and responds within t_rob.
bool RobustRowPasses(const PredictedMetrics& metrics, const AutoTuneResult& result) {
  return metrics.settled && metrics.overshoot_percent <= result.robust_overshoot &&
         OrInf(metrics.response_time) <= result.robust_response_time;
}

/// What the candidate search settled on, for the final evaluation and the review.
struct ChosenDesign {
  /// A new controller of the chosen settings (each evaluation starts from rest).
  std::function<std::unique_ptr<Controller>()> make_controller;
  Eigen::MatrixXd hessian;  // QP Hessian of the chosen settings (mpc/dmc; empty for pid)
  // mpc/dmc: lambda_f and its response time, the fastest robust design (NaN if none).
  double lambda_fastest = kNaN;
  double t_fastest = kNaN;
};

// ---------------------------------------------------------------------------
// mpc/dmc: the search over the move suppression lambda

/// Condition number of a symmetric matrix (infinite when it is singular).
double ConditionNumber(const Eigen::MatrixXd& symmetric) {
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(symmetric, Eigen::EigenvaluesOnly);
  const double eig_min = eig.eigenvalues().minCoeff(), eig_max = eig.eigenvalues().maxCoeff();
  return eig_min > 0.0 ? eig_max / eig_min : kInf;
}

/// The review's bound on the QP Hessian condition (above it: fail).
constexpr double kMaxHessianCondition = 1e8;

/// The mpc or dmc controller of the horizons P, M for a move suppression
/// lambda, built as MakeController builds it (MakePredictiveController) on
/// the design's sampled model.
struct PredictiveControllerFactory {
  const PredictionModel* model = nullptr;  // sampled once for the design
  /// type, the explicit rule with P and M, the deviation limits, dmc:
  /// constrained, mpc: the disturbance model and the noise variances; lambda
  /// set by Make.
  ControllerSpec spec;

  std::unique_ptr<Controller> Make(double lambda) const {
    ControllerSpec candidate = spec;
    candidate.tuning.lambda = lambda;
    return internal::MakePredictiveController(*model, candidate).controller;
  }

  /// The QP Hessian of lambda: the MPC's H, or A'A + lambda I for DMC.
  Eigen::MatrixXd Hessian(double lambda) const { return Hessian(*Make(lambda), lambda); }

  /// The same of `controller`, made by Make(lambda).
  static Eigen::MatrixXd Hessian(const Controller& made, double lambda) {
    if (const auto* mpc = dynamic_cast<const MpcController*>(&made)) return mpc->hessian();
    const auto* dmc = dynamic_cast<const DmcController*>(&made);
    PNEUMID_CHECK(dmc != nullptr, "the auto-tuner designs mpc or dmc, got {}", made.Describe());
    const Eigen::MatrixXd& A = dmc->dynamic_matrix();
    return A.transpose() * A + lambda * Eigen::MatrixXd::Identity(A.cols(), A.cols());
  }
};

/// Closed-loop evaluation of the lambda candidates of the search.
class LambdaCandidates {
 public:
  /// `robust_time_factor`: for the fastest robust design (no response time
  /// given), each robustness row must also respond within this factor of the
  /// candidate's own nominal response time, and the QP Hessian's condition
  /// must stay within kMaxHessianCondition, as the review then asks of the
  /// design (its t* is that response time); NaN otherwise.
  LambdaCandidates(const PredictiveControllerFactory& factory, Evaluator& evaluator,
                   double max_overshoot, double robust_overshoot,
                   double robust_time_factor = kNaN)
      : factory_(factory),
        evaluator_(evaluator),
        max_overshoot_(max_overshoot),
        robust_overshoot_(robust_overshoot),
        robust_time_factor_(robust_time_factor) {}

  /// feasible(lambda): the nominal step meets OS and every robustness row
  /// settles within OS_rob (the rows stop at the first that does not); for
  /// the fastest robust design also the response times and the condition
  /// above. Without the latter a plant twice as slow as the reach of the
  /// move suppression (sopdt tau 1 s and 0.5 s at Ts = 0.01 s) got lambda =
  /// 1.9e-5, cond(H) = 1.1e8, and a gain -20 % row 2.4 times slower than
  /// the nominal step: a design its own review failed.
  bool Feasible(double lambda) {
    const std::unique_ptr<Controller> controller = factory_.Make(lambda);
    const PredictedMetrics nominal = evaluator_.Run(*controller, 0);
    bool feasible = NominalStepMeetsOvershoot(nominal, max_overshoot_);
    const bool fastest = !std::isnan(robust_time_factor_);
    if (feasible && fastest)
      feasible = ConditionNumber(PredictiveControllerFactory::Hessian(*controller, lambda)) <=
                 kMaxHessianCondition;
    const double t_allowed = !std::isnan(rows_within_) ? rows_within_
                             : fastest ? robust_time_factor_ * OrInf(nominal.response_time)
                                       : kInf;
    for (int i = 1; feasible && i < kPlantCount; ++i) {
      const PredictedMetrics row = evaluator_.Run(*controller, i);
      feasible = RobustRowStable(row, robust_overshoot_) && OrInf(row.response_time) <= t_allowed;
    }
    return feasible;
  }

  /// From now on the robustness rows of the fastest robust design must
  /// respond within `t` s (the review's bound, once t* is known).
  void HoldRowsWithin(double t) { rows_within_ = t; }

  /// t(lambda): the nominal response time (infinite when there is none).
  double ResponseTime(double lambda) {
    const std::unique_ptr<Controller> controller = factory_.Make(lambda);
    return OrInf(evaluator_.Run(*controller, 0).response_time);
  }

 private:
  const PredictiveControllerFactory& factory_;
  Evaluator& evaluator_;
  double max_overshoot_;
  double robust_overshoot_;
  double robust_time_factor_;
  double rows_within_ = kNaN;
};

/// lambda_f, the smallest feasible lambda: an ascending scan of 4 points per
/// decade over lambda_0 10^-6 .. lambda_0 10^4, refined by bisection of
/// log lambda between the last infeasible and the first feasible point; NaN
/// when no point of the scan is feasible.
double SmallestFeasibleLambda(LambdaCandidates& candidates, double lambda0) {
  const double lo_exp = -6.0, hi_exp = 4.0;
  double lambda_feasible = kNaN;
  double lambda_infeasible = kNaN;  // the scan point before it
  for (int k = 0; lo_exp + 0.25 * k <= hi_exp + 1e-9; ++k) {
    const double lambda = lambda0 * std::pow(10.0, lo_exp + 0.25 * k);
    if (candidates.Feasible(lambda)) {
      lambda_feasible = lambda;
      break;
    }
    lambda_infeasible = lambda;
  }
  if (std::isnan(lambda_feasible) || std::isnan(lambda_infeasible)) return lambda_feasible;
  double lo = std::log(lambda_infeasible), hi = std::log(lambda_feasible);
  for (int i = 0; i < 12; ++i) {
    const double mid = 0.5 * (lo + hi);
    if (candidates.Feasible(std::exp(mid)))
      hi = mid;
    else
      lo = mid;
  }
  return std::exp(hi);
}

/// lambda* when lambda_f responds faster than t*: bracket t(lambda) = t* by
/// decades above lambda_f (t grows with lambda), then bisect log lambda and
/// take the end whose |ln(t / t*)| is smaller; the last decade tried when
/// none brackets it.
double LambdaForResponseTime(LambdaCandidates& candidates, double lambda_f, double t_aim) {
  double lo = std::log(lambda_f), hi = lo;
  bool bracketed = false;
  for (int i = 0; i < 12 && !bracketed; ++i) {
    lo = hi;
    hi += std::log(10.0);
    bracketed = candidates.ResponseTime(std::exp(hi)) >= t_aim;
  }
  if (!bracketed) return std::exp(hi);
  for (int i = 0; i < 30 && hi - lo > 1e-4; ++i) {
    const double mid = 0.5 * (lo + hi);
    if (candidates.ResponseTime(std::exp(mid)) < t_aim)
      lo = mid;
    else
      hi = mid;
  }
  const double t_lo = candidates.ResponseTime(std::exp(lo));
  const double t_hi = candidates.ResponseTime(std::exp(hi));
  return std::abs(std::log(t_lo / t_aim)) <= std::abs(std::log(t_hi / t_aim)) ? std::exp(lo)
                                                                              : std::exp(hi);
}

/// lambda* when even lambda_f is too slow: the response is limited by the
/// model, the horizons or the actuator, and flat in lambda. The largest lambda
/// whose response time is at most t_ok (hardly slower than lambda_f) is better
/// conditioned and as fast; it is taken when feasible, else lambda_f.
double LargestLambdaAsFast(LambdaCandidates& candidates, double lambda_f, double t_ok) {
  double lo = std::log(lambda_f), hi = lo;
  bool bracketed = false;
  for (int i = 0; i < 12 && !bracketed; ++i) {
    lo = hi;
    hi += std::log(10.0);
    bracketed = candidates.ResponseTime(std::exp(hi)) > t_ok;
  }
  if (bracketed) {
    for (int i = 0; i < 30 && hi - lo > 1e-3; ++i) {
      const double mid = 0.5 * (lo + hi);
      if (candidates.ResponseTime(std::exp(mid)) <= t_ok)
        lo = mid;
      else
        hi = mid;
    }
  }
  return candidates.Feasible(std::exp(lo)) ? std::exp(lo) : lambda_f;
}

/// mpc/dmc (file comment): P and M by Shridhar-Cooper, then lambda* by the
/// closed-loop search. Without a given response time the target becomes the
/// response time of lambda_f, the fastest robust design.
ChosenDesign SearchPredictiveDesign(const PredictionModel& model, const AutoTuneOptions& options,
                                    Evaluator& evaluator, AutoTuneResult& result) {
  auto factory = std::make_shared<PredictiveControllerFactory>();
  factory->model = &model;
  TuningOptions rule_options;
  rule_options.rule = TuningRule::kShridharCooper;
  rule_options.M = options.M;
  const TuningResult base = Tune(model, rule_options);
  result.P = base.P;
  result.M = base.M;
  const double lambda0 = base.lambda_condition;
  ControllerSpec& spec = factory->spec;
  spec.type = options.controller;
  spec.tuning.rule = TuningRule::kExplicit;
  spec.tuning.P = base.P;
  spec.tuning.M = base.M;
  spec.limits = evaluator.limits;
  // DMC optimizes its moves under the limits (QDMC), as the rule auto of
  // MakeController deploys it; the MPC does whenever a limit is finite.
  spec.constrained = spec.type == ControllerType::kDmc &&
                     internal::AutoTunedDmcIsConstrained(evaluator.limits, options.constrained);
  spec.disturbance = options.disturbance;
  spec.measurement_noise = options.measurement_noise;
  spec.state_noise = options.state_noise;
  spec.disturbance_noise = options.disturbance_noise;

  LambdaCandidates candidates(*factory, evaluator, options.max_overshoot, result.robust_overshoot,
                              result.fastest ? 1.5 + options.aggressiveness : kNaN);
  ChosenDesign chosen;
  // Nothing robust: take the Shridhar-Cooper value and let the review say why.
  double lambda_star = lambda0;
  const double lambda_f = SmallestFeasibleLambda(candidates, lambda0);
  if (!std::isnan(lambda_f)) {
    chosen.lambda_fastest = lambda_f;
    chosen.t_fastest = candidates.ResponseTime(lambda_f);
    if (result.fastest && std::isfinite(chosen.t_fastest)) {
      // The target is the fastest robust response itself.
      result.response_time_target = result.response_time_aimed = chosen.t_fastest;
      result.robust_response_time = (1.5 + options.aggressiveness) * result.response_time_aimed;
    }
    const double t_aim = result.response_time_aimed;
    if (chosen.t_fastest < t_aim) {
      lambda_star = LambdaForResponseTime(candidates, lambda_f, t_aim);
    } else {
      // Hardly slower: 2 % of t* (0.5 % for the fastest robust design).
      const double t_ok = chosen.t_fastest + (result.fastest ? 0.005 : 0.02) * t_aim;
      // The rows of a design hardly slower than lambda_f are held to the
      // review's bound, (1.5 + a) t* with t* lambda_f's response.
      if (result.fastest) candidates.HoldRowsWithin(result.robust_response_time);
      lambda_star = LargestLambdaAsFast(candidates, lambda_f, t_ok);
    }
  }
  result.lambda = lambda_star;
  chosen.make_controller = [factory, lambda_star] { return factory->Make(lambda_star); };
  chosen.hessian = factory->Hessian(lambda_star);
  return chosen;
}

// ---------------------------------------------------------------------------
// pid: loop shaping and the set-point weight

/// The PID controller of the designed gains for a set-point weight b.
struct PidControllerFactory {
  double Ts = 0.0;
  PidGains gains;
  double N = 10.0;     // derivative filter
  InputLimits limits;  // deviation limits

  std::unique_ptr<Controller> Make(double setpoint_weight) const {
    PidOptions pid_options;
    pid_options.gains = gains;
    pid_options.setpoint_weight = setpoint_weight;
    pid_options.derivative_filter = N;
    pid_options.limits = limits;
    return std::make_unique<PidController>(Ts, pid_options);
  }
};

/// arg C1(e^{j w Ts}) in degrees of a PI (Td = 0) or PID (Td = Ti/4) with Ti.
double ControllerPhaseDeg(double Ti, bool use_pid, double N, double Ts, double w) {
  return std::arg(PidShape(Ti, use_pid ? Ti / 4.0 : 0.0, N, Ts, w)) * kDeg;
}

struct IntegralTimeSolution {
  double Ti = kNaN;
  bool solved = false;  // false: Ti is the grid point closest to the phase asked for
};

/// Ti from arg C1(Ti) = phi_c at w: a log grid of Ti over 1e-4/w .. 1e4/w,
/// the first step that brackets the solution, bisection within it.
IntegralTimeSolution SolveIntegralTime(double phi_c, bool use_pid, double N, double Ts, double w) {
  auto phase_error = [&](double log_Ti) {
    return ControllerPhaseDeg(std::exp(log_Ti), use_pid, N, Ts, w) - phi_c;
  };
  const int grid_steps = 400;
  double closest_Ti = kNaN, closest_error = 1e300;
  const double lo = std::log(1e-4 / w), hi = std::log(1e4 / w);
  double x_prev = lo, e_prev = phase_error(lo);
  for (int i = 1; i <= grid_steps; ++i) {
    const double x = lo + (hi - lo) * i / grid_steps;
    const double e = phase_error(x);
    if (std::abs(e) < closest_error) {
      closest_error = std::abs(e);
      closest_Ti = std::exp(x);
    }
    if (e_prev * e <= 0.0) {
      double xa = x_prev, xb = x, ea = e_prev;
      for (int k = 0; k < 60; ++k) {
        const double xm = 0.5 * (xa + xb);
        const double em = phase_error(xm);
        if (ea * em <= 0.0)
          xb = xm;
        else {
          xa = xm;
          ea = em;
        }
      }
      return {std::exp(0.5 * (xa + xb)), true};
    }
    x_prev = x;
    e_prev = e;
  }
  return {closest_Ti, false};
}

/// The PID loop-shaping design point: what the response time asks for and
/// where the loop was designed.
struct PidDesignPoint {
  double wc = kNaN;        // crossover the response time asks for, rad/s
  double wn = kNaN;        // Nyquist frequency, rad/s
  double w_design = kNaN;  // wc, at most half the Nyquist frequency
  double phi_c = kNaN;     // phase the controller must supply at w_design, deg
  bool use_pid = false;    // PID (Td = Ti/4), else PI
  bool solved = false;     // Ti meets phi_c
};

/// The "loop shaping" review item of the PID design.
ReviewItem LoopShapingItem(const PidDesignPoint& point, const AutoTuneResult& result) {
  if (!point.solved || point.wc > 0.5 * point.wn) {
    return {"loop shaping", ReviewStatus::kFail,
            point.wc > 0.5 * point.wn
                ? fmt::format("the crossover 2/t* = {:.4g} rad/s the response time asks for "
                              "exceeds half the Nyquist frequency ({:.4g} rad/s): designed at "
                              "{:.4g} rad/s; sample faster or ask for a slower response",
                              point.wc, 0.5 * point.wn, point.w_design)
                : fmt::format("a {} cannot give the phase margin {:.3g} deg at {:.4g} rad/s (the "
                              "controller would need {:.1f} deg of phase); closest Ti taken",
                              point.use_pid ? "PID" : "PI", result.phase_margin_target,
                              point.w_design, point.phi_c)};
  }
  return {"loop shaping", ReviewStatus::kOk,
          fmt::format("{} with crossover {:.4g} rad/s (target {:.4g}), phase "
                      "margin {:.3g} deg (target {:.3g}), gain margin {:.3g}",
                      point.use_pid ? "PID (Td = Ti/4)" : "PI", result.crossover,
                      result.crossover_target, result.phase_margin, result.phase_margin_target,
                      result.gain_margin)};
}

/// The crossover and margins the discrete loop of result.pid (derivative
/// filter result.derivative_filter) achieves on the zoh model Gd, into result.
void StoreLoopMargins(const TransferFunction& Gd, double Ts, AutoTuneResult& result) {
  const LoopMargins margins = DiscreteLoopMargins(Gd, result.pid, result.derivative_filter, Ts);
  result.crossover = margins.crossover;
  result.phase_margin = margins.phase_margin;
  result.gain_margin = margins.gain_margin;
}

/// PID loop shaping (file comment): wc and PM from t* and the knob, PI or PID
/// from the phase the controller must supply, Ti and Kc on the discrete loop,
/// the margins it achieves and the "loop shaping" review item.
void ShapePidLoop(const TransferFunction& model, double Ts, const AutoTuneOptions& options,
                  AutoTuneResult& result) {
  const TransferFunction Gd = LinearPlant(model, Ts).model();
  const double sgn = result.fopdt.K > 0.0 ? 1.0 : -1.0;
  PidDesignPoint point;
  point.wn = kPi / Ts;
  point.wc = (options.measure == ResponseMeasure::kRise ? 2.0 : 4.0) / result.response_time_aimed;
  result.crossover_target = point.wc;
  result.phase_margin_target = 75.0 - 30.0 * options.aggressiveness;
  point.w_design = std::min(point.wc, 0.5 * point.wn);
  const auto [plant_mag, plant_phase] = PlantAt(Gd, point.w_design);
  const double phase_of_sgn_G = plant_phase - (sgn < 0.0 ? 180.0 : 0.0);  // design on sgn * G
  point.phi_c = -180.0 + result.phase_margin_target - phase_of_sgn_G;
  const double N = result.derivative_filter;
  point.use_pid = point.phi_c > -10.0;
  const IntegralTimeSolution Ti =
      SolveIntegralTime(point.phi_c, point.use_pid, N, Ts, point.w_design);
  point.solved = Ti.solved;
  result.pid.Ti = Ti.Ti;
  result.pid.Td = point.use_pid ? Ti.Ti / 4.0 : 0.0;
  result.pid.Kc =
      sgn / (std::abs(PidShape(Ti.Ti, result.pid.Td, N, Ts, point.w_design)) * plant_mag);
  StoreLoopMargins(Gd, Ts, result);
  result.review.push_back(LoopShapingItem(point, result));
}

/// Set-point weight: the largest b in [0, 1] whose nominal step meets the
/// overshoot spec (b = 1 when the loop itself does), by bisection.
double SetpointWeightForOvershoot(const PidControllerFactory& factory, Evaluator& evaluator,
                                  double max_overshoot) {
  const std::unique_ptr<Controller> controller = factory.Make(1.0);
  const PredictedMetrics metrics = evaluator.Run(*controller, 0);
  if (!(metrics.overshoot_percent > max_overshoot + kOvershootTolerance)) return 1.0;
  double b_lo = 0.0, b_hi = 1.0;
  for (int i = 0; i < 20; ++i) {
    const double b_mid = 0.5 * (b_lo + b_hi);
    const std::unique_ptr<Controller> candidate = factory.Make(b_mid);
    if (evaluator.Run(*candidate, 0).overshoot_percent <= max_overshoot)
      b_lo = b_mid;
    else
      b_hi = b_mid;
  }
  return b_lo;
}

/// The SIMC closed-loop time constant tau_c [pid.hpp, 1] whose response
/// meets t* (result.response_time_aimed): with Ti = tau the loop is about
/// exp(-theta s) / (tau_c s + 1), whose 10-90 % rise takes 2.2 tau_c and whose
/// 2 % settling takes theta + 3.9 tau_c; at least the effective dead time
/// theta + Ts/2, SIMC's "tight control" bound for robustness [1, sec. 4]: on
/// a delay-dominant model (tau 0.1 s, theta 0.3 s) tau_c = t*/2.2 = 0.18 s
/// overshot 14.8 %, tau_c = theta + Ts/2 4.9 %. NaN when the model has no
/// FOPDT description (K, tau > 0, theta >= 0).
double SimcTimeConstant(const AutoTuneResult& result, ResponseMeasure measure, double Ts) {
  const FopdtEstimate& f = result.fopdt;
  const double t = result.response_time_aimed;
  if (!(std::isfinite(f.K) && f.K != 0.0 && f.tau > 0.0 && f.theta >= 0.0 && t > 0.0)) return kNaN;
  const double tau_c = measure == ResponseMeasure::kRise ? t / 2.2 : (t - f.theta) / 3.9;
  return std::max(tau_c, f.theta + Ts / 2.0);
}

/// A PID candidate of DesignPid: its gains, set-point weight and how its step
/// does on the model and on the robustness rows.
struct PidCandidate {
  PidControllerFactory factory;
  double b = 1.0;
  PredictedMetrics nominal;
  bool passes = false;  ///< nominal OS met, settled, every robustness row passes
};

PidCandidate EvaluatePidCandidate(const PidControllerFactory& factory, Evaluator& evaluator,
                                  const AutoTuneOptions& options, const AutoTuneResult& result) {
  PidCandidate c{factory, 1.0, {}, false};
  c.b = SetpointWeightForOvershoot(factory, evaluator, options.max_overshoot);
  c.nominal = evaluator.Run(*factory.Make(c.b), 0);
  c.passes = c.nominal.settled &&
             c.nominal.overshoot_percent <= options.max_overshoot + kOvershootTolerance;
  for (int i = 1; i < kPlantCount && c.passes; ++i)
    c.passes = RobustRowPasses(evaluator.Run(*factory.Make(c.b), i), result);
  return c;
}

/// pid (file comment): loop shaping, then the set-point weight; the SIMC PI
/// for the same response time instead when it settles sooner and passes too,
/// or settles where the shaped loop does not.
ChosenDesign DesignPid(const TransferFunction& model, double Ts, const AutoTuneOptions& options,
                       Evaluator& evaluator, AutoTuneResult& result) {
  ShapePidLoop(model, Ts, options, result);
  PidCandidate chosen_pid = EvaluatePidCandidate(
      {Ts, result.pid, result.derivative_filter, evaluator.limits}, evaluator, options, result);
  const double tau_c = options.pid_simc ? SimcTimeConstant(result, options.measure, Ts) : kNaN;
  if (std::isfinite(tau_c)) {
    const PidGains simc = TunePid(result.fopdt.K, result.fopdt.tau, result.fopdt.theta, Ts,
                                  PidTuningRule::kSimc, tau_c);
    PidCandidate c = EvaluatePidCandidate({Ts, simc, result.derivative_filter, evaluator.limits},
                                          evaluator, options, result);
    // Kept when it passes and settles sooner, or passes where the shaped
    // loop does not; when neither passes, when it settles on the model and
    // the shaped loop does not (a t* too fast for the dead time: a stable
    // loop whose review says so, not an unstable one).
    const bool better =
        c.passes ? !chosen_pid.passes ||
                       c.nominal.settling_time < chosen_pid.nominal.settling_time
                 : !chosen_pid.passes && c.nominal.settled && !chosen_pid.nominal.settled;
    if (better) {
      const PredictedMetrics shaped = chosen_pid.nominal;
      chosen_pid = std::move(c);
      result.pid = simc;
      StoreLoopMargins(LinearPlant(model, Ts).model(), Ts, result);
      result.review.back() = {
          "loop shaping", ReviewStatus::kOk,
          fmt::format("SIMC PI with tau_c = {} (Ti = {}), crossover {:.4g} rad/s, phase margin "
                      "{:.3g} deg, gain margin {:.3g}: its step settles in {} against {} for the "
                      "loop shaped to crossover {:.4g} rad/s and phase margin {:.3g} deg",
                      Seconds(tau_c), Seconds(simc.Ti), result.crossover, result.phase_margin,
                      result.gain_margin, Seconds(chosen_pid.nominal.settling_time),
                      Seconds(shaped.settling_time), result.crossover_target,
                      result.phase_margin_target)};
    }
  }
  result.setpoint_weight = chosen_pid.b;
  ChosenDesign chosen;
  chosen.make_controller = [factory = chosen_pid.factory, b = chosen_pid.b] {
    return factory.Make(b);
  };
  return chosen;
}

// ---------------------------------------------------------------------------
// The chosen design: final evaluation and review

/// The chosen design on the nominal plant, the robustness rows and the load
/// step, into `result`. Returns whether every robustness row passes.
bool EvaluateChosenDesign(const ChosenDesign& design, Evaluator& evaluator,
                          AutoTuneResult& result) {
  {
    const std::unique_ptr<Controller> controller = design.make_controller();
    result.predicted = evaluator.Run(*controller, 0);
  }
  bool all_rows_pass = true;
  for (int i = 1; i < kPlantCount; ++i) {
    const std::unique_ptr<Controller> controller = design.make_controller();
    RobustnessRow row;
    row.name = kRobustnessRowNames[i - 1];
    row.metrics = evaluator.Run(*controller, i);
    row.pass = RobustRowPasses(row.metrics, result);
    all_rows_pass = all_rows_pass && row.pass;
    result.robustness.push_back(row);
  }
  {
    const std::unique_ptr<Controller> controller = design.make_controller();
    result.steady_state_error = evaluator.LoadSteadyStateError(*controller);
  }
  result.evaluations = evaluator.evaluations;
  return all_rows_pass;
}

/// What the review looks at besides the result.
struct ReviewContext {
  const TransferFunction& model;
  const AutoTuneOptions& options;
  const Evaluator& evaluator;
  const InputStep& input_step;
  const ChosenDesign& design;
};

ReviewItem NominalStabilityItem(const PredictedMetrics& nominal, double window) {
  if (nominal.settled)
    return {
        "nominal stability", ReviewStatus::kOk,
        fmt::format("the set-point step settles (2 % band) in {}", Seconds(nominal.settling_time))};
  return {"nominal stability", ReviewStatus::kFail,
          fmt::format("the set-point step does not settle within {:.4g} s: the loop "
                      "is unstable or too slow",
                      window)};
}

/// Offset-free: a constant output disturbance `load` leaves |steady-state
/// error| <= kOffsetTolerance of it.
ReviewItem OffsetFreeItem(double steady_state_error, double load) {
  if (std::abs(steady_state_error) <= kOffsetTolerance * load)
    return {"offset-free", ReviewStatus::kOk,
            fmt::format("a constant output disturbance of {:.4g} is removed: "
                        "steady-state error {:.3g}",
                        load, steady_state_error)};
  return {"offset-free", ReviewStatus::kFail,
          fmt::format("a constant output disturbance of {:.4g} leaves a "
                      "steady-state error of {:.3g}",
                      load, steady_state_error)};
}

/// QP Hessian condition: ok <= 1e4, warning <= 1e8, else fail.
ReviewItem HessianConditionItem(double condition, ControllerType controller) {
  const ReviewStatus status = condition <= 1e4                    ? ReviewStatus::kOk
                              : condition <= kMaxHessianCondition ? ReviewStatus::kWarning
                                                 : ReviewStatus::kFail;
  return {
      "QP Hessian condition", status,
      fmt::format("cond({}) = {:.3g}{}",
                  controller == ControllerType::kDmc ? "A'A + lambda I" : "H", condition,
                  status == ReviewStatus::kOk ? ""
                                              : " (the moves are sensitive to noise and rounding; "
                                                "a larger lambda or a smaller M conditions it)")};
}

/// Constraint conflicts: the set-points reachable at steady state, and a
/// warning when the input saturates during the evaluation step.
ReviewItem ConstraintConflictsItem(const ReviewContext& context, const AutoTuneResult& result) {
  const InputLimits& limits = context.options.limits;
  ReviewItem item{"constraint conflicts", ReviewStatus::kOk, ""};
  if (!Finite(limits)) {
    item.message = "no input limits: every set-point is reachable at steady state";
    return item;
  }
  const double K = result.fopdt.K;
  const double y_at_u_min = K * limits.u_min, y_at_u_max = K * limits.u_max;
  item.message = fmt::format(
      "set-points reachable at steady state: [{:.4g}, {:.4g}] for u in "
      "[{:.4g}, {:.4g}]; evaluation step {:.4g} -> {:.4g}",
      std::min(y_at_u_min, y_at_u_max), std::max(y_at_u_min, y_at_u_max), limits.u_min,
      limits.u_max, result.step_from, result.step_to);
  const double du_lo = context.evaluator.limits.u_min, du_hi = context.evaluator.limits.u_max;
  const PredictedMetrics& nominal = result.predicted;
  if (nominal.u_min <= du_lo + 1e-9 * (1 + std::abs(du_lo)) ||
      nominal.u_max >= du_hi - 1e-9 * (1 + std::abs(du_hi))) {
    item.status = ReviewStatus::kWarning;
    item.message += "; the input saturates during the step (the actuator limits the speed)";
  }
  return item;
}

ReviewItem RobustnessItem(const AutoTuneResult& result, bool all_rows_pass) {
  if (all_rows_pass)
    return {"robustness", ReviewStatus::kOk,
            fmt::format("gain +-20 % and one more sample of dead time: settled, "
                        "overshoot <= {:.3g} %, response <= {:.4g} s",
                        result.robust_overshoot, result.robust_response_time)};
  std::string failing;
  for (const RobustnessRow& row : result.robustness) {
    if (!row.pass)
      failing +=
          fmt::format("{}{} (overshoot {:.3g} %, response {})", failing.empty() ? "" : "; ",
                      row.name, row.metrics.overshoot_percent, Seconds(row.metrics.response_time));
  }
  return {"robustness", ReviewStatus::kFail,
          fmt::format("fails (allowed overshoot {:.3g} %, response {:.4g} s): {}",
                      result.robust_overshoot, result.robust_response_time, failing)};
}

/// Open loop with the input at its limit from the step on: the fastest
/// response possible, as the rise (10-90 %) or settling (98 %) time of the
/// evaluation step; NaN when it is not reached within the window.
double OpenLoopResponseAtLimit(const TransferFunction& model, const Evaluator& evaluator,
                               double u_limit) {
  const double Ts = evaluator.Ts;
  LinearPlant plant(model, Ts);
  plant.Reset();
  const bool rise = evaluator.measure == ResponseMeasure::kRise;
  double t_10 = kNaN, response_time = kNaN;
  for (int k = 0; k < static_cast<int>(evaluator.window / Ts) && std::isnan(response_time); ++k) {
    const double fraction = plant.Measure() / evaluator.step;
    if (std::isnan(t_10) && fraction >= 0.1) t_10 = k * Ts;
    if (fraction >= (rise ? 0.9 : 0.98)) response_time = k * Ts - (rise ? t_10 : 0.0);
    plant.Advance(u_limit);
  }
  return response_time;
}

/// Why the response cannot be faster than it is: the fastest robust design,
/// the sample time and dead time, the actuator.
std::vector<std::string> ReasonsTooSlow(const ReviewContext& context,
                                        const AutoTuneResult& result) {
  const AutoTuneOptions& options = context.options;
  const ChosenDesign& design = context.design;
  const double t_aim = result.response_time_aimed;
  std::vector<std::string> reasons;
  if (std::isfinite(design.t_fastest) && design.t_fastest > (1.0 + kTimeTolerance) * t_aim)
    reasons.push_back(
        fmt::format("the fastest design within the overshoot and robustness "
                    "limits (lambda = {:.4g}) responds in {:.4g} s",
                    design.lambda_fastest, design.t_fastest));
  else if (options.controller != ControllerType::kPid && std::isnan(design.lambda_fastest))
    reasons.push_back("no lambda meets the overshoot and robustness limits");
  const double t_min_delay = result.fopdt.theta + result.Ts;
  if (t_aim < t_min_delay)
    reasons.push_back(
        fmt::format("the target is shorter than the dead time plus one sample "
                    "({:.4g} s)",
                    t_min_delay));
  const InputLimits& limits = options.limits;
  if (Finite(limits)) {
    const Evaluator& evaluator = context.evaluator;
    const double u_limit =
        evaluator.step * result.fopdt.K > 0 ? evaluator.limits.u_max : evaluator.limits.u_min;
    if (std::isfinite(u_limit)) {
      const double t_at_limit = OpenLoopResponseAtLimit(context.model, evaluator, u_limit);
      if (std::isfinite(t_at_limit) && t_at_limit > t_aim)
        reasons.push_back(
            fmt::format("with the input held at its limit {:.4g} the model needs "
                        "{:.4g} s (input limits [{:.4g}, {:.4g}])",
                        u_limit + context.input_step.from, t_at_limit, limits.u_min, limits.u_max));
    }
  }
  return reasons;
}

/// Specification: overshoot and response time within 20 % of t*.
ReviewItem SpecificationItem(const ReviewContext& context, const AutoTuneResult& result) {
  const AutoTuneOptions& options = context.options;
  const PredictedMetrics& nominal = result.predicted;
  const double t_aim = result.response_time_aimed;
  std::vector<std::string> why;
  bool warn_only = true;
  if (!(nominal.overshoot_percent <= options.max_overshoot + kOvershootTolerance)) {
    why.push_back(fmt::format("overshoot {:.3g} % > {:.3g} %", nominal.overshoot_percent,
                              options.max_overshoot));
    warn_only = false;
  }
  const double relative_error = OrInf(nominal.response_time) / t_aim - 1.0;
  if (std::abs(relative_error) > kTimeTolerance) {
    why.push_back(fmt::format("{} time {} is {} than the target {:.4g} s (+-{:.0f} %)",
                              ToString(options.measure), Seconds(nominal.response_time),
                              relative_error > 0 ? "slower" : "faster", t_aim,
                              100 * kTimeTolerance));
    // PID: the crossover rule sets the time only approximately.
    if (options.controller != ControllerType::kPid || std::abs(relative_error) > 1.0)
      warn_only = false;
    if (relative_error > 0) {
      const std::vector<std::string> reasons = ReasonsTooSlow(context, result);
      why.insert(why.end(), reasons.begin(), reasons.end());
    }
  }
  if (why.empty()) {
    return {"specification", ReviewStatus::kOk,
            fmt::format("overshoot {:.3g} % <= {:.3g} %, {} time {} within {:.0f} % "
                        "of {:.4g} s",
                        nominal.overshoot_percent, options.max_overshoot, ToString(options.measure),
                        Seconds(nominal.response_time), 100 * kTimeTolerance, t_aim)};
  }
  std::string message;
  for (const std::string& reason : why) message += (message.empty() ? "" : "; ") + reason;
  return {"specification", warn_only ? ReviewStatus::kWarning : ReviewStatus::kFail, message};
}

/// Termination and message from the review: failure when the nominal step
/// does not settle, spec_not_met when a check fails, else converged.
void ConcludeReview(AutoTuneResult& result) {
  bool any_fail = false;
  std::string fails;
  for (const ReviewItem& item : result.review) {
    if (item.status == ReviewStatus::kFail) {
      any_fail = true;
      fails += (fails.empty() ? "" : "; ") + item.check + ": " + item.message;
    }
  }
  if (!result.predicted.settled) {
    result.termination = AutoTuneTermination::kFailure;
    result.message = "no stable design found: " + fails;
  } else if (any_fail) {
    result.termination = AutoTuneTermination::kSpecNotMet;
    result.message = "specification not met: " + fails;
  } else {
    result.termination = AutoTuneTermination::kConverged;
    result.message =
        fmt::format("specification met ({} closed-loop simulations)", result.evaluations);
  }
}

/// The design review (file comment), appended to result.review, and the
/// termination it leads to.
void ReviewDesign(const ReviewContext& context, bool all_rows_pass, AutoTuneResult& result) {
  result.review.push_back(NominalStabilityItem(result.predicted, context.evaluator.window));
  result.review.push_back(
      OffsetFreeItem(result.steady_state_error, kLoadFraction * std::abs(context.evaluator.step)));
  if (context.design.hessian.size() > 0) {
    result.hessian_condition = ConditionNumber(context.design.hessian);
    result.review.push_back(HessianConditionItem(result.hessian_condition, result.controller));
  }
  result.review.push_back(ConstraintConflictsItem(context, result));
  result.review.push_back(RobustnessItem(result, all_rows_pass));
  result.review.push_back(SpecificationItem(context, result));
  ConcludeReview(result);
}

}  // namespace

std::string ToString(ResponseMeasure v) { return std::string(EnumToString(kMeasureNames, v)); }
ResponseMeasure ResponseMeasureFromString(const std::string& name) {
  return EnumFromString(kMeasureNames, name, "response measure");
}
std::string ToString(ReviewStatus v) { return std::string(EnumToString(kStatusNames, v)); }
std::string ToString(AutoTuneTermination v) {
  return std::string(EnumToString(kTerminationNames, v));
}

bool AutoTuneOptions::IsValid(std::string* error) const {
  auto fail = [&](const std::string& message) {
    if (error) *error = message;
    return false;
  };
  if (controller == ControllerType::kGpc)
    return fail("the automatic tuning designs mpc, dmc or pid, not gpc");
  if (!std::isnan(response_time) && !(response_time > 0.0 && std::isfinite(response_time)))
    return fail(fmt::format("response_time must be positive (NaN = from the model), got {}",
                            response_time));
  if (!(max_overshoot >= 0.0 && std::isfinite(max_overshoot)))
    return fail(fmt::format("max_overshoot must be >= 0 percent, got {}", max_overshoot));
  if (!(aggressiveness >= 0.0 && aggressiveness <= 1.0))
    return fail(fmt::format("aggressiveness must be in [0, 1], got {}", aggressiveness));
  std::string e;
  if (!limits.IsValid(&e)) return fail("input limits: " + e);
  if (limits.u_min == limits.u_max)
    return fail(fmt::format("input limits leave no range: u_min = u_max = {}", limits.u_min));
  if (M < 0) return fail(fmt::format("M must be >= 0 (0 = 5), got {}", M));
  if (controller == ControllerType::kMpc) {
    // The estimator's noises as the MPC checks them (NaN = its defaults; the
    // other options at their defaults pass).
    MpcOptions mpc;
    mpc.disturbance = disturbance;
    if (!std::isnan(measurement_noise)) mpc.measurement_noise = measurement_noise;
    if (!std::isnan(state_noise)) mpc.state_noise = state_noise;
    if (!std::isnan(disturbance_noise)) mpc.disturbance_noise = disturbance_noise;
    if (!mpc.IsValid(&e)) return fail(e);
  }
  return true;
}

namespace {

void CheckAutoTuneArguments(const TransferFunction& model, double Ts,
                            const AutoTuneOptions& options) {
  std::string error;
  PNEUMID_CHECK(options.IsValid(&error), "invalid auto-tuning options: {}", error);
  PNEUMID_CHECK(Ts > 0.0 && std::isfinite(Ts), "Ts must be positive, got {}", Ts);
  PNEUMID_CHECK(model.IsContinuous() || std::abs(model.Ts() - Ts) <= 1e-9 * Ts,
                "a discrete model must have the controller's sample time {} s, got {} s", Ts,
                model.Ts());
}

/// AutoTune of `model` at Ts; `sampled` is the model sampled at Ts (mpc and
/// dmc, the pid designs without it).
AutoTuneResult TuneToSpecification(const TransferFunction& model, double Ts,
                                   const AutoTuneOptions& options, const PredictionModel* sampled) {
  AutoTuneResult result = SpecificationAsUsed(model, Ts, options);
  // The evaluation step in input space, then deviation variables.
  const InputStep input_step = EvaluationInputStep(options.limits, result.fopdt.K);
  result.step_from = result.fopdt.K * input_step.from;
  result.step_to = result.fopdt.K * input_step.to;
  Evaluator evaluator = MakeEvaluator(model, Ts, options, result, input_step.from);

  const ChosenDesign design = options.controller == ControllerType::kPid
                                  ? DesignPid(model, Ts, options, evaluator, result)
                                  : SearchPredictiveDesign(*sampled, options, evaluator, result);

  const bool all_rows_pass = EvaluateChosenDesign(design, evaluator, result);
  ReviewDesign({model, options, evaluator, input_step, design}, all_rows_pass, result);
  return result;
}

}  // namespace

AutoTuneResult AutoTune(const TransferFunction& model, double Ts, const AutoTuneOptions& options) {
  CheckAutoTuneArguments(model, Ts, options);
  if (options.controller == ControllerType::kPid)
    return TuneToSpecification(model, Ts, options, nullptr);
  const PredictionModel sampled(model, Ts);
  return TuneToSpecification(model, Ts, options, &sampled);
}

AutoTuneResult AutoTune(const PredictionModel& model, const AutoTuneOptions& options) {
  CheckAutoTuneArguments(model.model(), model.Ts(), options);
  return TuneToSpecification(model.model(), model.Ts(), options, &model);
}

TuningResult AutoTuneResult::ToTuningResult() const {
  TuningResult t;
  t.rule = TuningRule::kExplicit;
  t.P = P;
  t.M = M;
  t.lambda = lambda;
  t.Ts = Ts;
  t.fopdt = fopdt;
  t.lambda_explicit = true;
  t.formula = fmt::format(
      "auto: P = round(5 tau/Ts + theta/Ts + 1) = {}, M = {}, lambda = {:.6g} "
      "from the closed-loop search for {}a {} time of {:.4g} s and overshoot "
      "<= {:.3g} %",
      P, M, lambda, fastest ? "the fastest robust design, " : "", ToString(measure),
      response_time_aimed, max_overshoot);
  return t;
}

namespace {
nlohmann::json Num(double v) { return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(); }

nlohmann::ordered_json MetricsJson(const PredictedMetrics& m) {
  nlohmann::ordered_json j;
  j["rise_time"] = Num(m.rise_time);
  j["overshoot_percent"] = Num(m.overshoot_percent);
  j["settling_time"] = Num(m.settling_time);
  j["response_time"] = Num(m.response_time);
  j["settled"] = m.settled;
  j["u_min"] = m.u_min;
  j["u_max"] = m.u_max;
  return j;
}
}  // namespace

nlohmann::ordered_json AutoTuneResult::ToJson() const {
  nlohmann::ordered_json j;
  const bool pid_type = controller == ControllerType::kPid;
  j["rule"] = "auto";
  j["controller"] = ToString(controller);
  j["P"] = pid_type ? nlohmann::json() : nlohmann::json(P);
  j["M"] = pid_type ? nlohmann::json() : nlohmann::json(M);
  j["lambda"] = pid_type ? nlohmann::json() : Num(lambda);
  if (pid_type) {
    j["Kc"] = Num(pid.Kc);
    j["Ti"] = Num(pid.Ti);
    j["Td"] = pid.Td;
    j["b"] = setpoint_weight;
    j["N"] = derivative_filter;
    j["crossover_target"] = Num(crossover_target);
    j["crossover"] = Num(crossover);
    j["phase_margin_target"] = Num(phase_margin_target);
    j["phase_margin"] = Num(phase_margin);
    j["gain_margin"] = Num(gain_margin);
  } else {
    j["hessian_condition"] = Num(hessian_condition);
  }
  j["Ts"] = Ts;
  j["specification"] = {{"measure", ToString(measure)},
                        {"response_time", response_time_target},
                        {"response_time_source", fastest ? "fastest robust" : "given or model"},
                        {"response_time_aimed", response_time_aimed},
                        {"max_overshoot", max_overshoot},
                        {"aggressiveness", aggressiveness},
                        {"robust_overshoot", robust_overshoot},
                        {"robust_response_time", robust_response_time}};
  j["fopdt"] = {
      {"K", fopdt.K}, {"tau", fopdt.tau}, {"theta", fopdt.theta}, {"method", fopdt.method}};
  j["step"] = {{"from", step_from}, {"to", step_to}};
  j["predicted"] = MetricsJson(predicted);
  j["steady_state_error_after_load"] = Num(steady_state_error);
  nlohmann::ordered_json rows = nlohmann::ordered_json::array();
  for (const RobustnessRow& row : robustness) {
    nlohmann::ordered_json rj;
    rj["case"] = row.name;
    rj.update(MetricsJson(row.metrics));
    rj["pass"] = row.pass;
    rows.push_back(rj);
  }
  j["robustness"] = rows;
  nlohmann::ordered_json review_j = nlohmann::ordered_json::array();
  for (const ReviewItem& item : review)
    review_j.push_back(
        {{"check", item.check}, {"status", ToString(item.status)}, {"message", item.message}});
  j["review"] = review_j;
  j["evaluations"] = evaluations;
  j["termination"] = ToString(termination);
  j["message"] = message;
  return j;
}

std::string AutoTuneResult::FullReport() const {
  std::string s;
  const bool pid_type = controller == ControllerType::kPid;
  s += fmt::format("rule        auto\ncontroller  {}\n", ToString(controller));
  if (pid_type) {
    s += fmt::format(
        "Kc          {:.6g}\nTi          {}\nTd          {:.6g} s\nb           {:.4g}\n"
        "crossover   {:.4g} rad/s (target {:.4g})\nphase margin {:.3g} deg (target "
        "{:.3g}), gain margin {:.3g}\n",
        pid.Kc, std::isfinite(pid.Ti) ? fmt::format("{:.6g} s", pid.Ti) : "inf", pid.Td,
        setpoint_weight, crossover, crossover_target, phase_margin, phase_margin_target,
        gain_margin);
  } else {
    s += fmt::format("P           {}\nM           {}\nlambda      {:.6g}\n", P, M, lambda);
  }
  s += fmt::format(
      "target      {} time {:.4g} s ({}, aggressiveness {:.2g}), "
      "overshoot <= {:.3g} %\n",
      ToString(measure), response_time_target,
      fastest ? "the fastest robust design" : fmt::format("aimed {:.4g} s", response_time_aimed),
      aggressiveness, max_overshoot);
  auto line = [](const std::string& name, const PredictedMetrics& m) {
    return fmt::format(
        "  {:<20} {:>9} {:>10} {:>9}", name, Seconds(m.rise_time),
        std::isfinite(m.overshoot_percent) ? fmt::format("{:.3g} %", m.overshoot_percent) : "none",
        Seconds(m.settling_time));
  };
  s += fmt::format("predicted (step {:.4g} -> {:.4g} on the model):\n", step_from, step_to);
  s += fmt::format("  {:<20} {:>9} {:>10} {:>9}  {}\n", "case", "rise", "overshoot", "settling",
                   "pass");
  s += line("nominal", predicted) + "\n";
  for (const RobustnessRow& row : robustness)
    s += line(row.name, row.metrics) + (row.pass ? "  yes\n" : "  NO\n");
  s += "review:\n";
  for (const ReviewItem& item : review)
    s += fmt::format("  [{}] {}: {}\n", ToString(item.status), item.check, item.message);
  s += fmt::format("termination: {} - {}\n", ToString(termination), message);
  return s;
}

}  // namespace pneumid
