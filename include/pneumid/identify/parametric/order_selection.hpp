// ARX order and delay selection (MATLAB arxstruc, selstruc, delayest [1]).
//
// Every candidate ARX(na, nb, nk) of the sweep is fitted by least squares on the
// same regression rows t = n0 .. N-1 (n0 from the largest orders of the sweep),
// so that the losses are comparable. With V = sum eps^2 / N the loss on the
// estimation data (or on validation data when given), N the number of rows and
// d = na + nb the number of parameters:
//   AIC   N ln V + 2 d                                [2] eq. 16.33 (Akaike 1974)
//   AICc  AIC + 2 d (d + 1) / (N - d - 1)             (Hurvich & Tsai 1989)
//   FPE   V (1 + d/N) / (1 - d/N)                     [2] eq. 16.32 (Akaike 1969)
//   MDL   N ln V + d ln N                             [2] eq. 16.34 (Rissanen 1978)
// The additive constants of the Gaussian log-likelihood are left out; they do
// not change the ranking. delayest: the nk of least loss for ARX(na, nb, nk).
//
// [1] MathWorks, System Identification Toolbox, arxstruc / selstruc / delayest,
//     https://www.mathworks.com/help/ident/ref/arxstruc.html
// [2] L. Ljung, System Identification: Theory for the User, 2nd ed., 1999.
#pragma once

#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "pneumid/data/dataset.hpp"
#include "pneumid/identify/identified_model.hpp"

namespace pneumid {

/// Inclusive integer range min..max.
struct OrderRange {
  int min = 1;  ///< smallest value tried
  int max = 5;  ///< largest value tried (>= min)
  /// Parses "3" or "1:5". @throws InvalidArgument naming the text.
  static OrderRange Parse(const std::string& text);
  /// "min:max", e.g. "1:5" (also for a single value: "3:3").
  std::string ToString() const;
};

/// Criterion by which the best candidate is chosen: the loss V alone, or AIC, AICc, FPE,
/// MDL (formulas above; smaller is better for all).
enum class OrderCriterion { kLoss, kAic, kAicc, kFpe, kMdl };
/// "loss", "aic", "aicc", "fpe", "mdl".
std::string ToString(OrderCriterion c);
/// Inverse of ToString; throws InvalidArgument listing the valid names.
OrderCriterion OrderCriterionFromString(const std::string& name);

/// Ranges of the ARX orders and delay swept by SelectArxOrders, and the data columns.
struct OrderSelectionOptions {
  OrderRange na{1, 5};  ///< >= 0
  OrderRange nb{1, 5};  ///< >= 1
  OrderRange nk{0, 3};  ///< >= 0
  int input = 0;   ///< input column (>= 0)
  int output = 0;  ///< output column (>= 0)
  /// The operating point (u0, y0) the ARX models are fitted about, from the
  /// estimation data (identified_model.hpp): kAuto is zero for a record that
  /// starts at rest at zero and the means otherwise (an ARX without an
  /// intercept spends orders on an offset: ARX(2,2,3) data with u + 50,
  /// y + 100 chose 5, 5, 3 by every criterion), as `identify` fits about it.
  OperatingPointKind operating_point = OperatingPointKind::kAuto;
  /// True when each range has min <= max within the bounds above and the columns are >= 0;
  /// otherwise false with the reason in *error (when error is not null).
  bool IsValid(std::string* error) const;
};

/// One ARX(na, nb, nk) of the sweep with its loss and information criteria.
struct OrderCandidate {
  /// A order.
  int na = 0, nb = 0, nk = 0;  ///< input delay in samples
  /// @var nb
  /// Number of B coefficients.
  /// @var aicc
  /// AICc = AIC + 2 d (d + 1) / (N - d - 1); infinity when N <= d + 1.
  /// @var fpe
  /// FPE = V (1 + d/N) / (1 - d/N), in output units^2; infinity when d >= N.
  int num_parameters = 0;  ///< d = na + nb
  double loss = 0.0;  ///< V
  /// AIC = N ln V + 2 d.
  double aic = 0.0, aicc = 0.0, fpe = 0.0, mdl = 0.0;  ///< MDL = N ln V + d ln N
  /// Value of criterion c.
  double Value(OrderCriterion c) const;
};

/// Result of SelectArxOrders: every candidate, comparable on the same N rows.
struct OrderSelection {
  std::vector<OrderCandidate> candidates;  ///< in sweep order (na, nb, nk nested)
  long long num_rows = 0;                  ///< N used by every candidate
  bool validation = false;                 ///< losses measured on validation data
  double u0 = 0.0;                         ///< input level the models are fitted about
  double y0 = 0.0;                         ///< output level the models are fitted about
  /// Index of the best candidate by criterion c (the first one on ties).
  std::size_t Best(OrderCriterion c) const;
  /// {num_rows, loss_on ("estimation" or "validation"), candidates: [{na, nb, nk,
  /// num_parameters, loss, aic, aicc, fpe, mdl}], best: {criterion name: {na, nb, nk}}}.
  nlohmann::json ToJson() const;
};

/// Sweeps the ranges of `options`. With `validation` non-null, the loss is the
/// one-step prediction-error loss of each model on the validation data.
/// @throws InvalidArgument for invalid options; DataError when the data are too short.
OrderSelection SelectArxOrders(const Dataset& data, const OrderSelectionOptions& options,
                               const Dataset* validation = nullptr);

/// delayest: the delay nk in [nk_min, nk_max] of least loss for ARX(na, nb, nk).
/// @throws InvalidArgument / DataError as SelectArxOrders.
int EstimateDelay(const Dataset& data, int na = 2, int nb = 2, int nk_min = 0, int nk_max = 10,
                  int input = 0, int output = 0);

}  // namespace pneumid
