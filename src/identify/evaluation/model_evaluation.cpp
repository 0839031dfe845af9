#include "pneumid/identify/evaluation/model_evaluation.hpp"

#include <algorithm>
#include <cmath>
#include <complex>
#include <limits>

#include <fmt/format.h>
#include <Eigen/Dense>

#include "pneumid/common/check.hpp"
#include "pneumid/common/enum_names.hpp"
#include "pneumid/identify/evaluation/initial_state.hpp"
#include "pneumid/identify/evaluation/residual_analysis.hpp"
#include "pneumid/identify/nonlinear/nonlinear.hpp"
#include "pneumid/identify/parametric/parametric_model.hpp"
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
  data.RequireUniform();  // a gap is named as such, not as another sample time
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

namespace {

// A block-oriented model (Hammerstein, Wiener, Hammerstein-Wiener) simulated
// from the initial state of its linear part that best explains output column
// `output`: with v = f(u) (or u) and x(t) = x_v(t) + Phi(t) x0 the linear
// part's output (x_v its zero-state response, Phi(t) = C A^t), the
// Hammerstein output x is linear in x0 (least squares, EstimateInitialState);
// through an output map g, y = g(x) is not, and x0 minimises
// sum_t (y(t) - g(x(t)))^2 by Gauss-Newton with step halving, from the state
// at rest at v(0).
Eigen::VectorXd SimulateBlockFromEstimatedState(const IdentifiedModel& model, const Dataset& data,
                                                int input, int output) {
  PNEUMID_CHECK(output >= 0 && output < data.num_outputs(),
                "output column {} does not exist (the data have {} output(s))", output,
                data.num_outputs());
  PNEUMID_CHECK(model.discrete.has_value(),
                "the block-oriented model{} has no discrete linear part",
                model.method.empty() ? "" : " '" + model.method + "'");
  const StateSpace ss = ToStateSpace(FormOnDataGrid(model, data, input));
  const Eigen::VectorXd u = data.u(input), y = data.y(output);
  const Eigen::MatrixXd v = model.input_map ? model.input_map->Evaluate(u) : u;
  if (!model.output_map) {
    const Eigen::VectorXd x0 = EstimateInitialState(ss, v, y);
    return SimulateFromState(ss, v, x0).col(0);
  }
  const StaticMap& out = *model.output_map;
  const Eigen::Index nx = ss.A().rows(), n = u.size();
  const Eigen::VectorXd xv = SimulateFromState(ss, v, Eigen::VectorXd::Zero(nx)).col(0);
  Eigen::MatrixXd phi(n, nx);
  for (Eigen::Index i = 0; i < nx; ++i)
    phi.col(i) = SimulateFromState(ss, Eigen::MatrixXd::Zero(n, 1), Eigen::VectorXd::Unit(nx, i));
  Eigen::VectorXd x0 = Eigen::VectorXd::Zero(nx);
  const Eigen::MatrixXd I = Eigen::MatrixXd::Identity(nx, nx);
  const Eigen::VectorXd rest = (I - ss.A()).colPivHouseholderQr().solve(ss.B() * v(0, 0));
  if (rest.allFinite()) x0 = rest;
  auto residual = [&](const Eigen::VectorXd& x) {
    return (y - out.Evaluate((xv + phi * x).eval())).eval();
  };
  Eigen::VectorXd r = residual(x0);
  double cost = r.squaredNorm();
  for (int it = 0; it < 50 && std::isfinite(cost); ++it) {
    const Eigen::VectorXd x = xv + phi * x0;
    Eigen::MatrixXd J(n, nx);
    for (Eigen::Index t = 0; t < n; ++t) J.row(t) = out.Slope(x[t]) * phi.row(t);
    const Eigen::VectorXd step = J.colPivHouseholderQr().solve(r);
    if (!step.allFinite()) break;
    bool improved = false;
    for (double a = 1.0; a > 1e-4; a *= 0.5) {
      const Eigen::VectorXd trial = x0 + a * step;
      const Eigen::VectorXd rt = residual(trial);
      if (rt.squaredNorm() < cost) {
        x0 = trial;
        r = rt;
        improved = cost - rt.squaredNorm() > 1e-12 * cost;
        cost = rt.squaredNorm();
        break;
      }
    }
    if (!improved) break;
  }
  return out.Evaluate((xv + phi * x0).eval());
}

}  // namespace

