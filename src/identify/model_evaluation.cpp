#include "pneumid/identify/model_evaluation.hpp"

#include <algorithm>
#include <cmath>
#include <complex>
#include <limits>

#include <fmt/format.h>

#include "pneumid/common/check.hpp"
#include "pneumid/common/enum_names.hpp"
#include "pneumid/identify/identified_model_io.hpp"
#include "pneumid/identify/initial_state.hpp"
#include "pneumid/identify/nonlinear.hpp"
#include "pneumid/identify/parametric_model.hpp"
#include "pneumid/identify/residual_analysis.hpp"
#include "pneumid/lti/conversion.hpp"
#include "pneumid/lti/response.hpp"

namespace pneumid {

namespace {

const TransferFunction& SimulatedForm(const IdentifiedModel& m) {
  return m.discrete ? *m.discrete : m.tf;
}

std::string Complex(std::complex<double> z) {
  if (std::abs(z.imag()) < 1e-12 * std::max(1.0, std::abs(z.real())))
    return fmt::format("{:.4g}", z.real());
  return fmt::format("{:.4g}{:+.4g}i", z.real(), z.imag());
}

bool IsPolynomial(const IdentifiedModel& m) {
  return m.params.contains("a") && m.params.contains("b") && m.params.contains("Ts");
}

}  // namespace

namespace {

// The form SimulateModel runs on the data's grid: a discrete model with the
// data's sample time (after checking that the two agree), a continuous model
// as it is (simulated with a zero-order hold at that sample time).
TransferFunction FormOnDataGrid(const IdentifiedModel& model, const Dataset& data, int input) {
  PNEUMID_CHECK(input >= 0 && input < data.num_inputs(),
                "input column {} does not exist (the data have {} input(s))", input,
                data.num_inputs());
  const TransferFunction& g = SimulatedForm(model);
  if (!g.IsDiscrete()) return g;
  const double Ts = data.SampleTime();
  PNEUMID_CHECK(std::abs(g.Ts() - Ts) <= 1e-6 * Ts,
                "the model{} has sample time {} s, the data{} {} s",
                model.method.empty() ? "" : " '" + model.method + "'", g.Ts(),
                data.source().empty() ? "" : " of " + data.source(), Ts);
  return TransferFunction(g.num(), g.den(), Ts, g.delay());
}

}  // namespace

Eigen::VectorXd SimulateModel(const IdentifiedModel& model, const Dataset& data, int input) {
  if (IsNonlinearModel(model)) return SimulateNonlinear(model, data, input, 0);
  const TransferFunction g = FormOnDataGrid(model, data, input);
  const Eigen::VectorXd du = (data.u(input).array() - model.u0).matrix();
  return (Lsim(g, du, data.SampleTime()).array() + model.y0).matrix();
}

namespace {
inline constexpr EnumName<InitialCondition> kInitialConditionNames[] = {
    {InitialCondition::kZero, "zero"}, {InitialCondition::kEstimate, "estimate"}};
}  // namespace

std::string ToString(InitialCondition c) {
  return std::string(EnumToString(kInitialConditionNames, c));
}

InitialCondition InitialConditionFromString(const std::string& name) {
  return EnumFromString(kInitialConditionNames, name, "initial condition");
}

Eigen::VectorXd SimulateModel(const IdentifiedModel& model, const Dataset& data, int input,
                              int output, InitialCondition initial) {
  if (IsNonlinearModel(model)) {
    PNEUMID_CHECK(initial == InitialCondition::kZero,
                  "the initial-state estimate is for linear models; the {} model '{}' starts "
                  "at rest (initial condition zero)",
                  model.structure, model.method);
    return SimulateNonlinear(model, data, input, output);
  }
  if (initial == InitialCondition::kZero) return SimulateModel(model, data, input);
  PNEUMID_CHECK(output >= 0 && output < data.num_outputs(),
                "output column {} does not exist (the data have {} output(s))", output,
                data.num_outputs());
  const TransferFunction g = FormOnDataGrid(model, data, input);
  const StateSpace ss = ToStateSpace(g.IsDiscrete() ? g : C2D(g, data.SampleTime()));
  const Eigen::MatrixXd du = (data.u(input).array() - model.u0).matrix();
  const Eigen::MatrixXd dy = (data.y(output).array() - model.y0).matrix();
  const Eigen::VectorXd x0 = EstimateInitialState(ss, du, dy);
  return (SimulateFromState(ss, du, x0).col(0).array() + model.y0).matrix();
}

FitMetrics EvaluateModel(const IdentifiedModel& model, const Dataset& data, int input, int output,
                         Eigen::Index score_from) {
  if (IsNonlinearModel(model))
    return ScoreSimulation(data, output, SimulateNonlinear(model, data, input, output), score_from);
  return ScoreSimulation(data, output, SimulateModel(model, data, input), score_from);
}

FitMetrics ScoreSimulation(const Dataset& data, int output, const Eigen::VectorXd& yhat,
                           Eigen::Index score_from) {
  PNEUMID_CHECK(output >= 0 && output < data.num_outputs(),
                "output column {} does not exist (the data have {} output(s))", output,
                data.num_outputs());
  PNEUMID_CHECK(yhat.size() == data.size(), "the simulated output has {} samples, the data {}",
                yhat.size(), data.size());
  PNEUMID_CHECK(score_from >= 0 && score_from + 2 <= data.size(),
                "the scored samples must start in [0, {}], got {}", data.size() - 2, score_from);
  const Eigen::Index n = data.size() - score_from;
  if (!yhat.tail(n).allFinite()) {
    const double inf = std::numeric_limits<double>::infinity();
    return FitMetrics{-inf, inf, inf, inf};
  }
  return ComputeFitMetrics(data.time().tail(n), data.y(output).tail(n), yhat.tail(n));
}

void ScoreModel(const Dataset& data, int input, int output, IdentifiedModel* model) {
  PNEUMID_CHECK(model != nullptr, "ScoreModel: model must not be null");
  const FitMetrics f = EvaluateModel(*model, data, input, output);
  model->fit_percent = f.fit_percent;
  model->iae = f.iae;
  if (!std::isfinite(f.fit_percent))
    model->notes.push_back("the simulated response is not finite (unstable model?)");
}

bool ModelQualityOptions::IsValid(std::string* error) const {
  auto fail = [error](std::string m) {
    if (error) *error = std::move(m);
    return false;
  };
  if (!(nyquist_distance >= 0.0 && nyquist_distance < 1.0))
    return fail(fmt::format("ModelQualityOptions::nyquist_distance must be in [0, 1), got {}",
                            nyquist_distance));
  if (!(confidence > 0.0 && confidence < 1.0))
    return fail(
        fmt::format("ModelQualityOptions::confidence must be in (0, 1), got {}", confidence));
  if (max_lag < 1)
    return fail(fmt::format("ModelQualityOptions::max_lag must be >= 1, got {}", max_lag));
  return true;
}

std::vector<ModelFlagNote> AssessModel(const IdentifiedModel& model, const Dataset& data, int input,
                                       int output, const ModelQualityOptions& options) {
  std::string why;
  PNEUMID_CHECK(options.IsValid(&why), "{}", why);
  std::vector<ModelFlagNote> flags;
  const TransferFunction& g = SimulatedForm(model);
  const Eigen::VectorXcd poles = g.Poles();
  const double tol = 1e-9;
  for (Eigen::Index i = 0; i < poles.size(); ++i) {
    const std::complex<double> p = poles[i];
    const bool unstable = g.IsDiscrete() ? std::abs(p) > 1.0 + tol : p.real() > tol;
    if (unstable) {
      flags.push_back(
          {ModelFlag::kUnstable,
           fmt::format("pole at {} = {}{}", g.IsDiscrete() ? "z" : "s", Complex(p),
                       g.IsDiscrete() ? fmt::format(" (|z| = {:.4g})", std::abs(p)) : "")});
      break;
    }
  }
  if (g.IsDiscrete() && options.nyquist_distance > 0.0) {
    for (Eigen::Index i = 0; i < poles.size(); ++i) {
      const double d = std::abs(poles[i] + 1.0);
      if (d <= options.nyquist_distance) {
        flags.push_back({ModelFlag::kNyquistPole,
                         fmt::format("pole at z = {}, {:.3g} from z = -1 (a ripple at the "
                                     "Nyquist frequency {:g} Hz, not plant dynamics)",
                                     Complex(poles[i]), d, 0.5 / g.Ts())});
        break;
      }
    }
  }
  if (model.termination == Termination::kNoConvergence ||
      model.termination == Termination::kFailure) {
    flags.push_back({ModelFlag::kNoConvergence,
                     fmt::format("the estimator ended with '{}'", ToString(model.termination))});
  }
  // A model with a finite fit has a finite simulation: simulate (again) only
  // where the residual test needs it.
  const bool noise_model = IsPolynomial(model) && model.structure != "OE";
  Eigen::VectorXd yhat;
  if (!noise_model || !std::isfinite(model.fit_percent)) {
    yhat = IsNonlinearModel(model) ? SimulateNonlinear(model, data, input, output)
                                   : SimulateModel(model, data, input);
    if (!yhat.allFinite()) {
      flags.push_back({ModelFlag::kNotFinite, "the simulated output is not finite"});
      return flags;
    }
  }
  ResidualAnalysisOptions ro;
  ro.max_lag = std::min<int>(options.max_lag, static_cast<int>(data.size() / 2) - 1);
  ro.confidence = options.confidence;
  if (ro.max_lag < 1) return flags;
  try {
    Eigen::VectorXd e;
    if (noise_model) {
      const PolynomialModel poly =
          PolynomialModel::FromParamsJson(ToJson(model.params), model.structure);
      e = PredictionErrors(poly, data.y(output), data.u(input));
    } else {
      e = data.y(output) - yhat;
    }
    const ResidualAnalysis r = AnalyzeWhiteness(e, ro);
    if (!r.whiteness_passed) {
      flags.push_back(
          {ModelFlag::kResidualsNotWhite,
           fmt::format("{} errors not white: Q = {:.4g} > {:.4g} ({:g} % level), {} of {} lags "
                       "outside the band",
                       noise_model ? "one-step prediction" : "simulation", r.whiteness_statistic,
                       r.whiteness_threshold, 100.0 * options.confidence, r.auto_outside,
                       r.autocorr.size() - 1)});
    }
  } catch (const InvalidArgument&) {
    // constant residuals or input: the test is undefined, nothing to flag
  }
  return flags;
}

int RankGroup(const IdentifiedModel& model) {
  if (model.flags.empty()) return 0;
  const bool only_residuals =
      std::all_of(model.flags.begin(), model.flags.end(),
                  [](const ModelFlagNote& f) { return f.flag == ModelFlag::kResidualsNotWhite; });
  return only_residuals ? 1 : 2;
}

double RankScore(const IdentifiedModel& model) {
  const double s = std::isfinite(model.validation_fit_percent) ? model.validation_fit_percent
                                                               : model.fit_percent;
  return std::isnan(s) ? -std::numeric_limits<double>::infinity() : s;
}

void RankModels(std::vector<IdentifiedModel>* models) {
  PNEUMID_CHECK(models != nullptr, "RankModels: models must not be null");
  std::stable_sort(models->begin(), models->end(),
                   [](const IdentifiedModel& a, const IdentifiedModel& b) {
                     const int ga = RankGroup(a), gb = RankGroup(b);
                     if (ga != gb) return ga < gb;
                     return RankScore(a) > RankScore(b);
                   });
}

}  // namespace pneumid
