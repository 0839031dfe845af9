// The result every identification method returns, and the request shared by
// the `pneumid identify` command and the bindings.
//
// Parameters are named and typed (ModelParams): FOPDT parameters are K, tau,
// theta (output units per input unit, s, s); polynomial models (ARX, ARMAX,
// OE, BJ) hold "a", "b", "nk", "Ts" (plus "c", "d", "f"), and "tf" is their
// continuous (d2c) form when it exists, the discrete model otherwise. The JSON
// form (`pneumid identify --json`) is in identified_model_io.hpp.
#pragma once

#include <initializer_list>
#include <limits>
#include <map>
#include <optional>
#include <string>
#include <variant>
#include <vector>

#include <Eigen/Core>

#include "pneumid/common/termination.hpp"
#include "pneumid/data/dataset.hpp"
#include "pneumid/data/preprocess.hpp"
#include "pneumid/identify/nonlinear/narx.hpp"
#include "pneumid/identify/parametric/subspace.hpp"
#include "pneumid/lti/transfer_function.hpp"
#include "pneumid/models/static_map.hpp"

namespace pneumid {

/// One named parameter: a real number, an integer (orders, delays in samples),
/// a coefficient vector, integers per input (delays of a multi-input model) or
/// rows (matrices of state-space models, coefficients per input).
using ParamValue = std::variant<double, int, std::vector<double>, std::vector<int>,
                                std::vector<std::vector<double>>>;

/// Named parameters of an identified model, ordered by name.
class ModelParams {
 public:
  using Map = std::map<std::string, ParamValue>;  ///< storage: name -> value, sorted by name
  /// No parameters.
  ModelParams() = default;
  /// From {name, value} pairs, e.g. {{"K", 2.0}, {"tau", 1.5}, {"theta", 0.2}}.
  ModelParams(std::initializer_list<Map::value_type> values) : values_(values) {}

  /// The parameter `name`, inserted (as 0.0) when missing.
  ParamValue& operator[](const std::string& name) { return values_[name]; }
  /// True when a parameter `name` exists (of any type).
  bool contains(const std::string& name) const { return values_.count(name) > 0; }
  /// @throws InvalidArgument naming the parameter and the available ones when missing.
  const ParamValue& at(const std::string& name) const;
  /// The number `name` (an int converts).
  /// @throws InvalidArgument when missing or not a number.
  double Scalar(const std::string& name) const;
  /// The number `name`, std::nullopt when missing or not a number.
  std::optional<double> FindScalar(const std::string& name) const;
  /// The coefficient vector `name`.
  /// @throws InvalidArgument when missing or not a vector of reals.
  const std::vector<double>& Vector(const std::string& name) const;

  bool empty() const { return values_.empty(); }       ///< True when there are no parameters.
  std::size_t size() const { return values_.size(); }  ///< Number of parameters.
  /// First (name, value) pair in name order, for range-for over the parameters.
  Map::const_iterator begin() const { return values_.begin(); }
  Map::const_iterator end() const { return values_.end(); }  ///< Past the last pair.
  bool operator==(const ModelParams&) const = default;

