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

  PredictedMetrics Run(Controller& c, int plant) {
    ++evaluations;
    LinearPlant p(plants[plant], Ts);
    StepSetpoint sp(step, t_step);
    ClosedLoopOptions o;
    o.duration = t_step + window;
    o.actuator = limits;
    const ClosedLoopResult r = SimulateClosedLoop(c, p, sp, o);
    PredictedMetrics m;
    m.rise_time = r.metrics.rise_time;
    m.overshoot_percent = r.metrics.overshoot_percent;
    m.settling_time = r.metrics.settling_time;
    m.settled = r.metrics.settled && std::isfinite(r.metrics.settling_time);
    m.response_time = measure == ResponseMeasure::kRise ? m.rise_time : m.settling_time;
    m.u_min = r.metrics.u_min;
    m.u_max = r.metrics.u_max;
    // A loop that grows without bound has no meaningful overshoot.
    if (!r.y.allFinite()) {
      m.settled = false;
      m.overshoot_percent = std::numeric_limits<double>::infinity();
    }
    return m;
  }

  /// Steady-state error after a constant output disturbance of
  /// kLoadFraction * step at constant set-point 0.
  double LoadSteadyStateError(Controller& c) {
    ++evaluations;
    LinearPlant p(plants[0], Ts);
    StepSetpoint sp(0.0, 0.0);
    ClosedLoopOptions o;
    o.duration = t_step + window;
    o.actuator = limits;
    o.load_steps = {{t_step, -kLoadFraction * step}};
    const ClosedLoopResult r = SimulateClosedLoop(c, p, sp, o);
    if (!r.y.allFinite()) return std::numeric_limits<double>::infinity();
    return r.metrics.steady_state_error;
  }
};

double OrInf(double v) { return std::isfinite(v) ? v : std::numeric_limits<double>::infinity(); }

bool Finite(const InputLimits& l) { return std::isfinite(l.u_min) || std::isfinite(l.u_max); }

std::string Seconds(double t) { return std::isfinite(t) ? fmt::format("{:.4g} s", t) : "none"; }

/// Value of the discrete PID (without Kc) at z = e^{j w Ts}, as PidController computes it.
std::complex<double> PidShape(double Ti, double Td, double N, double Ts, double w) {
  const std::complex<double> zinv = std::exp(std::complex<double>(0.0, -w * Ts));
  std::complex<double> c = 1.0;
  if (std::isfinite(Ti)) c += (Ts / Ti) * zinv / (1.0 - zinv);
  if (Td > 0.0) {
    const double beta = Td / (Td + N * Ts);
    c += (N * Td / (Td + N * Ts)) * (1.0 - zinv) / (1.0 - beta * zinv);
  }
  return c;
}

struct LoopMargins {
  double crossover = std::numeric_limits<double>::quiet_NaN();
  double phase_margin = std::numeric_limits<double>::quiet_NaN();
  double gain_margin = std::numeric_limits<double>::infinity();
};

/// Crossover, phase and gain margin of Kc C1(z) G(z) on a dense grid up to
/// the Nyquist frequency: the first frequency where |L| falls through 1, the
/// phase margin there, and the smallest 1/|L| where the phase crosses -180.
LoopMargins DiscreteLoopMargins(const TransferFunction& Gd, const PidGains& g, double N,
                                double Ts) {
  const double wn = kPi / Ts;
  const Eigen::VectorXd w = LogSpace(std::log10(wn) - 5.0, std::log10(wn * 0.9999), 4000);
  const BodeData b = Bode(Gd, w);
  const int n = static_cast<int>(w.size());
  Eigen::VectorXd mag(n), ph(n);
  for (int i = 0; i < n; ++i) {
    const std::complex<double> c = g.Kc * PidShape(g.Ti, g.Td, N, Ts, w(i));
    mag(i) = std::abs(c) * b.magnitude(i);
    ph(i) = std::arg(c) * kDeg + b.phase_deg(i);
  }
  LoopMargins m;
  for (int i = 1; i < n; ++i) {
    if (std::isnan(m.crossover) && (mag(i - 1) - 1.0) * (mag(i) - 1.0) <= 0.0 && mag(i - 1) > 1.0) {
      const double f = std::log(mag(i - 1)) / (std::log(mag(i - 1)) - std::log(mag(i)));
      m.crossover = std::exp(std::log(w(i - 1)) + f * (std::log(w(i)) - std::log(w(i - 1))));
      m.phase_margin = 180.0 + ph(i - 1) + f * (ph(i) - ph(i - 1));
    }
    const double a = ph(i - 1) + 180.0, c = ph(i) + 180.0;
    if (a * c <= 0.0 && a != c) {
      const double f = a / (a - c);
      const double lm = std::log(mag(i - 1)) + f * (std::log(mag(i)) - std::log(mag(i - 1)));
      m.gain_margin = std::min(m.gain_margin, std::exp(-lm));
    }
  }
  return m;
}

