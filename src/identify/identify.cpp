#include "pneumid/identify/identify.hpp"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <exception>
#include <mutex>
#include <optional>
#include <thread>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "pneumid/common/check.hpp"
#include "pneumid/common/strings.hpp"
#include "pneumid/identify/evaluation/fit_metrics.hpp"
#include "pneumid/identify/evaluation/validation.hpp"
#include "pneumid/identify/nonlinear/nonlinear.hpp"
#include "pneumid/identify/parametric/parametric.hpp"
#include "pneumid/lti/conversion.hpp"
#include "pneumid/identify/step/step_analysis.hpp"

namespace pneumid {

bool IdentifyOptions::IsValid(std::string* error) const {
  if (!step.IsValid(error) || !quality.IsValid(error) || !nonlinear.IsValid(error)) return false;
  if (!(split == 0.0 || (split > 0.0 && split < 1.0))) {
    if (error)
      *error = fmt::format("IdentifyOptions::split must be 0 (none) or in (0, 1), got {}", split);
    return false;
  }
  if (num_threads < 0) {
    if (error)
      *error = fmt::format("IdentifyOptions::num_threads must be >= 0, got {}", num_threads);
    return false;
  }
  return true;
}

const std::vector<std::string>& IdentifyMethodNames() {
  static const std::vector<std::string> names = [] {
    std::vector<std::string> all = StepMethodNames();
    for (const std::string& m : ParametricMethodNames()) all.push_back(m);
    return all;
  }();
  return names;
}

bool IsIdentifyMethod(const std::string& name) {
  const auto& names = IdentifyMethodNames();
  return std::find(names.begin(), names.end(), name) != names.end() || IsNonlinearMethod(name);
}

namespace {

std::string ValidMethodList() {
  return fmt::format("{}, {}", fmt::join(IdentifyMethodNames(), ", "),
                     fmt::join(NonlinearMethodNames(), ", "));
}

}  // namespace

std::vector<std::string> ParseMethodList(const std::string& list) {
  std::vector<std::string> out;
  auto add = [&out](const std::string& m) {
    if (std::find(out.begin(), out.end(), m) == out.end()) out.push_back(m);
  };
  for (const std::string& item : Split(list, ',')) {
    if (item.empty()) continue;
    if (item == "all") {
      for (const std::string& m : IdentifyMethodNames()) add(m);
      continue;
    }
    PNEUMID_CHECK(IsIdentifyMethod(item), "unknown method '{}' (valid: {}, or all)", item,
                  ValidMethodList());
    add(item);
  }
  PNEUMID_CHECK(!out.empty(), "the method list needs at least one method name, got '{}'", list);
  return out;
}

std::vector<std::string> AutoMethods(const Dataset& data, const IdentifyRequest& request,
                                     const std::vector<std::string>& for_a_step,
                                     std::string* warning) {
  if (warning != nullptr) warning->clear();
  try {
    AnalyzeStep(data, request.input, request.output);
    return for_a_step;
  } catch (const DataError& e) {
    std::vector<std::string> general = ParseMethodList(kGeneralInputMethods);
    if (warning != nullptr) {
      // (Its advice to use a fit-* method is what is done here.)
      const std::string what = e.what();
      *warning = fmt::format(
          "the step-test methods ({}) need a step test and this record is not one ({}): "
          "identified with the methods for general inputs, {} (choose others with --method)",
          fmt::join(for_a_step, ", "), what.substr(0, what.find("; use a fit-* method")),
          fmt::join(general, ", "));
    }
    return general;
  }
}

IdentifiedModel Identify(const std::string& method, const Dataset& data,
                         const IdentifyRequest& request, const IdentifyOptions& options) {
  data.RequireNumericScale();
  if (IsStepMethod(method)) return IdentifyStepMethod(method, data, request, options.step);
  if (IsParametricMethod(method)) return IdentifyParametric(method, data, request);
  if (IsNonlinearMethod(method)) return IdentifyNonlinear(method, data, request, options.nonlinear);
  PNEUMID_CHECK(false, "unknown method '{}' (valid: {})", method, ValidMethodList());
  return {};
}

std::string IdentificationSummary::BriefReport() const {
  std::string best;
  if (!models.empty()) {
    const IdentifiedModel& m = models.front();
    best = fmt::format(", best {} ({:.2f} % {}fit{})", m.method, RankScore(m),
                       std::isfinite(m.validation_fit_percent) ? "validation " : "",
                       m.flags.empty() ? "" : ", flagged");
  }
  return fmt::format("identify {}: {} model(s), {} failed{}", ToString(termination), models.size(),
                     failures.size(), best);
}

namespace {

bool SameChannels(const std::vector<Channel>& a, const std::vector<Channel>& b) {
  if (a.size() != b.size()) return false;
  for (std::size_t i = 0; i < a.size(); ++i)
    if (a[i].name != b[i].name) return false;
  return true;
}

std::string ChannelNames(const std::vector<Channel>& c) {
  std::vector<std::string> names;
  for (const Channel& x : c) names.push_back(x.name);
  return fmt::format("[{}]", fmt::join(names, ", "));
}

// The held-out fit from the other start than the ranking's (`ranked`), as a
// note when the two differ by more than one point of fit: a model whose fit
// rests on an estimated initial state (its slow modes absorbing an error of
// the whole record), or one that cannot start at rest where the record does,
// shows it. `validate` starts at rest unless told otherwise.
std::optional<std::string> OtherStartNote(const IdentifiedModel& m, const Dataset& scored,
                                          const IdentifyRequest& request, InitialCondition ranked,
                                          Eigen::Index score_from) {
  const InitialCondition other =
      ranked == InitialCondition::kEstimate ? InitialCondition::kZero : InitialCondition::kEstimate;
  double fit = 0.0;
  try {
    fit =
        ScoreSimulation(scored, request.output,
                        SimulateModel(m, scored, request.input, request.output, other), score_from)
            .fit_percent;
  } catch (const std::exception&) {
    return std::nullopt;  // no such start for this model (e.g. no state-space form)
  }
  const double at = m.validation_fit_percent;
  if (!std::isfinite(at) || (std::isfinite(fit) && std::abs(fit - at) <= 1.0)) return std::nullopt;
  const auto name = [](InitialCondition c) {
    return c == InitialCondition::kZero ? std::string("rest (--initial-state zero)")
                                        : std::string(
                                              "the estimated initial state "
                                              "(--initial-state estimate)");
  };
  return fmt::format(
      "held-out fit {:.2f} % from {}, the start it is ranked by; {} from {}", at, name(ranked),
      std::isfinite(fit) ? fmt::format("{:.2f} %", fit) : std::string("not finite"), name(other));
}

// Samples a model with this linear part takes to settle within 2 % after its
// input changes: its delay plus the decay of its slowest stable pole (0 when
// it has none).
Eigen::Index SettlingSamples(const TransferFunction& g) {
  double slowest = 0.0;
  const Eigen::VectorXcd poles = g.Poles();
  for (Eigen::Index i = 0; i < poles.size(); ++i)
    if (std::abs(poles[i]) < 1.0) slowest = std::max(slowest, std::abs(poles[i]));
  const double decay = slowest > 0.0 ? std::ceil(std::log(0.02) / std::log(slowest)) : 0.0;
  // A discrete numerator in ascending powers of z^-1: its leading zeros
  // delay, and so does the transfer function's own delay.
  Eigen::Index delay = 0;
  const Eigen::VectorXd& num = g.num();
  while (delay < num.size() && num[delay] == 0.0) ++delay;
  if (g.IsDiscrete()) delay += g.DelaySamples();
  return delay + static_cast<Eigen::Index>(decay);
}

// Samples the model `m` takes to settle after its input changes
// (SettlingSamples): of its discrete linear part, else of its continuous
// transfer function sampled at Ts with a zero-order hold; -1 for a model
// without a linear part (NARX) or a continuous one with no stable pole.
Eigen::Index ModelSettlingSamples(const IdentifiedModel& m, double Ts) {
  if (m.discrete) return SettlingSamples(*m.discrete);
  if (m.tf.IsDiscrete() || m.tf.den().size() < 2 || !(Ts > 0.0)) return -1;
  if (!(m.tf.Poles().real().array() < 0.0).any()) return -1;
  return SettlingSamples(C2D(m.tf, Ts));
}

// A held-out part shorter than half the time the best-ranked model takes to
// settle (about two of its slowest time constants) scores mostly the start
// each model is simulated from (its estimated initial state), not how it
// follows the input, and the ranking and the nonlinear structure search rest
// on it: e.g. the cascaded tanks with --split 0.99 (10 held-out samples,
// 40 s, against a Hammerstein model's 1060 s) ranked a model held out by
// -2854 % with nothing said. The first ranked model with a linear part sets
// the time scale.
void WarnHeldOutShorterThanSettling(const IdentificationSummary& s, double Ts,
                                    const std::string& what, bool validation,
                                    std::vector<std::string>* warnings) {
  for (const IdentifiedModel& m : s.models) {
    const Eigen::Index settle = ModelSettlingSamples(m, Ts);
    if (settle < 0) continue;
    if (2 * s.validation_samples < settle)
      warnings->push_back(fmt::format(
          "{} holds {} samples ({:.4g} s), fewer than half of what the best-ranked model '{}' "
          "takes to settle after an input change ({} samples, {:.4g} s): the held-out fits (and "
          "the structure search on them) score mostly the start each model is simulated from, "
          "not how it follows the input; {}",
          what, s.validation_samples, static_cast<double>(s.validation_samples) * Ts, m.method,
          settle, static_cast<double>(settle) * Ts,
          validation ? "give a longer validation record" : "choose a smaller --split"));
    return;
  }
}

// Ranking on what the estimation data determine (IdentifiedModel::
// determined_fit_percent): when the held-out samples [from, N) of `scored`
// visit input intervals that the models' input maps leave undetermined (a
// jump or bend between two estimation levels that no sample placed), every
// model's fit there measures how its interpolation happens to fall, not what
// the data said: a polynomial NARX can outscore a Hammerstein model there
// and then run away on the next record. The models are then scored also on
// the other held-out samples, the samples within the slowest block model's
// settling time after each visit excluded; `sims` holds each model's
// simulation of `scored`. Too few samples left (under a fifth of the
// held-out part or 50): a warning instead.
void ScoreOnDeterminedSamples(std::vector<IdentifiedModel>* models,
                              const std::vector<Eigen::VectorXd>& sims, const Dataset& scored,
                              Eigen::Index from, const IdentifyRequest& request,
                              std::vector<std::string>* warnings) {
  std::vector<std::pair<double, double>> gaps;
  Eigen::Index settle = 0;
  for (const IdentifiedModel& m : *models) {
    for (const auto& g : m.input_map_undetermined)
      if (std::find(gaps.begin(), gaps.end(), g) == gaps.end()) gaps.push_back(g);
    if (m.input_map && m.discrete) settle = std::max(settle, SettlingSamples(*m.discrete));
  }
  if (gaps.empty()) return;
  std::sort(gaps.begin(), gaps.end());
  const Eigen::VectorXd u = scored.u(request.input);
  const Eigen::VectorXd y = scored.y(request.output);
  const Eigen::Index n = scored.size(), held = n - from;
  settle = std::min(settle, held / 4);
  const auto inside = [&](double x) {
    return std::any_of(gaps.begin(), gaps.end(),
                       [x](const auto& g) { return VisitsMapGap(x, g.first, g.second); });
  };
  std::vector<bool> keep(static_cast<std::size_t>(n), true);
  Eigen::Index last_visit = -1, visits = 0;
  for (Eigen::Index t = 0; t < n; ++t) {
    if (inside(u[t])) last_visit = t;
    if (t >= from && last_visit >= 0 && t - last_visit <= settle) {
      keep[static_cast<std::size_t>(t)] = false;
      if (last_visit == t) ++visits;
    }
  }
  if (visits == 0) return;
  Eigen::Index kept = 0;
  for (Eigen::Index t = from; t < n; ++t) kept += keep[static_cast<std::size_t>(t)] ? 1 : 0;
  std::vector<std::string> names;
  for (const auto& [lo, hi] : gaps) names.push_back(fmt::format("({:g}, {:g})", lo, hi));
  const std::string where = fmt::format(
      "the held-out data visit input intervals the estimation data leave undetermined ({}) in "
      "{} of their {} samples",
      fmt::join(names, ", "), visits, held);
  if (kept < std::max<Eigen::Index>(50, held / 5)) {
    warnings->push_back(fmt::format(
        "{}: too few samples ({}) lie outside them and the {} samples after each visit for a "
        "ranking on what the estimation data determine; the models are ranked by their fit "
        "there all the same, which measures how each interpolates, not what the data said",
        where, kept, settle));
    return;
  }
  // The measured output and each model's simulation on the kept samples.
  Eigen::VectorXd y_kept(kept), sim_kept(kept);
  const auto gather = [&](const Eigen::VectorXd& x, Eigen::VectorXd* out) {
    Eigen::Index i = 0;
    for (Eigen::Index t = from; t < n; ++t)
      if (keep[static_cast<std::size_t>(t)]) (*out)[i++] = x[t];
  };
  gather(y, &y_kept);
  if (!(y_kept.maxCoeff() > y_kept.minCoeff())) return;  // constant there: no fit defined
  for (std::size_t i = 0; i < models->size(); ++i) {
    const Eigen::VectorXd& yhat = sims[i];
    if (yhat.size() != n || !yhat.allFinite()) continue;
    gather(yhat, &sim_kept);
    (*models)[i].determined_fit_percent = NrmseFit(y_kept, sim_kept);
  }
  warnings->push_back(fmt::format(
      "{}: the models are ranked by their fit on the other {} held-out samples (the {} samples "
      "after each visit excluded too), where the estimation data say what a model should do; "
      "each model's held-out fit over all samples is reported beside it",
      where, kept, settle));
}

}  // namespace

IdentificationSummary IdentifyModels(const std::vector<std::string>& methods, const Dataset& data,
                                     const IdentifyRequest& request, const IdentifyOptions& options,
                                     const Dataset* validation, const IdentifyProgress& progress) {
  std::string why;
  PNEUMID_CHECK(!methods.empty(), "IdentifyModels needs at least one method");
  for (const std::string& m : methods)
    PNEUMID_CHECK(IsIdentifyMethod(m), "unknown method '{}' (valid: {})", m, ValidMethodList());
  PNEUMID_CHECK(request.IsValid(&why), "invalid identify request: {}", why);
  PNEUMID_CHECK(options.IsValid(&why), "{}", why);
  PNEUMID_CHECK(request.input < data.num_inputs() && request.output < data.num_outputs(),
                "input column {} / output column {} do not exist (the data{} have {} input(s) "
                "and {} output(s))",
                request.input, request.output, data.source().empty() ? "" : " of " + data.source(),
                data.num_inputs(), data.num_outputs());
  PNEUMID_CHECK(validation == nullptr || options.split == 0.0,
                "give either held-out validation data or a split fraction ({}), not both",
                options.split);
  if (validation != nullptr) {
    const std::string vsrc =
        validation->source().empty() ? "the validation data" : validation->source();
    PNEUMID_CHECK(SameChannels(validation->input_channels(), data.input_channels()) &&
                      SameChannels(validation->output_channels(), data.output_channels()),
                  "{} have the channels inputs {} outputs {}, the estimation data inputs {} "
                  "outputs {}",
                  vsrc, ChannelNames(validation->input_channels()),
                  ChannelNames(validation->output_channels()), ChannelNames(data.input_channels()),
                  ChannelNames(data.output_channels()));
    // Each record uniform first: a gap in the estimation data shifts its
    // mean interval, and the comparison below blamed the validation data.
    data.RequireUniform();
    validation->RequireUniform();
    PNEUMID_CHECK(
        std::abs(validation->SampleTime() - data.SampleTime()) <= 1e-6 * data.SampleTime(),
        "{} is sampled every {:.6g} s, the estimation data every {:.6g} s", vsrc,
        validation->SampleTime(), data.SampleTime());
  }

  // The estimation part, and the held-out samples [score_from, N) of `scored`.
  std::optional<Dataset> head, rest;
  const Dataset* scored = validation;
  Eigen::Index score_from = 0;
  if (options.split > 0.0) {
    auto parts = SplitDataset(data, options.split);
    head.emplace(std::move(parts.first));
    rest.emplace(std::move(parts.second));
    rest->set_source(fmt::format("the last {:.0f} % of {}", 100.0 * (1.0 - options.split),
                                 data.source().empty() ? "the data" : data.source()));
    scored = &data;
    score_from = head->size();
  }
  // The held-out record of the nonlinear methods' structure search: the
  // validation data, or the split's rest (the same part that scores them).
  const Dataset* held_out = validation != nullptr ? validation : (rest ? &*rest : nullptr);
  const Dataset& estimation = head ? *head : data;
  if (scored != nullptr) {
    const Eigen::VectorXd y = scored->y(request.output).tail(scored->size() - score_from);
    PNEUMID_CHECK(y.size() >= 2 && y.maxCoeff() > y.minCoeff(),
                  "the held-out {} holds a constant output ({} samples at y = {:g}): no fit can be "
                  "scored on it; {}",
                  validation
                      ? "data"
                      : fmt::format("last {:.0f} % of the data", 100.0 * (1.0 - options.split)),
                  y.size(), y.size() ? y[0] : 0.0,
                  validation ? "give a validation record that excites the plant"
                             : "choose another --split or give --validation data");
  }
  {
    // A constant estimation output leaves nothing to fit: every method failed
    // on it in its own words (a map "needs finite input samples", a fit "of
    // y = 0" after scaling), and some returned a non-finite model as best.
    const Eigen::VectorXd y = estimation.y(request.output);
    PNEUMID_CHECK(y.size() < 2 || y.maxCoeff() > y.minCoeff(),
                  "{} holds a constant output ({} samples at y = {:g}): nothing to identify; "
                  "record the output while the input moves the plant",
                  head ? fmt::format("the first {:.0f} % of {}", 100.0 * options.split,
                                     data.source().empty() ? "the data" : data.source())
                       : (data.source().empty() ? std::string("the estimation data")
                                                : data.source()),
                  y.size(), y[0]);
  }
  std::vector<std::string> warnings;
  {
    // A constant estimation input leaves the input's effect undetermined: a
    // linear model fits the output's transient from its initial state (ARX's
    // regressors are rank deficient), and every nonlinear method refuses it.
    const Eigen::VectorXd u = estimation.u(request.input);
    if (u.size() > 0 && !(u.maxCoeff() > u.minCoeff()))
      warnings.push_back(fmt::format(
          "the estimation data{} hold a constant input (u = {:g} over {} samples): no model "
          "can tell the input's effect from them (its gain is undetermined; a fit measures the "
          "output's transient from its initial state); record a step, a staircase or a PRBS",
          head ? fmt::format(" (the first {:.0f} %)", 100.0 * options.split) : "", u[0], u.size()));
  }
  if (held_out != nullptr) {
    // A held-out part on one input level scores each model's steady state
    // there, not its dynamics: a ranking (and a structure search) on it says
    // little. Models are still scored; the nonlinear structure search does not
    // choose on it (IdentifyNonlinear falls back on the request's orders).
    const Eigen::VectorXd u = held_out->u(request.input);
    if (u.size() > 0 && !(u.maxCoeff() > u.minCoeff()))
      warnings.push_back(fmt::format(
          "{} holds a constant input (u = {:g} over {} samples): its fit scores each model's "
          "steady state at one level, not its dynamics, and the ranking rests on it; {}",
          held_out->source().empty() ? "the held-out data" : held_out->source(), u[0], u.size(),
          validation ? "give a validation record whose input moves"
                     : "choose another --split or give --validation data"));
  }

  const std::size_t n = methods.size();
  std::vector<std::optional<IdentifiedModel>> results(n);
  std::vector<Eigen::VectorXd> simulations(n);  // of `scored`, when held out
  std::vector<std::string> errors(n);
  std::mutex progress_mutex;
  std::size_t started = 0;
  std::atomic<std::size_t> next{0};
  auto work = [&] {
    for (std::size_t i = next++; i < n; i = next++) {
      if (progress) {
        std::lock_guard<std::mutex> lock(progress_mutex);
        progress(started++, n, methods[i]);
      }
      try {
        // A structure search of the nonlinear methods chooses on the held-out
        // part when there is one (--validation or --split); without one it
        // splits the estimation data itself (NonlinearOptions::structure_split).
        IdentifiedModel m;
        if (IsNonlinearMethod(methods[i]) && held_out != nullptr) {
          estimation.RequireNumericScale();
          m = IdentifyNonlinear(methods[i], estimation, request, options.nonlinear, held_out);
        } else {
          m = Identify(methods[i], estimation, request, options);
        }
        m.flags = AssessModel(m, estimation, request.input, request.output, options.quality);
        if (scored != nullptr) {
          const Eigen::VectorXd yhat =
              SimulateModel(m, *scored, request.input, request.output, options.validation_initial);
          const FitMetrics f = ScoreSimulation(*scored, request.output, yhat, score_from);
          m.validation_fit_percent = f.fit_percent;
          simulations[i] = yhat;
          // Where the held-out part leaves what the estimation data support
          // (validate's warnings), the held-out fit says so beside it.
          std::optional<Dataset> slice;
          if (score_from > 0) slice = SliceDataset(*scored, score_from, scored->size());
          const Dataset& part = slice ? *slice : *scored;
          const Eigen::VectorXd part_yhat = yhat.tail(part.size());
          for (const std::string& w : ExtrapolationWarnings(m, part, request.input, &part_yhat))
            m.notes.push_back("held-out part: " + w);
          if (std::optional<std::string> note =
                  OtherStartNote(m, *scored, request, options.validation_initial, score_from))
            m.notes.push_back(std::move(*note));
        }
        results[i] = std::move(m);
      } catch (const std::exception& e) {
        errors[i] = e.what();
      }
    }
  };
  unsigned threads = options.num_threads > 0 ? static_cast<unsigned>(options.num_threads)
                                             : std::max(1u, std::thread::hardware_concurrency());
  threads = static_cast<unsigned>(std::min<std::size_t>(threads, n));
  if (threads <= 1) {
    work();
  } else {
    std::vector<std::thread> pool;
    for (unsigned t = 0; t < threads; ++t) pool.emplace_back(work);
    for (std::thread& t : pool) t.join();
  }
  if (progress) progress(n, n, "");

  IdentificationSummary s;
  s.warnings = std::move(warnings);
  s.estimation_samples = estimation.size();
  s.validation_samples = scored == nullptr ? 0 : scored->size() - score_from;
  std::vector<Eigen::VectorXd> sims;
  for (std::size_t i = 0; i < n; ++i) {
    if (results[i]) {
      s.models.push_back(std::move(*results[i]));
      sims.push_back(std::move(simulations[i]));
    } else {
      s.failures.emplace_back(methods[i], errors[i]);
    }
  }
  if (scored != nullptr)
    ScoreOnDeterminedSamples(&s.models, sims, *scored, score_from, request, &s.warnings);
  RankModels(&s.models, options.quality);
  if (scored != nullptr)
    WarnHeldOutShorterThanSettling(
        s, data.SampleTime(),
        held_out != nullptr && !held_out->source().empty() ? held_out->source()
                                                           : std::string("the held-out data"),
        validation != nullptr, &s.warnings);
  if (s.models.empty()) {
    s.termination = Termination::kFailure;
    s.message = fmt::format("no method produced a model ({} failed)", n);
  } else if (!s.failures.empty()) {
    s.termination = Termination::kPartial;
    s.message = fmt::format("{} of {} methods failed", s.failures.size(), n);
  } else {
    s.termination = Termination::kSuccess;
    s.message = fmt::format("all {} methods produced a model", n);
  }
  return s;
}

}  // namespace pneumid
