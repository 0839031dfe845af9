// Tuning rules for the predictive controllers (DMC, GPC) from an FOPDT
// description K exp(-theta s) / (tau s + 1) of the plant.
//
// "shridhar-cooper" [1, 2] (the paper's "conventional" method, docs/paper.md
// section 6):
//   P = round(5 tau/Ts + k),  k = theta/Ts + 1                       [1, eq. 8]
//   lambda_condition = lambda_max(A'A) / 500                         (used)
//   lambda_formula   = (M/500) K^2 (3.5 tau/Ts + 2 - (M-1)/2)        [2, eq. 17]
// where A is the P x M dynamic matrix of the model's step response. Both aim
// at a condition number of about 500 for A'A + lambda I; the first is exact
// for the model at hand, the second is its closed-form approximation for an
// FOPDT. The paper prints P = 126 and lambda = 2.25 (M = 5) without formulas;
// they are reproduced by
//   * P: tau rounded to two significant digits (0.245 s -> 0.25 s) before
//     the formula: 5 * 25 + 0.1 + 1 = 126.1 -> 126 (123.6 with 0.245 s).
//     The rounding is an option (tau_significant_digits, 0 = none);
//   * lambda: lambda_max(A'A)/500 = 2.2508 with the model as identified
//     (tau = 0.245 s) and P = 126, M = 5; the closed form gives 2.24 with
//     tau = 0.25 s (2.195 with 0.245 s).
// The SISO form of [1] (f = (M/10)(3.5 tau/Ts + 2 - (M-1)/2), lambda = f K^2)
// gives about 110 and is not the paper's.
// "paper-modified": the paper's modified method, P = 126, M = 10,
//   lambda = 1.92, taken as explicit settings: its formula (the authors'
//   ASCC 2015 paper) is not published, and the rules above give 4.35-4.37 for
//   M = 10.
// "explicit": P, M and lambda given by the user.
//
// The FOPDT parameters come from the model: exactly for a continuous
// first-order model with delay, otherwise by the two-point method of Smith
// [3] on the step response (tau = 1.5 (t63 - t28), theta = t63 - tau,
// K = static gain).
//
// [1] R. Shridhar, D. J. Cooper, "A tuning strategy for unconstrained SISO
//     model predictive control", Ind. Eng. Chem. Res. 36 (1997) 729-746.
// [2] R. Shridhar, D. J. Cooper, "A tuning strategy for unconstrained
//     multivariable model predictive control", Ind. Eng. Chem. Res. 37
//     (1998) 4003-4016.
// [3] C. L. Smith, Digital Computer Process Control, Intext, 1972.
#pragma once

#include <limits>
#include <string>

#include <nlohmann/json_fwd.hpp>

#include "pneumid/control/prediction_model.hpp"
#include "pneumid/lti/fopdt.hpp"
#include "pneumid/lti/transfer_function.hpp"

namespace pneumid {

/// How P, M and lambda of a predictive controller are chosen (file comment).
enum class TuningRule { kShridharCooper, kPaperModified, kExplicit };
/// "shridhar-cooper", "paper-modified", "explicit".
std::string ToString(TuningRule rule);
/// Inverse of ToString (also accepts "conventional" = shridhar-cooper and
/// "modified" = paper-modified); throws InvalidArgument listing the valid names.
TuningRule TuningRuleFromString(const std::string& name);

/// FOPDT parameters (lti/fopdt.hpp) with how they were obtained.
struct FopdtEstimate : FopdtParams {
  /// "exact" (first-order model) or "two-point" (fitted to the step response).
  std::string method;
};

/// FOPDT description of a stable model (see the file comment).
/// @throws InvalidArgument for an unstable model or a zero static gain.
FopdtEstimate FopdtFromModel(const TransferFunction& model);

/// The tuning rule and the settings that override it.
struct TuningOptions {
  TuningRule rule = TuningRule::kShridharCooper;  ///< default shridhar-cooper
  /// Control horizon; 0 = the rule's default (5 for shridhar-cooper, or P when P < 5; 10 for
  /// paper-modified; required for explicit).
  int M = 0;
  /// Explicit settings (rule explicit only; also override P or lambda of the
  /// other rules when set): P > 0, lambda >= 0 (NaN = unset).
  int P = 0;
  /// Move suppression (>= 0); NaN (default) = the rule's.
  double lambda = std::numeric_limits<double>::quiet_NaN();
  /// Significant digits tau is rounded to in the P formula (0 = no rounding).
  int tau_significant_digits = 2;
  /// Target condition number of A'A + lambda I.
  double target_condition = 500.0;
  /// True when M, P >= 0 with M <= P when both are set, lambda is NaN or finite and >= 0,
  /// explicit has P, M and lambda, tau_significant_digits >= 0 and target_condition > 1;
  /// otherwise false with the reason in *error (when error is not null).
  bool IsValid(std::string* error) const;
};

/// Settings of a predictive controller from a tuning rule, with the values behind them.
struct TuningResult {
  TuningRule rule = TuningRule::kShridharCooper;  ///< the rule applied
  int P = 0;                                      ///< prediction horizon, samples
  int M = 0;                                      ///< control horizon, samples
  double lambda = 0.0;                            ///< the value used
  /// Both Shridhar-Cooper move suppressions (NaN for other rules).
  double lambda_condition = std::numeric_limits<double>::quiet_NaN();
  /// Closed-form (M/500) K^2 (3.5 tau/Ts + 2 - (M-1)/2) (NaN for other rules).
  double lambda_formula = std::numeric_limits<double>::quiet_NaN();
  double P_unrounded = 0.0;  ///< 5 tau'/Ts + theta/Ts + 1 before rounding
  double tau_used = 0.0;     ///< tau after rounding, as used for P
  FopdtEstimate fopdt;       ///< K, tau, theta the rule started from, and how they were found
  /// Human-readable statement of the formulas used, with their values.
  std::string formula;
  double Ts = 0.0;  ///< controller sample time the settings are for (s)
  /// True when lambda was given explicitly (TuningOptions::lambda) rather
  /// than taken from the rule.
  bool lambda_explicit = false;

  /// The JSON form of `pneumid tune --json`: rule, P, M, lambda; for
  /// shridhar-cooper also lambda_source ("lambda_condition" or "explicit"),
  /// lambda_condition, lambda_formula, P_unrounded, tau_used and fopdt {K,
  /// tau, theta, method}; then Ts and formula. NaN is written as null.
  nlohmann::ordered_json ToJson() const;
};

/// Horizons and move suppression for a controller sampled at model.Ts(): the
/// FOPDT from model.model(), the dynamic matrix from the sampled model.
/// @throws InvalidArgument for invalid options, or a model that
/// FopdtFromModel rejects (rule shridhar-cooper).
TuningResult Tune(const PredictionModel& model, const TuningOptions& options);
/// Tune(PredictionModel(model, Ts), options).
/// @throws InvalidArgument as above, and for Ts <= 0 or a discrete model with
/// another sample time.
TuningResult Tune(const TransferFunction& model, double Ts, const TuningOptions& options);

/// x rounded to `digits` significant decimal digits, halves away from zero
/// (0.245 -> 0.25 with 2 digits, despite 0.245 being stored as 0.24499...).
double RoundSignificant(double x, int digits);

}  // namespace pneumid