 private:
  Map values_;
};

/// Why a model should not be trusted (model_evaluation.hpp decides and ranks
/// flagged models after unflagged ones).
enum class ModelFlag {
  kNotFinite,         ///< "not_finite": the simulated output is not finite
  kUnstable,          ///< "unstable": a pole outside the stability region
  kNyquistPole,       ///< "nyquist_pole": a discrete pole near z = -1 (ripple aliased to Nyquist)
  kNoConvergence,     ///< "no_convergence": the iterative estimator did not converge
  kResidualsNotWhite  ///< "residuals_not_white": residual whiteness test failed
};
/// The flag's name as written in JSON and reports: "not_finite", "unstable", "nyquist_pole",
/// "no_convergence", "residuals_not_white".
std::string ToString(ModelFlag f);
/// Inverse of ToString. @throws InvalidArgument listing the valid names.
ModelFlag ModelFlagFromString(const std::string& name);

/// A flag and the measured reason ("pole at z = -0.962, 0.038 from -1").
struct ModelFlagNote {
  ModelFlag flag = ModelFlag::kNotFinite;  ///< what is wrong with the model
  std::string reason;                      ///< measured evidence, in words and numbers
  bool operator==(const ModelFlagNote&) const = default;
};

/// Covariance of the estimated parameters: `matrix` (n x n, symmetric) in the
/// order of `names`, which name entries of IdentifiedModel::params (for
/// polynomial models the coefficients a1.., b1.., c1.., d1.., f1.. of
/// PolynomialModel::ParameterNames(), which index into the vectors "a", "b",
/// ...). Confidence bands of responses are computed from it
/// (model_uncertainty.hpp).
struct ParameterCovariance {
  std::vector<std::string> names;  ///< parameter names, one per row/column of `matrix`
  Eigen::MatrixXd matrix;          ///< covariance, in squared units of the parameters
};

/// How an identified discrete model's continuous form `tf` was obtained:
///  - kZoh: the exact zero-order-hold equivalent (matrix logarithm, D2C);
///  - kTustin: no zoh equivalent exists (a pole on the negative real axis),
///    `tf` is the bilinear approximation and the model is used in its
///    discrete form (model_io.hpp);
///  - kNone: neither exists, `tf` is the discrete model itself.
/// Written "zoh", "tustin", "none" (model file key "continuous_form").
enum class ContinuousForm { kZoh, kTustin, kNone };
/// "zoh", "tustin", "none".
std::string ToString(ContinuousForm form);
/// Parses the names of ToString; @throws InvalidArgument naming the valid ones.
ContinuousForm ContinuousFormFromString(const std::string& name);

/// A model from one identification method: its parameters, transfer function,
/// operating point, fit on the data and the reasons not to trust it.
struct IdentifiedModel {
  std::string method;     ///< e.g. "reaction-curve", "fit-p1d", "arx"
  std::string structure;  ///< e.g. "FOPDT", "PTn", "P2D", "ARX"
  ModelParams params;     ///< named parameters
  ModelParams param_std;  ///< standard deviations when known (same names as params)
  TransferFunction tf;    ///< model usable by the rest of the toolkit (continuous if possible)
  std::optional<TransferFunction> discrete;  ///< discrete form of polynomial models
  /// How `tf` derives from `discrete` (models estimated in discrete time only).
  std::optional<ContinuousForm> continuous_form;
  double fit_percent = 0.0;  ///< NRMSE fit, MATLAB compare: 100 (1 - |y - yhat| / |y - mean y|)
  double iae = 0.0;          ///< integral of |y - yhat| dt over the data (output units * s)
  std::vector<std::string> notes;  ///< warnings (poor excitation, not converged, ...)
  /// Operating point of the model: on data it predicts y0 + G (u - u0) from a
  /// state at rest (model_evaluation.hpp, SimulateModel). Step-response
  /// methods take u0 and y0 from the level before the step (process fits
  /// estimate y0), the polynomial and state-space methods model the signals
  /// as they are (0, 0), the correlation methods their means.
  double u0 = 0.0;
  double y0 = 0.0;  ///< output of the operating point (output units); see u0
  /// How the estimator ended (kNoConvergence: the last iterate is returned).
  Termination termination = Termination::kConvergence;
  /// NRMSE fit on held-out validation data (NaN when none were given); the
  /// ranking uses it instead of fit_percent when present.
  double validation_fit_percent = std::numeric_limits<double>::quiet_NaN();
  /// NRMSE fit on the held-out samples the estimation data determine: those
  /// outside the input intervals the estimation data leave undetermined (the
  /// identified models' input_map_undetermined), a settling time after each
  /// visit excluded too (IdentifyModels). Set only when the held-out data
  /// visit such intervals; the ranking then uses it instead of
  /// validation_fit_percent. NaN otherwise; not written to model files.
  double determined_fit_percent = std::numeric_limits<double>::quiet_NaN();
  /// Reasons not to trust the model (empty: none found).
  std::vector<ModelFlagNote> flags;
  /// The preprocessing of the data the model was identified from (window,
  /// offsets, filter, decimation); u0/y0 above refer to the preprocessed
  /// signals. `validate` re-applies it to new data (ApplyRecorded).
  std::optional<PreprocessRecord> preprocessing;
  /// Parameter covariance when the estimator gives one (ARX, ARMAX, OE, BJ,
  /// IV4, fit-* process models: full; diagonal param_std^2 for a fit whose
  /// full covariance is not finite); none for
  /// the graphical, subspace and correlation methods.
  std::optional<ParameterCovariance> covariance;
  /// Nonlinear parts (nonlinear.hpp; absent for linear models): the input map
  /// f of a Hammerstein model or a static map (yhat from f(u) through
  /// `discrete`), the output map of a Wiener model, a polynomial NARX model.
  std::optional<StaticMap> input_map;
  std::optional<StaticMap> output_map;  ///< Wiener: g applied to the linear part's output
  std::optional<NarxModel> narx;        ///< NARX and affine NARX: the polynomial model
  /// Input intervals {lo, hi} between neighbouring levels of the estimation
  /// data across which the input map changes steeply with no sample inside
  /// (FindMapGaps, nonlinear/static_map_fit.hpp): the data leave the map
  /// undetermined there, and a simulation whose input visits them is a guess
  /// (ExtrapolationWarnings warns). Model file key "input_map_undetermined",
  /// [[lo, hi], ...]; empty for linear models and files that lack it.
  std::vector<std::pair<double, double>> input_map_undetermined;
  /// Set by RankModels when parsimony ranked this model ahead of models that
  /// score better but not by more than the tolerance, e.g. "preferred to hw
  /// (97.13 %, 28 parameters) for fewer parameters (17): simulation errors
  /// within 5 % of each other"; empty otherwise. Not written to model files.
  std::string rank_note;
  /// The held-out record a structure search scored this model's candidate
  /// orders, delay, degree or terms on (IdentifyNonlinear's `held_out`, e.g.
  /// "the last 30 % of est.csv"); empty when the structure was given, or chosen
  /// on a split of the estimation data itself. A held-out fit on that record
  /// includes the choice, and RankReason says so. Not written to model files.
  std::string structure_chosen_on;
};

/// The operating point (u0, y0) the polynomial and state-space methods (arx,
/// iv4, armax, oe, bj, n4sid) model the signals around: they estimate
/// G from the deviations u - u0, y - y0 and the model predicts
/// y0 + G (u - u0) (MATLAB: detrend before estimation, the offsets stored in
/// the model as getTrend/retrend do).
///  - kAuto: zero when the record starts at rest at zero (the first samples of
///    u and y within 5 % of their range of 0: a step test from rest, as the
///    paper's, is modelled as it is). Otherwise the model is identified both
///    from the raw signals and around the means, and the one that simulates
///    the estimation data better is kept (a note gives both fits): raw data
///    need no detrending by hand (the cascaded tanks start at 5 V), and data
///    that are linear without offset keep their exact model.
///  - kZero: the signals as they are (an offset is then a model error).
///  - kMean: the means of u and y over the record (`--detrend mean`).
///  - kInitial: the means over the first samples (the level before a step;
///    `--remove-initial`), n = max(1, min(20, N / 50)).
enum class OperatingPointKind { kAuto, kZero, kMean, kInitial };
/// "auto", "zero", "mean", "initial".
std::string ToString(OperatingPointKind k);
/// Parses the names of ToString; @throws InvalidArgument naming the valid ones.
OperatingPointKind OperatingPointKindFromString(const std::string& name);

/// Options shared by every method of `pneumid identify`.
struct IdentifyRequest {
  int input = 0;   ///< input column
  int output = 0;  ///< output column
  int order = 2;   ///< PTn / Strejc order n
  /// na: A order (0..50) of arx, iv4, armax, oe, bj; the order of n4sid, the linear part of
  /// hammerstein/wiener and the output lags of narx.
  int na = 3, nb = 3, nk = 1;  ///< nk: input delay in samples (0..1000)
  /// nc: C order (noise numerator) of armax and bj (0..50).
  int nc = 1, nd = 1, nf = 3;  ///< nf: F order of oe and bj (0..50)
  /// @var nb
  /// Number of B coefficients (1..50); the input lags of narx.
  /// @var nd
  /// D order (noise denominator) of bj (0..50).
  bool feedthrough = false;  ///< n4sid: estimate the D term (subspace.hpp)
  SubspaceWeighting n4sid_weight = SubspaceWeighting::kMoesp;  ///< n4sid: W1/W2 weighting
  /// Operating point of arx, iv4, armax, oe, bj, n4sid (see OperatingPointKind).
  OperatingPointKind operating_point = OperatingPointKind::kAuto;
  /// True when the columns are >= 0 and the orders in the ranges above (order 1..20);
  /// otherwise false with the reason in *error (when error is not null).
  bool IsValid(std::string* error) const;
};

}  // namespace pneumid
