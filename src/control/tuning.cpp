#include "pneumid/control/tuning.hpp"

#include <cmath>

#include <fmt/format.h>
#include <Eigen/Eigenvalues>
#include <nlohmann/json.hpp>

#include "pneumid/common/check.hpp"
#include "pneumid/common/enum_names.hpp"
#include "pneumid/lti/response.hpp"

namespace pneumid {

namespace {
constexpr EnumName<TuningRule> kTuningRuleNames[] = {
    {TuningRule::kShridharCooper, "shridhar-cooper"},
    {TuningRule::kPaperModified, "paper-modified"},
    {TuningRule::kExplicit, "explicit"},
    {TuningRule::kShridharCooper, "conventional"},
    {TuningRule::kPaperModified, "modified"},
};
}  // namespace

std::string ToString(TuningRule v) { return std::string(EnumToString(kTuningRuleNames, v)); }

TuningRule TuningRuleFromString(const std::string& name) {
  return EnumFromString(kTuningRuleNames, name, "tuning rule");
}

double RoundSignificant(double x, int digits) {
  PNEUMID_CHECK(digits >= 1, "need at least one significant digit, got {}", digits);
  if (x == 0.0 || !std::isfinite(x)) return x;
  const double e = std::floor(std::log10(std::abs(x)));
  const double scale = std::pow(10.0, digits - 1 - e);
  // The relative nudge makes decimal halves stored just below .5 round up.
  return std::round(x * scale * (1.0 + 1e-12)) / scale;
}

FopdtEstimate FopdtFromModel(const TransferFunction& model) {
  PNEUMID_CHECK(model.IsStable(), "the model {} is not stable; no FOPDT description",
                model.ToString());
  const double K = model.DcGain();
  PNEUMID_CHECK(std::isfinite(K) && K != 0.0,
                "the model's static gain must be finite and "
                "nonzero, got {}",
                K);
  FopdtEstimate p;
  p.K = K;
  if (model.IsContinuous()) {
    const TransferFunction g = model.Normalized();
    const Eigen::VectorXd num = poly::TrimLeading(g.num());
    if (g.Order() == 1 && num.size() == 1) {
      // b / (s + a1): tau = 1 / a1.
      p.tau = 1.0 / g.den()(g.den().size() - 1);
      p.theta = model.delay();
      p.method = "exact";
      return p;
    }
  }
  // Smith's two-point method on the unit step response (lti/fopdt.hpp); a
  // level never reached counts as reached at the end of the response.
  const TimeResponse r = Step(model);
  const Eigen::VectorXd normalized = r.y / K;
  auto crossing = [&](double fraction) {
    const double t = FirstCrossing(r.t, normalized, fraction);
    return std::isnan(t) ? r.t(r.t.size() - 1) : t;
  };
  static_cast<FopdtParams&>(p) = SmithTwoPoint(K, crossing(kSmithLevel1), crossing(kSmithLevel2));
  p.method = "two-point";
  return p;
}

bool TuningOptions::IsValid(std::string* error) const {
  auto fail = [&](const std::string& message) {
    if (error) *error = message;
    return false;
  };
  if (M < 0) return fail(fmt::format("M must be >= 0 (0 = rule default), got {}", M));
  if (P < 0) return fail(fmt::format("P must be >= 0 (0 = rule default), got {}", P));
  if (!std::isnan(lambda) && !(lambda >= 0.0 && std::isfinite(lambda)))
    return fail(fmt::format("lambda must be finite and >= 0, got {}", lambda));
  if (rule == TuningRule::kExplicit && (P == 0 || M == 0 || std::isnan(lambda)))
    return fail("the explicit rule needs P, M and lambda");
  if (tau_significant_digits < 0)
    return fail(fmt::format("tau_significant_digits must be >= 0, got {}", tau_significant_digits));
  if (!(target_condition > 1.0))
    return fail(fmt::format("target_condition must exceed 1, got {}", target_condition));
  if (P > 0 && M > P) return fail(fmt::format("need M <= P, got M = {}, P = {}", M, P));
  if (P > kMaxPredictionHorizon || M > kMaxControlHorizon)
    return fail(fmt::format("P = {} and M = {} exceed the largest horizons taken, P = {} and M = {}",
                            P, M, kMaxPredictionHorizon, kMaxControlHorizon));
  return true;
}

TuningResult Tune(const TransferFunction& model, double Ts, const TuningOptions& options) {
  std::string error;
  PNEUMID_CHECK(options.IsValid(&error), "invalid tuning options: {}", error);
  return Tune(PredictionModel(model, Ts), options);
}

TuningResult Tune(const PredictionModel& model, const TuningOptions& options) {
  std::string error;
  PNEUMID_CHECK(options.IsValid(&error), "invalid tuning options: {}", error);
  const double Ts = model.Ts();
  TuningResult r;
  r.rule = options.rule;
  r.Ts = Ts;
  r.lambda_explicit = !std::isnan(options.lambda);
  switch (options.rule) {
    case TuningRule::kShridharCooper: {
      r.fopdt = FopdtFromModel(model.model());
      const FopdtEstimate& f = r.fopdt;
      r.tau_used = options.tau_significant_digits > 0
                       ? RoundSignificant(f.tau, options.tau_significant_digits)
                       : f.tau;
      r.P_unrounded = 5.0 * r.tau_used / Ts + f.theta / Ts + 1.0;
      PNEUMID_CHECK(options.P > 0 || r.P_unrounded <= kMaxPredictionHorizon,
                    "Shridhar-Cooper: the prediction horizon P = 5 tau/Ts + theta/Ts + 1 = {:g} "
                    "samples (tau = {} s, theta = {} s, Ts = {} s) exceeds the largest taken, "
                    "{}: choose a sample time of at least {:.3g} s",
                    r.P_unrounded, r.tau_used, f.theta, Ts, kMaxPredictionHorizon,
                    (5.0 * r.tau_used + f.theta) / (kMaxPredictionHorizon - 1));
      r.P = options.P > 0 ? options.P : std::max(1, static_cast<int>(std::lround(r.P_unrounded)));
      // Five moves, or P when the horizon is shorter (a plant fast for Ts).
      r.M = options.M > 0 ? options.M : std::min(5, r.P);
      PNEUMID_CHECK(r.M <= r.P, "need M <= P, got M = {}, P = {}", r.M, r.P);
      const Eigen::MatrixXd A = model.DynamicMatrix(r.P, r.M);
      const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(A.transpose() * A,
                                                               Eigen::EigenvaluesOnly);
      r.lambda_condition = eig.eigenvalues().maxCoeff() / options.target_condition;
      r.lambda_formula = r.M / options.target_condition * f.K * f.K *
                         (3.5 * r.tau_used / Ts + 2.0 - (r.M - 1) / 2.0);
      r.lambda = std::isnan(options.lambda) ? r.lambda_condition : options.lambda;
      r.formula = fmt::format(
          "Shridhar-Cooper: P = round(5 tau/Ts + theta/Ts + 1) = round({:.4g}) = {} with tau = "
          "{:g} s ({} FOPDT tau = {:.6g} s rounded to {} significant digits), theta = {:g} s; "
          "lambda = lambda_max(A'A)/{:g} = {:.6g} (used; A is the {}x{} dynamic matrix), "
          "closed form (M/{:g}) K^2 (3.5 tau/Ts + 2 - (M-1)/2) = {:.6g}",
          r.P_unrounded, r.P, r.tau_used, f.method, f.tau, options.tau_significant_digits, f.theta,
          options.target_condition, r.lambda_condition, r.P, r.M, options.target_condition,
          r.lambda_formula);
      if (options.P > 0 || !std::isnan(options.lambda))
        r.formula += "; overridden by explicit settings";
      break;
    }
    case TuningRule::kPaperModified:
      r.P = options.P > 0 ? options.P : 126;
      r.M = options.M > 0 ? options.M : 10;
      r.lambda = std::isnan(options.lambda) ? 1.92 : options.lambda;
      PNEUMID_CHECK(r.M <= r.P, "need M <= P, got M = {}, P = {}", r.M, r.P);
      r.formula =
          "paper's modified method: P = 126, M = 10, lambda = 1.92 taken as published settings "
          "(the formula is not published)";
      break;
    case TuningRule::kExplicit:
      r.P = options.P;
      r.M = options.M;
      r.lambda = options.lambda;
      r.formula = "explicit settings";
      break;
  }
  return r;
}

nlohmann::ordered_json TuningResult::ToJson() const {
  auto number = [](double v) { return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(); };
  nlohmann::ordered_json j;
  j["rule"] = ToString(rule);
  j["P"] = P;
  j["M"] = M;
  j["lambda"] = lambda;
  if (rule == TuningRule::kShridharCooper) {
    j["lambda_source"] = lambda_explicit ? "explicit" : "lambda_condition";
    j["lambda_condition"] = number(lambda_condition);
    j["lambda_formula"] = number(lambda_formula);
    j["P_unrounded"] = P_unrounded;
    j["tau_used"] = tau_used;
    j["fopdt"] = {
        {"K", fopdt.K}, {"tau", fopdt.tau}, {"theta", fopdt.theta}, {"method", fopdt.method}};
  }
  j["Ts"] = Ts;
  j["formula"] = formula;
  return j;
}

}  // namespace pneumid
