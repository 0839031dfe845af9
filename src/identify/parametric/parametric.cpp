#include "pneumid/identify/parametric/parametric.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "pneumid/common/check.hpp"
#include "pneumid/data/preprocess.hpp"
#include "pneumid/identify/parametric/arx.hpp"
#include "pneumid/identify/nonparametric/cra.hpp"
#include "pneumid/identify/evaluation/fit_metrics.hpp"
#include "pneumid/identify/identified_model_io.hpp"
#include "pneumid/identify/parametric/iv.hpp"
#include "pneumid/identify/evaluation/model_evaluation.hpp"
#include "pneumid/identify/nonparametric/nonparametric_freq.hpp"
#include "pneumid/identify/parametric/pem.hpp"
#include "pneumid/identify/parametric/subspace.hpp"
#include "pneumid/lti/conversion.hpp"
#include "pneumid/lti/response.hpp"

namespace pneumid {

const std::vector<std::string>& ParametricMethodNames() {
  static const std::vector<std::string> names = {"arx", "iv4",   "armax", "oe",
                                                 "bj",  "n4sid", "cra",   "spa"};
  return names;
}

bool IsParametricMethod(const std::string& name) {
  const auto& n = ParametricMethodNames();
  return std::find(n.begin(), n.end(), name) != n.end();
}

// Continuous form of an identified discrete model. Zero-order-hold d2c (matrix
// logarithm) is exact for sampled data with a held input and is tried first.
// A discrete pole on the negative real axis (often the alias of a ripple at
// the Nyquist frequency) has no real logarithm; the continuous form then comes
// from the bilinear (tustin) map s = (2/Ts)(z - 1)/(z + 1), which exists for
// every pole but z = -1, and a note says so. When neither exists the discrete
// model is kept, also with a note.
// Sets model->tf and model->continuous_form from the discrete model g.
static void SetContinuousForm(const TransferFunction& g, IdentifiedModel* model) {
  try {
    model->tf = D2C(g, DiscretizationMethod::kZoh);
    model->continuous_form = ContinuousForm::kZoh;
  } catch (const InvalidArgument& zoh_error) {
    try {
      model->tf = D2C(g, DiscretizationMethod::kTustin);
      model->continuous_form = ContinuousForm::kTustin;
      model->notes.push_back(std::string("continuous form by tustin d2c: no zoh equivalent (") +
                             zoh_error.what() + ")");
    } catch (const InvalidArgument& e) {
      model->tf = g;
      model->continuous_form = ContinuousForm::kNone;
      model->notes.push_back(std::string("no continuous (zoh d2c) equivalent: ") +
                             zoh_error.what() + "; tustin: " + e.what());
    }
  }
}

IdentifiedModel ToIdentifiedModel(const std::string& method, const PolynomialModel& model,
                                  const EstimationSummary& summary, const Dataset& data, int input,
                                  int output) {
  IdentifiedModel r;
  r.method = method;
  r.structure = model.structure;
  r.params = ToModelParams(model);
  const Eigen::VectorXd sd = model.ParameterStd();
  if (sd.size() > 0) {
    const auto names = model.ParameterNames();
    for (std::size_t i = 0; i < names.size(); ++i)
      r.param_std[names[i]] = sd[static_cast<Eigen::Index>(i)];
    if (model.covariance.allFinite()) r.covariance = ParameterCovariance{names, model.covariance};
  }
  r.discrete = model.ToTransferFunction(0);
  SetContinuousForm(*r.discrete, &r);
  r.termination = summary.termination;
  if (model.num_inputs() == 1) {
    ScoreModel(data, input, output, &r);
  } else {
    const Eigen::VectorXd y = data.y(output);
    const Eigen::VectorXd yhat = Simulate(model, data.inputs());
    if (yhat.allFinite()) {
      r.fit_percent = NrmseFit(y, yhat);
      r.iae = Iae(data.time(), y, yhat);
    } else {
      r.fit_percent = -std::numeric_limits<double>::infinity();
      r.iae = std::numeric_limits<double>::infinity();
      r.notes.push_back("the simulated model output diverges (unstable model)");
    }
  }
  r.notes.push_back(summary.BriefReport());
  for (const auto& w : summary.warnings) r.notes.push_back(w);
  return r;
}

namespace {

Dataset SisoData(const Dataset& data, const IdentifyRequest& request) {
  std::string error;
  PNEUMID_CHECK(request.IsValid(&error), "invalid identification request: {}", error);
  PNEUMID_CHECK(request.input >= 0 && request.input < data.num_inputs(),
                "input column {} out of range [0, {})", request.input, data.num_inputs());
  PNEUMID_CHECK(request.output >= 0 && request.output < data.num_outputs(),
                "output column {} out of range [0, {})", request.output, data.num_outputs());
  data.RequireUniform();
  // SISO data is shared, not copied.
  return data.SelectChannels({request.input}, {request.output});
}

// Fills discrete/tf (d2c when possible), fit and IAE of a transfer-function model.
IdentifiedModel FinishTransferFunctionModel(IdentifiedModel m, const TransferFunction& g,
                                            const EstimationSummary& summary, const Dataset& d,
                                            bool try_d2c = true) {
  m.discrete = g;
  m.tf = g;
  if (try_d2c) SetContinuousForm(g, &m);
  m.termination = summary.termination;
  if (!try_d2c) {
    // Non-parametric estimates describe deviations from the mean operating
    // point (they are computed from mean-removed signals).
    m.u0 = d.u(0).mean();
    m.y0 = d.y(0).mean();
    m.notes.push_back("fit of the deviations from the mean input and output");
  }
  ScoreModel(d, 0, 0, &m);
  m.notes.push_back(summary.BriefReport());
  for (const auto& w : summary.warnings) m.notes.push_back(w);
  return m;
}

// The operating point of OperatingPointKind (identified_model.hpp) on SISO
// data, with a note saying which was taken; (0, 0) and no note for kZero.
struct ChosenOperatingPoint {
  double u0 = 0.0;
  double y0 = 0.0;
  std::string note;
  bool ambiguous = false;  ///< kAuto away from rest at zero: also try the raw signals
  /// kAuto on a record that starts at rest away from zero: the rest, (u_init,
  /// y_init), is a third candidate (at_rest), preferred on a tie.
  bool at_rest = false;
  double u_rest = 0.0, y_rest = 0.0;
  std::string rest_note;
};

}  // namespace

bool StartsAtRestAtZero(const Eigen::VectorXd& u, const Eigen::VectorXd& y) {
  if (u.size() == 0 || y.size() == 0) return true;
  const Eigen::Index n0 = std::max<Eigen::Index>(1, std::min<Eigen::Index>(20, u.size() / 50));
  const double u_range = u.maxCoeff() - u.minCoeff();
  const double y_range = y.maxCoeff() - y.minCoeff();
  return std::abs(u.head(n0).mean()) <= 0.05 * u_range &&
         std::abs(y.head(n0).mean()) <= 0.05 * y_range;
}

namespace {

ChosenOperatingPoint ChooseOperatingPoint(const Dataset& d, OperatingPointKind kind) {
  const Eigen::VectorXd u = d.u(0);
  const Eigen::VectorXd y = d.y(0);
  const Eigen::Index n0 = std::max<Eigen::Index>(1, std::min<Eigen::Index>(20, d.size() / 50));
  const double u_init = u.head(n0).mean();
  const double y_init = y.head(n0).mean();
  ChosenOperatingPoint op;
  if (kind == OperatingPointKind::kAuto) {
    const double u_range = u.maxCoeff() - u.minCoeff();
    const double y_range = y.maxCoeff() - y.minCoeff();
    if (StartsAtRestAtZero(u, y)) return op;
    op.ambiguous = true;
    // At rest: the input constant and the output within 2 % of its range
    // over the first samples (and the record moves after them).
    const auto head_u = u.head(n0).array(), head_y = y.head(n0).array();
    op.at_rest = n0 >= 5 && u_range > 0.0 && y_range > 0.0 &&
                 head_u.maxCoeff() - head_u.minCoeff() <= 1e-9 * u_range &&
                 head_y.maxCoeff() - head_y.minCoeff() <= 0.02 * y_range;
    if (op.at_rest) {
      op.u_rest = u_init;
      op.y_rest = y_init;
      op.rest_note = fmt::format(
          "operating point u0 = {:.6g}, y0 = {:.6g} (the rest the record starts at, the means of "
          "its first {} samples): the model is G from u - u0 to y - y0",
          u_init, y_init, n0);
    }
    kind = OperatingPointKind::kMean;
  }
  if (kind == OperatingPointKind::kMean) {
    op.u0 = u.mean();
    op.y0 = y.mean();
    op.note = fmt::format(
        "operating point u0 = {:.6g}, y0 = {:.6g} (the means of the record): the model is G "
        "from u - u0 to y - y0; --operating-point zero models the raw signals",
        op.u0, op.y0);
  } else if (kind == OperatingPointKind::kInitial) {
    op.u0 = u_init;
    op.y0 = y_init;
    op.note = fmt::format(
        "operating point u0 = {:.6g}, y0 = {:.6g} (the means of the first {} samples): the model "
        "is G from u - u0 to y - y0",
        op.u0, op.y0, n0);
  }
  return op;
}

// The SISO data less an operating point.
Dataset Deviations(const Dataset& d, const ChosenOperatingPoint& op) {
  if (op.u0 == 0.0 && op.y0 == 0.0) return d;
  return SubtractOperatingPoint(
      d, {Eigen::VectorXd::Constant(1, op.u0), Eigen::VectorXd::Constant(1, op.y0)});
}

// Moves a model identified from deviations to the operating point: the fit
// and IAE are offset-free, so the scores stay as computed.
IdentifiedModel AtOperatingPoint(IdentifiedModel m, const ChosenOperatingPoint& op) {
  if (op.note.empty()) return m;
  m.u0 += op.u0;
  m.y0 += op.y0;
  m.notes.insert(m.notes.begin(), op.note);
  return m;
}

// NRMSE fit of the model simulated on SISO data from its estimated initial
// state (-inf when the simulation fails or diverges).
double FitFromEstimatedState(const IdentifiedModel& m, const Dataset& d) {
  try {
    const Eigen::VectorXd yhat = SimulateModel(m, d, 0, 0, InitialCondition::kEstimate);
    return yhat.allFinite() ? NrmseFit(d.y(0), yhat) : -std::numeric_limits<double>::infinity();
  } catch (const InvalidArgument&) {
    return -std::numeric_limits<double>::infinity();
  }
}

}  // namespace

namespace {
IdentifiedModel IdentifyParametricAtRest(const std::string& method, const Dataset& d,
                                         const IdentifyRequest& request);
}  // namespace

IdentifiedModel IdentifyParametric(const std::string& method, const Dataset& data,
                                   const IdentifyRequest& request) {
  PNEUMID_CHECK(IsParametricMethod(method), "unknown parametric method '{}'; valid: {}", method,
                fmt::format("{}", fmt::join(ParametricMethodNames(), ", ")));
  const Dataset siso = SisoData(data, request);
  const bool offset_model = method != "cra" && method != "spa";
  const ChosenOperatingPoint op =
      offset_model ? ChooseOperatingPoint(siso, request.operating_point) : ChosenOperatingPoint{};
  if (!op.ambiguous)
    return AtOperatingPoint(IdentifyParametricAtRest(method, Deviations(siso, op), request), op);
  // kAuto on a record that does not start at rest at zero: the raw signals
  // (the data may be linear without offset, as a simulation from rest) or the
  // means (an offset the linear model cannot hold, as on the cascaded tanks),
  // whichever simulates the estimation data better from its estimated
  // initial state (the record need not start at rest at either point).
  IdentifiedModel raw;
  std::string raw_error;
  try {
    raw = IdentifyParametricAtRest(method, siso, request);
  } catch (const DataError& e) {
    raw_error = e.what();
  } catch (const InvalidArgument& e) {
    raw_error = e.what();
  }
  IdentifiedModel centred =
      AtOperatingPoint(IdentifyParametricAtRest(method, Deviations(siso, op), request), op);
  const double raw_fit = raw_error.empty() ? FitFromEstimatedState(raw, siso)
                                           : -std::numeric_limits<double>::infinity();
  const double centred_fit = FitFromEstimatedState(centred, siso);
  // A record that starts at rest: a model around that rest simulates it from
  // rest as it starts (the fit that ranks it), where the raw signals' or the
  // means' model would start away from it (an exact ARX of a record at rest
  // at u = 20, y = 50 scored 73 % from rest at zero, 99.45 % from its
  // estimated state). Taken unless another simulates the record better by
  // more than half a point from its estimated initial state.
  if (op.at_rest) {
    ChosenOperatingPoint rest;
    rest.u0 = op.u_rest;
    rest.y0 = op.y_rest;
    rest.note = op.rest_note;
    try {
      IdentifiedModel at_rest =
          AtOperatingPoint(IdentifyParametricAtRest(method, Deviations(siso, rest), request), rest);
      const double rest_fit = FitFromEstimatedState(at_rest, siso);
      const double other = std::max(raw_fit, centred_fit);
      if (std::isfinite(rest_fit) && rest_fit >= other - 0.5) {
        at_rest.notes.insert(at_rest.notes.begin() + 1,
                             fmt::format("simulation fit {:.2f} % from an estimated initial "
                                         "state, against {:.2f} % around the means and {:.2f} % "
                                         "for the raw signals (operating point zero)",
                                         rest_fit, centred_fit, raw_fit));
        return at_rest;
      }
    } catch (const DataError&) {
    } catch (const InvalidArgument&) {
    }
  }
  if (std::isfinite(raw_fit) && !(centred_fit > raw_fit)) {
    raw.notes.insert(raw.notes.begin(),
                     fmt::format("operating point zero (the raw signals): simulation fit {:.2f} % "
                                 "from an estimated initial state, against {:.2f} % around the "
                                 "means u0 = {:.6g}, y0 = {:.6g}",
                                 raw_fit, centred_fit, op.u0, op.y0));
    return raw;
  }
  centred.notes.insert(
      centred.notes.begin() + 1,
      std::isfinite(raw_fit)
          ? fmt::format("simulation fit {:.2f} % from an estimated initial state, against {:.2f} "
                        "% for the raw signals (operating point zero)",
                        centred_fit, raw_fit)
          : std::string("the raw signals (operating point zero) gave no usable model"));
  return centred;
}

namespace {

IdentifiedModel IdentifyParametricAtRest(const std::string& method, const Dataset& d,
                                         const IdentifyRequest& request) {
  if (method == "arx") {
    ArxOptions o;
    o.na = request.na;
    o.nb = {request.nb};
    o.nk = {request.nk};
    const ArxResult r = EstimateArx(d, o);
    PNEUMID_CHECK(r.summary.IsSolutionUsable(), "ARX estimation failed: {}", r.summary.message);
    return ToIdentifiedModel(method, r.model, r.summary, d);
  }
  if (method == "iv4") {
    IvOptions o;
    o.na = request.na;
    o.nb = request.nb;
    o.nk = request.nk;
    const IvResult r = EstimateIv4(d, o);
    PNEUMID_CHECK(r.summary.IsSolutionUsable(), "IV4 estimation failed: {}", r.summary.message);
    return ToIdentifiedModel(method, r.model, r.summary, d);
  }
  if (method == "armax" || method == "oe" || method == "bj") {
    PemOrders o;
    o.na = request.na;
    o.nb = request.nb;
    o.nc = request.nc;
    o.nd = request.nd;
    o.nf = request.nf;
    o.nk = request.nk;
    const PemResult r = EstimatePolynomial(PolynomialStructureFromString(method), o, d);
    PNEUMID_CHECK(r.summary.IsSolutionUsable(), "{} estimation failed: {}", method,
                  r.summary.message);
    return ToIdentifiedModel(method, r.model, r.summary, d);
  }
  if (method == "n4sid") {
    SubspaceOptions o;
    o.order = request.na;
    o.feedthrough = request.feedthrough;
    o.weighting = request.n4sid_weight;
    const SubspaceResult r = EstimateSubspace(d, o);
    PNEUMID_CHECK(r.summary.IsSolutionUsable(), "subspace estimation failed: {}",
                  r.summary.message);
    IdentifiedModel m;
    m.method = method;
    m.structure = "SS";
    auto mat = [](const Eigen::MatrixXd& x) {
      std::vector<std::vector<double>> rows;
      for (Eigen::Index i = 0; i < x.rows(); ++i) {
        std::vector<double> row(x.cols());
        for (Eigen::Index k = 0; k < x.cols(); ++k) row[k] = x(i, k);
        rows.push_back(row);
      }
      return rows;
    };
    m.params = {{"A", mat(r.model.A())}, {"B", mat(r.model.B())}, {"C", mat(r.model.C())},
                {"D", mat(r.model.D())}, {"order", r.order},      {"Ts", r.model.Ts()}};
    std::vector<double> sv(r.singular_values.data(),
                           r.singular_values.data() + r.singular_values.size());
    m.params["singular_values"] = sv;
    if (request.na == 0)
      m.notes.push_back(fmt::format(
          "order {} chosen at the largest gap of the log singular values (--na 0; --na N fixes "
          "it): {:.3g}",
          r.order, fmt::join(sv.begin(), sv.begin() + std::min<std::size_t>(sv.size(), 8), ", ")));
    return FinishTransferFunctionModel(std::move(m), ToTransferFunction(r.model), r.summary, d);
  }
  if (method == "cra") {
    // Long enough for slow processes (MATLAB's default of 20 lags truncates them).
    CraOptions co;
    co.num_lags = static_cast<int>(std::min<Eigen::Index>(200, d.size() / 8));
    const CraResult r = Cra(d, co);
    IdentifiedModel m;
    m.method = method;
    m.structure = "FIR";
    m.params = ModelParamsFromJson(r.ToJson());
    std::vector<double> g(r.impulse.data(), r.impulse.data() + r.impulse.size());
    EstimationSummary s;
    s.termination = Termination::kConvergence;
    s.message = fmt::format("correlation analysis, {} lags, 99 % bound {:.4g}",
                            r.impulse.size() - 1, r.bound);
    return FinishTransferFunctionModel(std::move(m), TransferFunction::Discrete(g, {1.0}, r.Ts), s,
                                       d, false);
  }
  // spa: frequency response; the FIR model is the inverse DFT of the estimate.
  SpaOptions so;
  so.lag_window = static_cast<int>(std::min<Eigen::Index>(300, d.size() / 10));
  const FrequencyResponseEstimate r = Spa(d, so);
  IdentifiedModel m;
  m.method = method;
  m.structure = "FRD";
  m.params = ModelParamsFromJson(r.ToJson());
  const int K = static_cast<int>(r.response.size());
  // Where the windowed input spectrum estimate is not positive (a step input
  // has almost no power at high frequencies, and the Hann lag window's
  // spectral window has negative side lobes, so the estimate can dip below
  // zero there on long records) the frequency function is undefined (NaN in
  // the FRD). The FIR model takes the nearest defined value at those
  // frequencies instead of turning every tap into NaN.
  Eigen::VectorXcd G = r.response;
  int undefined = 0;
  for (int k = 0; k < K; ++k) undefined += std::isfinite(G[k].real()) ? 0 : 1;
  PNEUMID_CHECK(undefined < K, "spa: the input has no estimated power at any of the {} frequencies",
                K);
  for (int k = 1; k < K; ++k)
    if (!std::isfinite(G[k].real()) && std::isfinite(G[k - 1].real())) G[k] = G[k - 1];
  for (int k = K - 2; k >= 0; --k)
    if (!std::isfinite(G[k].real())) G[k] = G[k + 1];
  const int taps = 2 * K;
  std::vector<double> g(taps, 0.0);
  // G(e^{i w}) on w_k = k pi / K, k = 1..K; k = 0 taken equal to k = 1 (real part).
  for (int n = 0; n < taps; ++n) {
    double acc = G[0].real();
    for (int k = 1; k < K; ++k)
      acc += 2.0 * std::real(G[k - 1] * std::polar(1.0, M_PI * k * n / K));
    acc += std::real(G[K - 1] * std::polar(1.0, M_PI * n));
    g[n] = acc / taps;
  }
  EstimationSummary s;
  if (undefined > 0)
    s.warnings.push_back(fmt::format(
        "{} of {} frequencies have a non-positive input spectrum estimate (no excitation): the "
        "FIR model holds the nearest estimated value there",
        undefined, K));
  s.termination = Termination::kConvergence;
  s.message = fmt::format("Blackman-Tukey spectral analysis, Hann window, {} frequencies", K);
  return FinishTransferFunctionModel(
      std::move(m), TransferFunction::Discrete(g, {1.0}, d.SampleTime()), s, d, false);
}

}  // namespace

}  // namespace pneumid