namespace {

// The simulation of the two whose squared error against output column
// `output` is lower (a non-finite one never wins): the estimated start is
// never worse than the start at rest, which is one of the states it chooses
// from. The estimate can miss it: a Hammerstein model with a dead time of 3
// samples scored 95.34 % from its estimate and 95.74 % from rest (the delayed
// inputs are not among the estimated states), a Hammerstein-Wiener's
// Gauss-Newton stalled where the output map is clamped flat (90.44 against
// 94.39 %).
Eigen::VectorXd BetterOf(Eigen::VectorXd estimated, Eigen::VectorXd rest, const Dataset& data,
                         int output) {
  const Eigen::VectorXd y = data.y(output);
  const auto sse = [&](const Eigen::VectorXd& yhat) {
    const double s = yhat.size() == y.size() ? (y - yhat).squaredNorm() : std::numeric_limits<double>::infinity();
    return std::isfinite(s) ? s : std::numeric_limits<double>::infinity();
  };
  return sse(rest) < sse(estimated) ? rest : estimated;
}

}  // namespace

Eigen::VectorXd SimulateModel(const IdentifiedModel& model, const Dataset& data, int input,
                              int output, InitialCondition initial) {
  if (IsNonlinearModel(model)) {
    // A NARX simulation starts from the measured outputs in either case.
    if (initial == InitialCondition::kZero || model.narx)
      return SimulateNonlinear(model, data, input, output);
    return BetterOf(SimulateBlockFromEstimatedState(model, data, input, output),
                    SimulateNonlinear(model, data, input, output), data, output);
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
  return BetterOf((SimulateFromState(ss, du, x0).col(0).array() + model.y0).matrix(),
                  SimulateModel(model, data, input), data, output);
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
  if (!(parsimony_tolerance >= 0.0 && parsimony_tolerance < 1.0))
    return fail(fmt::format("ModelQualityOptions::parsimony_tolerance must be in [0, 1), got {}",
                            parsimony_tolerance));
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
  // The whiteness test runs on the simulation errors for every class (the
  // criterion the models are ranked by); a model with a noise model also
  // reports its one-step prediction errors' test in the note.
  const bool noise_model = IsPolynomial(model) && model.structure != "OE";
  const Eigen::VectorXd yhat = IsNonlinearModel(model)
                                   ? SimulateNonlinear(model, data, input, output)
                                   : SimulateModel(model, data, input);
  if (!yhat.allFinite()) {
    flags.push_back({ModelFlag::kNotFinite, "the simulated output is not finite"});
    return flags;
  }
  ResidualAnalysisOptions ro;
  ro.max_lag = std::min<int>(options.max_lag, static_cast<int>(data.size() / 2) - 1);
  ro.confidence = options.confidence;
  if (ro.max_lag < 1) return flags;
  try {
    const ResidualAnalysis r = AnalyzeWhiteness((data.y(output) - yhat).eval(), ro);
    if (!r.whiteness_passed) {
      std::string one_step;
      if (noise_model) {
        try {
          const PolynomialModel poly = PolynomialModelFromParams(model.params, model.structure);
          // The polynomial acts on the deviations from the operating point.
          const Eigen::VectorXd dy = (data.y(output).array() - model.y0).matrix();
          const Eigen::VectorXd du = (data.u(input).array() - model.u0).matrix();
          const ResidualAnalysis p = AnalyzeWhiteness(PredictionErrors(poly, dy, du), ro);
          one_step =
              fmt::format("; one-step prediction errors {} (Q = {:.4g})",
                          p.whiteness_passed ? "white" : "not white either", p.whiteness_statistic);
        } catch (const InvalidArgument&) {
        }
      }
      flags.push_back(
          {ModelFlag::kResidualsNotWhite,
           fmt::format("simulation errors not white: Q = {:.4g} > {:.4g} ({:g} % level), {} of {} "
                       "lags outside the band{}",
                       r.whiteness_statistic, r.whiteness_threshold, 100.0 * options.confidence,
                       r.auto_outside, r.autocorr.size() - 1, one_step)});
    }
  } catch (const InvalidArgument&) {
    // constant residuals or input: the test is undefined, nothing to flag
  }
  return flags;
}

int RankGroup(const IdentifiedModel& model) {
  int group = 0;
  for (const ModelFlagNote& f : model.flags) {
    if (f.flag == ModelFlag::kNotFinite || f.flag == ModelFlag::kUnstable) group = 2;
    if (f.flag == ModelFlag::kNyquistPole) group = std::max(group, 1);
  }
  return group;
}

double RankScore(const IdentifiedModel& model) {
  const double s = std::isfinite(model.determined_fit_percent)   ? model.determined_fit_percent
                   : std::isfinite(model.validation_fit_percent) ? model.validation_fit_percent
                                                                 : model.fit_percent;
  return std::isnan(s) ? -std::numeric_limits<double>::infinity() : s;
}

std::string RankReason(const IdentifiedModel& model) {
  const bool held_out = std::isfinite(model.validation_fit_percent);
  std::string why =
      held_out ? fmt::format("held-out simulation fit {:.2f} %", model.validation_fit_percent)
               : fmt::format("estimation fit {:.2f} % (no held-out data)", model.fit_percent);
  if (held_out && std::isfinite(model.determined_fit_percent))
    why += fmt::format(
        ", ranked by its {:.2f} % on the held-out samples outside the input intervals the "
        "estimation data leave undetermined",
        model.determined_fit_percent);
  std::vector<std::string> soft, hard;
  for (const ModelFlagNote& f : model.flags)
    (f.flag == ModelFlag::kNoConvergence || f.flag == ModelFlag::kResidualsNotWhite ? soft : hard)
        .push_back(ToString(f.flag));
  if (!hard.empty())
    why += fmt::format("; ranked after the models without {} ({})", fmt::join(hard, ", "),
                       RankGroup(model) == 2 ? "its simulation cannot be trusted"
                                             : "a ripple at the Nyquist frequency");
  if (!soft.empty())
    why += fmt::format("; flagged {}, ranked by its fit all the same", fmt::join(soft, ", "));
  // A structure search scores its candidates on the held-out data that rank
  // the model (IdentifyModels): the fit includes that choice.
  if (held_out && !model.structure_chosen_on.empty())
    why += "; its structure was chosen on the same held-out data";
  if (!model.rank_note.empty()) why += "; " + model.rank_note;
  return why;
}

namespace {

// Coefficients of a transfer function that an estimator chose: the
// denominator after its leading coefficient, the numerator from its first
// nonzero coefficient (leading zeros are the delay), and the dead time of a
// continuous model (a discrete one delays by whole samples, its structure).
int TransferFunctionParameters(const TransferFunction& g) {
  const Eigen::VectorXd& num = g.num();
  Eigen::Index first = 0;
  while (first < num.size() && num[first] == 0.0) ++first;
  const auto den = static_cast<int>(std::max<Eigen::Index>(g.den().size() - 1, 0));
  return den + static_cast<int>(num.size() - first) + (g.IsContinuous() && g.delay() > 0.0 ? 1 : 0);
}

}  // namespace

int ParameterCount(const IdentifiedModel& model) {
  int n = 0;
  if (model.narx) {
    n += static_cast<int>(model.narx->theta.size());
  } else {
    n += TransferFunctionParameters(model.discrete ? *model.discrete : model.tf);
  }
  if (model.input_map) n += static_cast<int>(model.input_map->size());
  if (model.output_map) n += static_cast<int>(model.output_map->size());
  return n;
}

void RankModels(std::vector<IdentifiedModel>* models, const ModelQualityOptions& options) {
  PNEUMID_CHECK(models != nullptr, "RankModels: models must not be null");
  std::string why;
  PNEUMID_CHECK(options.IsValid(&why), "{}", why);
  std::stable_sort(models->begin(), models->end(),
                   [](const IdentifiedModel& a, const IdentifiedModel& b) {
                     const int ga = RankGroup(a), gb = RankGroup(b);
                     if (ga != gb) return ga < gb;
                     return RankScore(a) > RankScore(b);
                   });
  for (IdentifiedModel& m : *models) m.rank_note.clear();
  if (options.parsimony_tolerance <= 0.0) return;
  // Each place in turn goes to the simplest model the evidence cannot tell
  // from the best remaining one (same group, error within the tolerance).
  for (std::size_t i = 0; i < models->size(); ++i) {
    const IdentifiedModel& lead = (*models)[i];
    const double score = RankScore(lead);
    if (!std::isfinite(score)) continue;
    const double limit = (100.0 - score) * (1.0 + options.parsimony_tolerance);
    std::size_t pick = i;
    int fewest = ParameterCount(lead);
    for (std::size_t j = i + 1; j < models->size(); ++j) {
      const IdentifiedModel& m = (*models)[j];
      if (RankGroup(m) != RankGroup(lead)) break;
      if (!(100.0 - RankScore(m) <= limit)) break;  // sorted: the rest score lower
      const int count = ParameterCount(m);
      if (count < fewest) {
        fewest = count;
        pick = j;
      }
    }
    if (pick == i) continue;
    std::vector<std::string> better;
    for (std::size_t j = i; j < pick; ++j)
      better.push_back(fmt::format("{} ({:.2f} %, {} parameters)", (*models)[j].method,
                                   RankScore((*models)[j]), ParameterCount((*models)[j])));
    std::rotate(models->begin() + static_cast<std::ptrdiff_t>(i),
                models->begin() + static_cast<std::ptrdiff_t>(pick),
                models->begin() + static_cast<std::ptrdiff_t>(pick) + 1);
    (*models)[i].rank_note = fmt::format(
        "preferred to {} for fewer parameters ({}): simulation errors within {:g} % of each "
        "other",
        fmt::join(better, ", "), fewest, 100.0 * options.parsimony_tolerance);
  }
}

}  // namespace pneumid