/// Unwrapped phase (deg) and magnitude of Gd at w.
std::pair<double, double> PlantAt(const TransferFunction& Gd, double w) {
  const Eigen::VectorXd grid = LogSpace(std::log10(w) - 4.0, std::log10(w), 400);
  const BodeData b = Bode(Gd, grid);
  return {b.magnitude(b.magnitude.size() - 1), b.phase_deg(b.phase_deg.size() - 1)};
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
  return true;
}

AutoTuneResult AutoTune(const TransferFunction& model, double Ts, const AutoTuneOptions& options) {
  std::string error;
  PNEUMID_CHECK(options.IsValid(&error), "invalid auto-tuning options: {}", error);
  PNEUMID_CHECK(Ts > 0.0 && std::isfinite(Ts), "Ts must be positive, got {}", Ts);
  PNEUMID_CHECK(model.IsContinuous() || std::abs(model.Ts() - Ts) <= 1e-9 * Ts,
                "a discrete model must have the controller's sample time {} s, got {} s", Ts,
                model.Ts());
  AutoTuneResult r;
  r.controller = options.controller;
  r.Ts = Ts;
  r.measure = options.measure;
  r.max_overshoot = options.max_overshoot;
  r.aggressiveness = options.aggressiveness;
  r.fopdt = FopdtFromModel(model);
  const FopdtEstimate& f = r.fopdt;
  const double a = options.aggressiveness;
  r.response_time_target =
      std::isnan(options.response_time)
          ? (options.measure == ResponseMeasure::kRise ? f.tau + f.theta : 2.0 * f.tau + f.theta)
          : options.response_time;
  r.response_time_aimed = r.response_time_target * std::pow(1.5, 1.0 - 2.0 * a);
  r.robust_overshoot = options.max_overshoot * (1.0 + 4.0 * a) + kOvershootTolerance;
  r.robust_response_time = (1.5 + a) * r.response_time_aimed;
  // mpc/dmc without a response time: the fastest robust design (file comment).
  r.fastest = std::isnan(options.response_time) && options.controller != ControllerType::kPid;
  double t_aim = r.response_time_aimed;

  // The evaluation step in input space, then deviation variables.
  const InputLimits& L = options.limits;
  const double K = f.K;
  double u_from = 0.0, u_to = 1.0 / K;
  if (std::isfinite(L.u_min) && std::isfinite(L.u_max)) {
    u_from = L.u_min + 0.4 * (L.u_max - L.u_min);
    u_to = L.u_min + 0.6 * (L.u_max - L.u_min);
  } else if (std::isfinite(L.u_min)) {
    u_from = L.u_min + 1.0 / std::abs(K);
    u_to = L.u_min + 2.0 / std::abs(K);
  } else if (std::isfinite(L.u_max)) {
    u_from = L.u_max - 2.0 / std::abs(K);
    u_to = L.u_max - 1.0 / std::abs(K);
  }
  r.step_from = K * u_from;
  r.step_to = K * u_to;

  Evaluator ev;
  ev.Ts = Ts;
  ev.step = r.step_to - r.step_from;
  ev.t_step = 5.0 * Ts;
  ev.window = std::max(10.0 * std::max(t_aim, f.tau + f.theta), 50.0 * Ts);
  ev.limits = L;
  ev.limits.u_min -= u_from;
  ev.limits.u_max -= u_from;
  ev.measure = options.measure;
  const double ts_model = model.IsContinuous() ? 0.0 : Ts;
  ev.plants = {model, TransferFunction(model.num() * 1.2, model.den(), ts_model, model.delay()),
               TransferFunction(model.num() * 0.8, model.den(), ts_model, model.delay()),
               model.WithDelay(model.delay() + Ts)};
  const char* kRowNames[] = {"gain +20%", "gain -20%", "dead time +1 sample"};

  auto row_pass = [&](const PredictedMetrics& m) {
    return m.settled && m.overshoot_percent <= r.robust_overshoot &&
           OrInf(m.response_time) <= r.robust_response_time;
  };
  auto robust_ok = [&](const PredictedMetrics& m) {  // stability and overshoot only
    return m.settled && m.overshoot_percent <= r.robust_overshoot;
  };
  auto nominal_ok = [&](const PredictedMetrics& m) {
    return m.settled && m.overshoot_percent <= options.max_overshoot + kOvershootTolerance;
  };

  std::function<std::unique_ptr<Controller>()> make_final;
  Eigen::MatrixXd hessian;
  std::unique_ptr<PredictionModel> pm_ptr;  // outlive make_final
  // mpc/dmc: the response time of lambda_f, the fastest robust design.
  double t_fastest = std::numeric_limits<double>::quiet_NaN();
  double lambda_fastest = t_fastest;
  StateSpace ss;

  if (options.controller == ControllerType::kMpc || options.controller == ControllerType::kDmc) {
    pm_ptr = std::make_unique<PredictionModel>(model, Ts);
    const PredictionModel& pm = *pm_ptr;
    TuningOptions to;
    to.rule = TuningRule::kShridharCooper;
    to.M = options.M;
    const TuningResult base = Tune(pm, to);
    r.P = base.P;
    r.M = base.M;
    const double lambda0 = base.lambda_condition;
    const bool is_mpc = options.controller == ControllerType::kMpc;
    if (is_mpc) ss = SampledStateSpace(model, Ts);
    auto make = [&, is_mpc](double lambda) -> std::unique_ptr<Controller> {
      if (is_mpc) {
        MpcOptions o;
        o.P = r.P;
        o.M = r.M;
        o.lambda = lambda;
        o.limits = ev.limits;
        o.disturbance = options.disturbance;
        return std::make_unique<MpcController>(ss, o);
      }
      DmcOptions o;
      o.P = r.P;
      o.M = r.M;
      o.lambda = lambda;
      o.limits = ev.limits;
      o.constrained = Finite(ev.limits) || std::isfinite(ev.limits.du_max);
      return std::make_unique<DmcController>(*pm_ptr, o);
    };
    struct Eval {
      PredictedMetrics nominal;
      bool feasible = false;
    };
    auto evaluate = [&](double lambda) {
      Eval e;
      auto c = make(lambda);
      e.nominal = ev.Run(*c, 0);
      e.feasible = nominal_ok(e.nominal);
      for (int i = 1; e.feasible && i < 4; ++i) e.feasible = robust_ok(ev.Run(*c, i));
      return e;
    };
    // Smallest feasible lambda: ascending scan in log lambda, then bisection.
    const double lo_exp = -6.0, hi_exp = 4.0;
    double lambda_f = std::numeric_limits<double>::quiet_NaN();
    double prev = std::numeric_limits<double>::quiet_NaN();
    for (int k = 0; lo_exp + 0.25 * k <= hi_exp + 1e-9; ++k) {
      const double lambda = lambda0 * std::pow(10.0, lo_exp + 0.25 * k);
      if (evaluate(lambda).feasible) {
        lambda_f = lambda;
        break;
      }
      prev = lambda;
    }
    double lambda_star;
    if (std::isnan(lambda_f)) {
      // Nothing robust: take the Shridhar-Cooper value and let the review say why.
      lambda_star = lambda0;
    } else {
      if (!std::isnan(prev)) {
        double lo = std::log(prev), hi = std::log(lambda_f);
        for (int i = 0; i < 12; ++i) {
          const double mid = 0.5 * (lo + hi);
          if (evaluate(std::exp(mid)).feasible)
            hi = mid;
          else
            lo = mid;
        }
        lambda_f = std::exp(hi);
      }
      lambda_star = lambda_f;
      auto time_of = [&](double lambda) {
        auto c = make(lambda);
        return OrInf(ev.Run(*c, 0).response_time);
      };
      lambda_fastest = lambda_f;
      t_fastest = time_of(lambda_f);
      if (r.fastest && std::isfinite(t_fastest)) {
        // The target is the fastest robust response itself.
        r.response_time_target = r.response_time_aimed = t_aim = t_fastest;
        r.robust_response_time = (1.5 + a) * t_aim;
      }
      if (t_fastest < t_aim) {
        // Bracket t(lambda) = t* above lambda_f, then bisect in log lambda.
        double lo = std::log(lambda_f), hi = lo;
        bool bracketed = false;
        for (int i = 0; i < 12 && !bracketed; ++i) {
          lo = hi;
          hi += std::log(10.0);
          bracketed = time_of(std::exp(hi)) >= t_aim;
        }
        if (bracketed) {
          for (int i = 0; i < 30 && hi - lo > 1e-4; ++i) {
            const double mid = 0.5 * (lo + hi);
            if (time_of(std::exp(mid)) < t_aim)
              lo = mid;
            else
              hi = mid;
          }
          const double tl = time_of(std::exp(lo)), th = time_of(std::exp(hi));
          lambda_star = std::abs(std::log(tl / t_aim)) <= std::abs(std::log(th / t_aim))
                            ? std::exp(lo)
                            : std::exp(hi);
        } else {
          lambda_star = std::exp(hi);
        }
      } else {
        // Even lambda_f is too slow: the response is limited by the model,
        // the horizons or the actuator, and flat in lambda. Take the largest
        // lambda that is hardly slower (2 % of t*): better conditioned, as fast.
        const double t_f = t_fastest;
        const double t_ok = t_f + (r.fastest ? 0.005 : 0.02) * t_aim;
        double lo = std::log(lambda_f), hi = lo;
        bool bracketed = false;
        for (int i = 0; i < 12 && !bracketed; ++i) {
          lo = hi;
          hi += std::log(10.0);
          bracketed = time_of(std::exp(hi)) > t_ok;
        }
        if (bracketed) {
          for (int i = 0; i < 30 && hi - lo > 1e-3; ++i) {
            const double mid = 0.5 * (lo + hi);
            if (time_of(std::exp(mid)) <= t_ok)
              lo = mid;
            else
              hi = mid;
          }
        }
        if (evaluate(std::exp(lo)).feasible) lambda_star = std::exp(lo);
      }
    }
    r.lambda = lambda_star;
    make_final = [make, lambda_star] { return make(lambda_star); };
    auto c = make(lambda_star);
    if (is_mpc) {
      hessian = static_cast<MpcController&>(*c).hessian();
    } else {
      const Eigen::MatrixXd& A = static_cast<DmcController&>(*c).dynamic_matrix();
      hessian = A.transpose() * A + lambda_star * Eigen::MatrixXd::Identity(A.cols(), A.cols());
    }
  } else {  // pid
    const TransferFunction Gd = LinearPlant(model, Ts).model();
    const double sgn = K > 0.0 ? 1.0 : -1.0;
    const double wn = kPi / Ts;
    double wc = (options.measure == ResponseMeasure::kRise ? 2.0 : 4.0) / t_aim;
    r.crossover_target = wc;
    r.phase_margin_target = 75.0 - 30.0 * a;
    const double w_design = std::min(wc, 0.5 * wn);
    const auto [gmag, gph0] = PlantAt(Gd, w_design);
    const double gph = gph0 - (sgn < 0.0 ? 180.0 : 0.0);  // design on sgn * G
    const double phi_c = -180.0 + r.phase_margin_target - gph;
    const double N = r.derivative_filter;
    auto arg_c = [&](double Ti, bool pid) {
      return std::arg(PidShape(Ti, pid ? Ti / 4.0 : 0.0, N, Ts, w_design)) * kDeg;
    };
    const bool use_pid = phi_c > -10.0;
    // Ti from arg C1(Ti) = phi_c: log grid, first bracket, bisection.
    const int n = 400;
    double best_Ti = std::numeric_limits<double>::quiet_NaN(), best_err = 1e300;
    double lo = std::log(1e-4 / w_design), hi = std::log(1e4 / w_design);
    double Ti_sol = std::numeric_limits<double>::quiet_NaN();
    double x_prev = lo, e_prev = arg_c(std::exp(lo), use_pid) - phi_c;
    for (int i = 1; i <= n && std::isnan(Ti_sol); ++i) {
      const double x = lo + (hi - lo) * i / n;
      const double e = arg_c(std::exp(x), use_pid) - phi_c;
      if (std::abs(e) < best_err) {
        best_err = std::abs(e);
        best_Ti = std::exp(x);
      }
      if (e_prev * e <= 0.0) {
        double xa = x_prev, xb = x, ea = e_prev;
        for (int k = 0; k < 60; ++k) {
          const double xm = 0.5 * (xa + xb);
          const double em = arg_c(std::exp(xm), use_pid) - phi_c;
          if (ea * em <= 0.0)
            xb = xm;
          else {
            xa = xm;
            ea = em;
          }
        }
        Ti_sol = std::exp(0.5 * (xa + xb));
      }
      x_prev = x;
      e_prev = e;
    }
    const bool solved = !std::isnan(Ti_sol);
    const double Ti = solved ? Ti_sol : best_Ti;
    r.pid.Ti = Ti;
    r.pid.Td = use_pid ? Ti / 4.0 : 0.0;
    r.pid.Kc = sgn / (std::abs(PidShape(Ti, r.pid.Td, N, Ts, w_design)) * gmag);
    const LoopMargins lm = DiscreteLoopMargins(Gd, r.pid, N, Ts);
    r.crossover = lm.crossover;
    r.phase_margin = lm.phase_margin;
    r.gain_margin = lm.gain_margin;
    if (!solved || wc > 0.5 * wn) {
      r.review.push_back(
          {"loop shaping", ReviewStatus::kFail,
           wc > 0.5 * wn
               ? fmt::format("the crossover 2/t* = {:.4g} rad/s the response time asks for exceeds "
                             "half the Nyquist frequency ({:.4g} rad/s): designed at {:.4g} rad/s; "
                             "sample faster or ask for a slower response",
                             wc, 0.5 * wn, w_design)
               : fmt::format("a {} cannot give the phase margin {:.3g} deg at {:.4g} rad/s (the "
                             "controller would need {:.1f} deg of phase); closest Ti taken",
                             use_pid ? "PID" : "PI", r.phase_margin_target, w_design, phi_c)});
    } else {
      r.review.push_back(
          {"loop shaping", ReviewStatus::kOk,
           fmt::format("{} with crossover {:.4g} rad/s (target {:.4g}), phase "
                       "margin {:.3g} deg (target {:.3g}), gain margin {:.3g}",
                       use_pid ? "PID (Td = Ti/4)" : "PI", r.crossover, r.crossover_target,
                       r.phase_margin, r.phase_margin_target, r.gain_margin)});
    }
    auto make = [&, N](double b) -> std::unique_ptr<Controller> {
      PidOptions o;
      o.gains = r.pid;
      o.setpoint_weight = b;
      o.derivative_filter = N;
      o.limits = ev.limits;
      return std::make_unique<PidController>(Ts, o);
    };
    // Set-point weight: the largest b in [0, 1] meeting the overshoot spec.
    double b = 1.0;
    {
      auto c = make(1.0);
      const PredictedMetrics m = ev.Run(*c, 0);
      if (m.overshoot_percent > options.max_overshoot + kOvershootTolerance) {
        double blo = 0.0, bhi = 1.0;
        for (int i = 0; i < 20; ++i) {
          const double bm = 0.5 * (blo + bhi);
          auto cm = make(bm);
          if (ev.Run(*cm, 0).overshoot_percent <= options.max_overshoot)
            blo = bm;
          else
            bhi = bm;
        }
        b = blo;
      }
    }
    r.setpoint_weight = b;
    make_final = [make, b] { return make(b); };
  }

  // Final design: nominal, robustness rows, load step, review.
  {
    auto c = make_final();
    r.predicted = ev.Run(*c, 0);
  }
  bool all_rows = true;
  for (int i = 1; i < 4; ++i) {
    auto c = make_final();
    RobustnessRow row;
    row.name = kRowNames[i - 1];
    row.metrics = ev.Run(*c, i);
    row.pass = row_pass(row.metrics);
    all_rows = all_rows && row.pass;
    r.robustness.push_back(row);
  }
  {
    auto c = make_final();
    r.steady_state_error = ev.LoadSteadyStateError(*c);
  }
  r.evaluations = ev.evaluations;
  const PredictedMetrics& m = r.predicted;

  r.review.push_back(
      m.settled
          ? ReviewItem{"nominal stability", ReviewStatus::kOk,
                       fmt::format("the set-point step settles (2 % band) in {}",
                                   Seconds(m.settling_time))}
          : ReviewItem{"nominal stability", ReviewStatus::kFail,
                       fmt::format("the set-point step does not settle within {:.4g} s: the loop "
                                   "is unstable or too slow",
                                   ev.window)});
  const double load = kLoadFraction * std::abs(ev.step);
  r.review.push_back(
      std::abs(r.steady_state_error) <= kOffsetTolerance * load
          ? ReviewItem{"offset-free", ReviewStatus::kOk,
                       fmt::format("a constant output disturbance of {:.4g} is removed: "
                                   "steady-state error {:.3g}",
                                   load, r.steady_state_error)}
          : ReviewItem{"offset-free", ReviewStatus::kFail,
                       fmt::format("a constant output disturbance of {:.4g} leaves a "
                                   "steady-state error of {:.3g}",
                                   load, r.steady_state_error)});
  if (hessian.size() > 0) {
    const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(hessian, Eigen::EigenvaluesOnly);
    const double lmin = eig.eigenvalues().minCoeff(), lmax = eig.eigenvalues().maxCoeff();
    r.hessian_condition = lmin > 0.0 ? lmax / lmin : std::numeric_limits<double>::infinity();
    const ReviewStatus s = r.hessian_condition <= 1e4   ? ReviewStatus::kOk
                           : r.hessian_condition <= 1e8 ? ReviewStatus::kWarning
                                                        : ReviewStatus::kFail;
    r.review.push_back(
        {"QP Hessian condition", s,
         fmt::format("cond({}) = {:.3g}{}",
                     options.controller == ControllerType::kDmc ? "A'A + lambda I" : "H",
                     r.hessian_condition,
                     s == ReviewStatus::kOk ? ""
                                            : " (the moves are sensitive to noise and rounding; "
                                              "a larger lambda or a smaller M conditions it)")});
  }
  {
    ReviewItem item{"constraint conflicts", ReviewStatus::kOk, ""};
    if (!Finite(L)) {
      item.message = "no input limits: every set-point is reachable at steady state";
    } else {
      const double y1 = K * L.u_min, y2 = K * L.u_max;
      item.message = fmt::format(
          "set-points reachable at steady state: [{:.4g}, {:.4g}] for u in "
          "[{:.4g}, {:.4g}]; evaluation step {:.4g} -> {:.4g}",
          std::min(y1, y2), std::max(y1, y2), L.u_min, L.u_max, r.step_from, r.step_to);
      const double du_lo = ev.limits.u_min, du_hi = ev.limits.u_max;
      if (m.u_min <= du_lo + 1e-9 * (1 + std::abs(du_lo)) ||
          m.u_max >= du_hi - 1e-9 * (1 + std::abs(du_hi))) {
        item.status = ReviewStatus::kWarning;
        item.message += "; the input saturates during the step (the actuator limits the speed)";
      }
    }
    r.review.push_back(item);
  }
  {
    std::string failing;
    for (const RobustnessRow& row : r.robustness) {
      if (!row.pass)
        failing += fmt::format("{}{} (overshoot {:.3g} %, response {})",
                               failing.empty() ? "" : "; ", row.name, row.metrics.overshoot_percent,
                               Seconds(row.metrics.response_time));
    }
    r.review.push_back(
        all_rows
            ? ReviewItem{"robustness", ReviewStatus::kOk,
                         fmt::format("gain +-20 % and one more sample of dead time: settled, "
                                     "overshoot <= {:.3g} %, response <= {:.4g} s",
                                     r.robust_overshoot, r.robust_response_time)}
            : ReviewItem{"robustness", ReviewStatus::kFail,
                         fmt::format("fails (allowed overshoot {:.3g} %, response {:.4g} s): {}",
                                     r.robust_overshoot, r.robust_response_time, failing)});
  }
  {
    // Specification: overshoot and response time within 20 % of t*.
    std::vector<std::string> why;
    bool warn_only = true;
    if (!(m.overshoot_percent <= options.max_overshoot + kOvershootTolerance)) {
      why.push_back(
          fmt::format("overshoot {:.3g} % > {:.3g} %", m.overshoot_percent, options.max_overshoot));
      warn_only = false;
    }
    const double t = OrInf(m.response_time);
    const double rel = t / t_aim - 1.0;
    if (std::abs(rel) > kTimeTolerance) {
      why.push_back(fmt::format("{} time {} is {} than the target {:.4g} s (+-{:.0f} %)",
                                ToString(options.measure), Seconds(m.response_time),
                                rel > 0 ? "slower" : "faster", t_aim, 100 * kTimeTolerance));
      // PID: the crossover rule sets the time only approximately.
      if (options.controller != ControllerType::kPid || std::abs(rel) > 1.0) warn_only = false;
      // Why it cannot be faster: sample time, dead time, actuator.
      if (rel > 0) {
        if (std::isfinite(t_fastest) && t_fastest > (1.0 + kTimeTolerance) * t_aim)
          why.push_back(
              fmt::format("the fastest design within the overshoot and robustness "
                          "limits (lambda = {:.4g}) responds in {:.4g} s",
                          lambda_fastest, t_fastest));
        else if (options.controller != ControllerType::kPid && std::isnan(lambda_fastest))
          why.push_back("no lambda meets the overshoot and robustness limits");
        const double t_min_delay = f.theta + Ts;
        if (t_aim < t_min_delay)
          why.push_back(
              fmt::format("the target is shorter than the dead time plus one sample "
                          "({:.4g} s)",
                          t_min_delay));
        if (Finite(L)) {
          // Open loop with the input at its limit from the step on: the fastest possible.
          const double u_lim = ev.step * K > 0 ? ev.limits.u_max : ev.limits.u_min;
          if (std::isfinite(u_lim)) {
            LinearPlant p(model, Ts);
            p.Reset();
            const bool rise = options.measure == ResponseMeasure::kRise;
            double t_lo = std::numeric_limits<double>::quiet_NaN(), t_fast = t_lo;
            for (int k = 0; k < static_cast<int>(ev.window / Ts) && std::isnan(t_fast); ++k) {
              const double frac = p.Measure() / ev.step;
              if (std::isnan(t_lo) && frac >= 0.1) t_lo = k * Ts;
              if (frac >= (rise ? 0.9 : 0.98)) t_fast = k * Ts - (rise ? t_lo : 0.0);
              p.Advance(u_lim);
            }
            if (std::isfinite(t_fast) && t_fast > t_aim)
              why.push_back(
                  fmt::format("with the input held at its limit {:.4g} the model needs "
                              "{:.4g} s (input limits [{:.4g}, {:.4g}])",
                              u_lim + u_from, t_fast, L.u_min, L.u_max));
          }
        }
      }
    }
    if (why.empty()) {
      r.review.push_back(
          {"specification", ReviewStatus::kOk,
           fmt::format("overshoot {:.3g} % <= {:.3g} %, {} time {} within {:.0f} % "
                       "of {:.4g} s",
                       m.overshoot_percent, options.max_overshoot, ToString(options.measure),
                       Seconds(m.response_time), 100 * kTimeTolerance, t_aim)});
    } else {
      std::string msg;
      for (const std::string& s : why) msg += (msg.empty() ? "" : "; ") + s;
      r.review.push_back(
          {"specification", warn_only ? ReviewStatus::kWarning : ReviewStatus::kFail, msg});
    }
  }

  bool any_fail = false;
  std::string fails;
  for (const ReviewItem& item : r.review) {
    if (item.status == ReviewStatus::kFail) {
      any_fail = true;
      fails += (fails.empty() ? "" : "; ") + item.check + ": " + item.message;
    }
  }
  if (!m.settled) {
    r.termination = AutoTuneTermination::kFailure;
    r.message = "no stable design found: " + fails;
  } else if (any_fail) {
    r.termination = AutoTuneTermination::kSpecNotMet;
    r.message = "specification not met: " + fails;
  } else {
    r.termination = AutoTuneTermination::kConverged;
    r.message = fmt::format("specification met ({} closed-loop simulations)", r.evaluations);
  }
  return r;
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
