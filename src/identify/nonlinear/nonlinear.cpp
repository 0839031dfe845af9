#include "pneumid/identify/nonlinear/nonlinear.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>

#include <fmt/format.h>
#include <Eigen/Dense>

#include "pneumid/common/check.hpp"
#include "pneumid/identify/evaluation/fit_metrics.hpp"
#include "pneumid/identify/evaluation/model_evaluation.hpp"
#include "pneumid/identify/evaluation/validation.hpp"
#include "pneumid/identify/nonlinear/narx_simulation_fit.hpp"
#include "pneumid/identify/nonlinear/static_map_fit.hpp"
#include "pneumid/lti/conversion.hpp"
#include "pneumid/lti/response.hpp"

namespace pneumid {

namespace {

std::string Values(const std::vector<double>& v) {
  std::vector<std::string> s;
  for (double x : v) s.push_back(fmt::format("{:.4g}", x));
  return fmt::format("[{}]", fmt::join(s, " "));
}

// "input map: monotone increasing, ...; u = [...]; y = [...]".
std::string MapNote(const char* which, const StaticMap& f) {
  const auto [lo, hi] = std::minmax_element(f.y().begin(), f.y().end());
  // Flat within 0.5 % of the output range counts as dead zone / saturation.
  return fmt::format("{}: {}; u = {}; y = {}", which, f.Describe(0.005 * (*hi - *lo)),
                     Values(f.u()), Values(f.y()));
}

void SetLinearPart(const PolynomialModel& g, IdentifiedModel* m) {
  m->discrete = g.ToTransferFunction(0);
  try {
    m->tf = D2C(*m->discrete, DiscretizationMethod::kZoh);
  } catch (const InvalidArgument& e) {
    m->tf = *m->discrete;
    m->notes.push_back(std::string("no continuous (zoh d2c) form of the linear part: ") + e.what());
  }
  const auto a = g.a, b = g.b[0];
  m->params = {{"A", std::vector<double>(a.data(), a.data() + a.size())},
               {"B", std::vector<double>(b.data(), b.data() + b.size())},
               {"nk", g.nk[0]},
               {"Ts", g.Ts}};
}

BlockModelOptions BlockOptions(const IdentifyRequest& request, const NonlinearOptions& options) {
  BlockModelOptions o = options.block;
  o.na = request.na;
  o.nb = std::max(1, request.nb);
  o.nk = request.nk;
  return o;
}

void AddSummary(const EstimationSummary& s, IdentifiedModel* m) {
  m->termination = s.termination;
  m->notes.push_back(
      fmt::format("{} ({} iterations, mean squared simulation error {:.4g}, "
                  "from {:.4g})",
                  s.message, s.iterations, s.loss, s.initial_loss));
  for (const std::string& w : s.warnings) m->notes.push_back(w);
}

}  // namespace

bool NonlinearOptions::IsValid(std::string* error) const {
  BlockModelOptions b = block;
  b.na = 0;  // orders come from the request
  b.nb = 1;
  b.nk = 0;
  NarxOptions n = narx;
  n.ny = 0;
  n.nu = 1;
  n.nk = 0;
  if (!(structure_split > 0.0 && structure_split < 1.0)) {
    if (error)
      *error = fmt::format("NonlinearOptions::structure_split must be in (0, 1), got {}",
                           structure_split);
    return false;
  }
  if (max_narx_lag < 1 || max_narx_terms < 1) {
    if (error)
      *error = fmt::format(
          "NonlinearOptions: max_narx_lag and max_narx_terms must be >= 1, got {} and {}",
          max_narx_lag, max_narx_terms);
    return false;
  }
  if (max_delay < 0 || max_delay > 1000) {
    if (error)
      *error = fmt::format("NonlinearOptions::max_delay must be in 0..1000, got {}", max_delay);
    return false;
  }
  return static_map.IsValid(error) && b.IsValid(error) && n.IsValid(error);
}

const std::vector<std::string>& NonlinearMethodNames() {
  static const std::vector<std::string> names = {"static-map", "hammerstein", "wiener",
                                                 "hw",         "narx",        "affine-narx"};
  return names;
}

bool IsNonlinearMethod(const std::string& name) {
  const auto& n = NonlinearMethodNames();
  return std::find(n.begin(), n.end(), name) != n.end();
}

bool IsNonlinearModel(const IdentifiedModel& model) {
  return model.input_map.has_value() || model.output_map.has_value() || model.narx.has_value();
}

namespace {

bool IsBlockMethod(const std::string& method) {
  return method == "hammerstein" || method == "wiener" || method == "hw";
}

// Focus simulation in the NARX structure search: refines the prefix model
// *m (least-squares theta) by the simulation error on the estimation part,
// also from *previous (the previous prefix's refined theta, the new terms at
// 0), and keeps the lower simulation error; *previous becomes the result.
void RefineNarxPrefix(NarxModel* m, const Eigen::VectorXd& u, const Eigen::VectorXd& y,
                      const NarxOptions& o, std::vector<double>* previous) {
  NarxSimulationFitOptions so;
  so.max_iterations = o.max_iterations;
  NarxSimulationFitResult best = FitNarxSimulation(m, u, y, so);
  if (!previous->empty() && previous->size() < m->theta.size()) {
    NarxModel warm = *m;
    std::fill(warm.theta.begin(), warm.theta.end(), 0.0);
    std::copy(previous->begin(), previous->end(), warm.theta.begin());
    const NarxSimulationFitResult r = FitNarxSimulation(&warm, u, y, so);
    if (best.diverges || (!r.diverges && r.summary.loss < best.summary.loss)) *m = std::move(warm);
  }
  *previous = m->theta;
}

// FROLS on (u, y) with options `no` (up to no.max_terms terms), then every
// prefix of 1, 2, .., 10 terms and every 5th after, refitted by least squares
// (focus simulation: refined by the simulation error, RefineNarxPrefix), is
// passed to fn(k, model); fn returns false to stop.
template <typename Fn>
void ForEachNarxPrefix(const Eigen::VectorXd& ue, const Eigen::VectorXd& ye, double Ts,
                       const NarxOptions& no, Fn&& fn) {
  NarxOptions ls = no;
  ls.focus = NarxFocus::kPrediction;  // the terms; each prefix is refined below
  const NarxModel full = EstimateNarx(ue, ye, Ts, ls).model;
  const Eigen::Index n0 = full.FirstSample(), rows = ye.size() - n0;
  const auto K = static_cast<Eigen::Index>(full.terms.size());
  Eigen::MatrixXd S(rows, K);
  for (Eigen::Index i = 0; i < K; ++i)
    for (Eigen::Index r = 0; r < rows; ++r)
      S(r, i) = full.TermValue(full.terms[static_cast<std::size_t>(i)], r + n0, ye, ue);
  const Eigen::VectorXd target = ye.tail(rows) / full.y_scale;
  std::vector<double> previous;  // focus simulation: the previous prefix's theta
  for (Eigen::Index k = std::min<Eigen::Index>(1, K);; k = std::min(K, k + (k < 10 ? 1 : 5))) {
    NarxModel pm = full;
    pm.terms.resize(static_cast<std::size_t>(k));
    pm.err.resize(static_cast<std::size_t>(k));
    const Eigen::VectorXd theta = S.leftCols(k).colPivHouseholderQr().solve(target);
    pm.theta.assign(theta.data(), theta.data() + k);
    if (no.focus == NarxFocus::kSimulation) RefineNarxPrefix(&pm, ue, ye, no, &previous);
    if (!fn(static_cast<int>(k), pm) || k == K) break;
  }
}

// The shift of the first outputs with which a NARX candidate's held-out run
// must forget its start (NarxModel::ForgetsItsStart): 25 % of the span of
// the estimation output `ye`.
double StartShift(const Eigen::VectorXd& ye) { return 0.25 * (ye.maxCoeff() - ye.minCoeff()); }

// The NARX part of ChooseBlockStructure (see nonlinear.hpp): `tail` is the
// held-out record, simulated from its own first outputs.
StructureChoice ChooseNarxStructure(const Dataset& estimation, const Dataset& tail,
                                    const IdentifyRequest& request, const NonlinearOptions& options,
                                    StructureChoice out) {
  const Eigen::VectorXd ue = estimation.u(request.input), ye = estimation.y(request.output);
  const Eigen::VectorXd uv = tail.u(request.input), yv = tail.y(request.output);
  const double Ts = estimation.SampleTime();
  const double inf = std::numeric_limits<double>::infinity();
  const double shift = StartShift(ye);
  for (int nk = 0; nk <= std::min(1, options.max_delay); ++nk) {
    for (int lag = 1; lag <= options.max_narx_lag; ++lag) {
      NarxOptions no = options.narx;
      no.ny = lag;
      no.nu = lag;
      no.nk = nk;
      no.max_terms = options.max_narx_terms;
      try {
        ForEachNarxPrefix(ue, ye, Ts, no, [&](int k, const NarxModel& pm) {
          const Eigen::Index n0 = pm.FirstSample();
          PNEUMID_CHECK(yv.size() > n0 + 2,
                        "the held-out part has {} samples, {} start a simulation", yv.size(), n0);
          const Eigen::VectorXd sim = pm.Simulate(uv, yv);
          const Eigen::Index nv = yv.size() - n0;
          double fit = -inf;
          if (sim.allFinite()) fit = NrmseFit(yv.tail(nv).eval(), sim.tail(nv).eval());
          if (!std::isfinite(fit)) fit = -inf;
          const bool forgets = std::isfinite(fit) && pm.ForgetsItsStart(uv, yv, shift, &sim);
          out.candidates.push_back({lag, lag, nk, k, fit, -inf, "", forgets});
          return true;
        });
      } catch (const std::exception& e) {
        out.candidates.push_back({lag, lag, nk, 0, -inf, -inf, e.what()});
      }
    }
  }
  // Only candidates that forget their start, unless none does.
  const bool any_forgets = std::any_of(out.candidates.begin(), out.candidates.end(),
                                       [](const StructureCandidate& c) { return c.forgets_start; });
  double best = -inf;
  for (const StructureCandidate& c : out.candidates)
    if (c.forgets_start || !any_forgets) best = std::max(best, c.fit_percent);
  PNEUMID_CHECK(std::isfinite(best), "narx: no structure could be estimated ({})",
                out.candidates.front().error);
  const StructureCandidate* pick = nullptr;
  for (const StructureCandidate& c : out.candidates) {
    if (!(c.fit_percent >= best - 0.1) || (any_forgets && !c.forgets_start)) continue;
    if (pick == nullptr || c.terms < pick->terms || (c.terms == pick->terms && c.na < pick->na))
      pick = &c;
  }
  out.na = pick->na;
  out.nb = pick->nb;
  out.nk = pick->nk;
  out.terms = pick->terms;
  out.fit_percent = pick->fit_percent;
  return out;
}

// The narx IdentifiedModel parts of an estimate: structure, params, notes, termination.
void SetNarxModel(const NarxResult& r, IdentifiedModel* m) {
  const NarxModel& n = r.model;
  m->structure = "NARX";
  m->narx = n;
  m->discrete = TransferFunction::Discrete({1.0}, {1.0}, n.Ts);
  m->tf = TransferFunction();
  m->params = {{"ny", n.ny},
               {"nu", n.nu},
               {"nk", n.nk},
               {"degree", n.degree},
               {"terms", static_cast<int>(n.terms.size())},
               {"Ts", n.Ts}};
  std::vector<std::string> terms;
  for (std::size_t i = 0; i < n.terms.size(); ++i)
    terms.push_back(fmt::format("{} (ERR {:.4g})", n.TermName(n.terms[i]), n.err[i]));
  m->notes.push_back(fmt::format("selected terms: {}", fmt::join(terms, ", ")));
  m->notes.push_back(n.Equation());
  m->notes.push_back(fmt::format("{}; one-step fit {:.2f} %, simulation fit {:.2f} %",
                                 r.summary.message, r.one_step_fit_percent,
                                 r.simulation_fit_percent));
  for (const std::string& w : r.summary.warnings) m->notes.push_back(w);
  m->termination = r.summary.termination;
}

// narx with focus simulation after the structure search: the candidate the
// search scored (its terms and refined theta, estimated on the estimation
// part) refined by the simulation error on all of `data`.
IdentifiedModel NarxFromChoice(const Dataset& data, const IdentifyRequest& request,
                               const NonlinearOptions& options, const Dataset* held_out,
                               const StructureChoice& c) {
  const Dataset estimation = held_out ? data : SplitDataset(data, options.structure_split).first;
  NarxOptions no = options.narx;
  no.ny = c.na;
  no.nu = c.nb;
  no.nk = c.nk;
  no.max_terms = options.max_narx_terms;
  std::optional<NarxModel> chosen;
  ForEachNarxPrefix(estimation.u(request.input), estimation.y(request.output),
                    estimation.SampleTime(), no, [&](int k, const NarxModel& pm) {
                      if (k == c.terms) chosen = pm;
                      return k < c.terms;
                    });
  PNEUMID_CHECK(chosen.has_value(), "narx: the chosen candidate ({} terms) was not rebuilt",
                c.terms);
  const Eigen::VectorXd u = data.u(request.input), y = data.y(request.output);
  NarxResult r;
  r.model = *chosen;
  NarxSimulationFitOptions so;
  so.max_iterations = no.max_iterations;
  const NarxSimulationFitResult f = FitNarxSimulation(&r.model, u, y, so);
  r.summary = f.summary;
  r.summary.message = fmt::format(
      "the chosen candidate ({} terms, FROLS on the estimation part) refined on all the data: "
      "{} ({} iterations, mean squared simulation error {:.4g}, from {:.4g})",
      c.terms, f.summary.message, f.summary.iterations, f.summary.loss, f.summary.initial_loss);
  // The refinement must not undo what chose the candidate: a free run on the
  // held-out part that forgets its start, as the search found for it
  // (ChooseNarxStructure; `chosen` is the candidate it scored on that part).
  const auto scored =
      std::find_if(c.candidates.begin(), c.candidates.end(), [&](const StructureCandidate& k) {
        return k.na == c.na && k.nk == c.nk && k.terms == c.terms;
      });
  const Dataset tail = held_out ? *held_out : SliceDataset(data, estimation.size(), data.size());
  if (scored != c.candidates.end() && scored->forgets_start &&
      !r.model.ForgetsItsStart(tail.u(request.input), tail.y(request.output),
                               StartShift(estimation.y(request.output)))) {
    r.model = *chosen;
    r.summary.termination = Termination::kConvergence;  // the candidate's own refinement
    r.summary.message = fmt::format(
        "the chosen candidate ({} terms) as estimated on the estimation part: refined on all the "
        "data ({}), its free run on the held-out part no longer forgets its start",
        c.terms, f.summary.message);
  }
  const Eigen::Index n0 = r.model.FirstSample(), rows = y.size() - n0;
  r.one_step_fit_percent = NrmseFit(y.tail(rows).eval(), r.model.Predict(y, u).tail(rows).eval());
  r.simulation_fit_percent = NarxSimulationFit(r.model, u, y, rows, &r.summary.warnings);
  IdentifiedModel m;
  m.method = "narx";
  SetNarxModel(r, &m);
  ScoreModel(data, request.input, request.output, &m);
  return m;
}

}  // namespace

std::string StructureChoice::Describe() const {
  if (terms > 0) {
    std::vector<std::string> tried;
    std::size_t kept = 0;
    for (const StructureCandidate& c : candidates) {
      if (!std::isfinite(c.fit_percent)) continue;
      kept += c.forgets_start ? 1 : 0;
      tried.push_back(fmt::format("{} {} {}: {:.2f}{}", c.na, c.nk, c.terms, c.fit_percent,
                                  c.forgets_start ? "" : "*"));
    }
    const std::string starred =
        kept == tried.size() ? ""
        : kept == 0
            ? "; * none forgets its start (all considered)"
            : "; * does not forget its start (a run from outputs shifted by 25 % of their span "
              "does not rejoin it): not chosen";
    return fmt::format(
        "ny = nu = {}, nk = {}, {} terms (held-out simulation fit {:.2f} % on {}); tried (lags nk "
        "terms: held-out fit %): {}{}",
        na, nk, terms, fit_percent, held_out, fmt::join(tried, ", "), starred);
  }
  std::vector<std::string> tried;
  for (const StructureCandidate& c : candidates)
    tried.push_back(std::isfinite(c.fit_percent)
                        ? fmt::format("{} {} {}: {:.2f} / {:.2f}", c.na, c.nb, c.nk,
                                      c.record_fit_percent, c.fit_percent)
                        : fmt::format("{} {} {}: failed", c.na, c.nb, c.nk));
  return fmt::format(
      "na = {}, nb = {}, nk = {} (held-out simulation fit {:.2f} % on {}); tried (na nb nk: "
      "estimation / held-out fit %): {}",
      na, nb, nk, fit_percent, held_out, fmt::join(tried, ", "));
}

StructureChoice ChooseBlockStructure(const std::string& method, const Dataset& data,
                                     const IdentifyRequest& request,
                                     const NonlinearOptions& options, const Dataset* held_out) {
  PNEUMID_CHECK(IsBlockMethod(method) || method == "narx",
                "the structure search is for hammerstein, wiener, hw and narx, got '{}'", method);
  std::string why;
  PNEUMID_CHECK(options.IsValid(&why), "{}", why);
  data.RequireUniform();
  StructureChoice out;
  std::optional<Dataset> head;
  const Dataset* scored = held_out;
  Eigen::Index score_from = 0;
  if (held_out == nullptr) {
    auto parts = SplitDataset(data, options.structure_split);
    PNEUMID_CHECK(parts.first.size() >= 20 && parts.second.size() >= 10,
                  "{}: {} samples are too few to choose the structure on held-out data (a split "
                  "at {:g} leaves {} to estimate and {} to validate); give the orders "
                  "(--na, --nb, --nk) or more data",
                  method, data.size(), options.structure_split, parts.first.size(),
                  parts.second.size());
    head.emplace(std::move(parts.first));
    scored = &data;
    score_from = head->size();
    out.held_out =
        fmt::format("the last {:.0f} % of the data", 100.0 * (1.0 - options.structure_split));
  } else {
    out.held_out = held_out->source().empty() ? "the validation data" : held_out->source();
  }
  // Candidates that differ in their dynamics only tell apart on an input
  // that moves; on one level every stable candidate scores its steady state.
  const Eigen::VectorXd u_held =
      held_out ? held_out->u(request.input) : data.u(request.input).tail(data.size() - score_from);
  PNEUMID_CHECK(u_held.size() > 0 && u_held.maxCoeff() > u_held.minCoeff(),
                "{}: the held-out part, {}, holds a constant input (u = {:g} over {} samples: "
                "no excitation to choose the structure on); give the orders (--na, --nb, --nk), "
                "another --split or --validation data",
                method, out.held_out, u_held.size() ? u_held[0] : 0.0, u_held.size());
  const Dataset& estimation = head ? *head : data;
  if (method == "narx")
    return ChooseNarxStructure(estimation,
                               held_out ? *held_out : SliceDataset(data, score_from, data.size()),
                               request, options, std::move(out));
  NonlinearOptions fixed = options;
  fixed.choose_structure = false;
  auto try_one = [&](int na, int nb, int nk) {
    StructureCandidate c{na,
                         nb,
                         nk,
                         0,
                         -std::numeric_limits<double>::infinity(),
                         -std::numeric_limits<double>::infinity(),
                         ""};
    try {
      IdentifyRequest r = request;
      r.na = na;
      r.nb = nb;
      r.nk = nk;
      const IdentifiedModel m = IdentifyNonlinear(method, estimation, r, fixed);
      const Eigen::VectorXd yhat =
          SimulateModel(m, *scored, request.input, request.output, InitialCondition::kEstimate);
      const double fit = ScoreSimulation(*scored, request.output, yhat, score_from).fit_percent;
      if (std::isfinite(fit)) c.fit_percent = fit;
      if (std::isfinite(m.fit_percent)) c.record_fit_percent = m.fit_percent;
    } catch (const std::exception& e) {
      c.error = e.what();
    }
    out.candidates.push_back(c);
    return c.record_fit_percent;
  };
  // 1. The delay with first-order dynamics: candidates of equal size, so the
  //    fit on the estimation part decides (a held-out part is dominated by
  //    the map between the levels it adds, not by the delay).
  int best_nk = 0;
  double best = -std::numeric_limits<double>::infinity();
  for (int nk = 0; nk <= options.max_delay; ++nk) {
    const double f = try_one(1, 1, nk);
    if (f > best) {
      best = f;
      best_nk = nk;
    }
  }
  // 2. The orders with that delay.
  for (int na = 1; na <= 3; ++na)
    for (int nb = 1; nb <= 3; ++nb)
      if (na > 1 || nb > 1) try_one(na, nb, best_nk);
  // The most parsimonious within 0.1 point of the best held-out fit among the
  // candidates with a delay in `delays` (fewest coefficients, then fewest
  // poles); null when none has a finite fit.
  const auto choose = [&](const std::vector<int>& delays) -> const StructureCandidate* {
    const auto counts = [&](const StructureCandidate& c) {
      return std::find(delays.begin(), delays.end(), c.nk) != delays.end();
    };
    double top = -std::numeric_limits<double>::infinity();
    for (const StructureCandidate& c : out.candidates)
      if (counts(c)) top = std::max(top, c.fit_percent);
    if (!std::isfinite(top)) return nullptr;
    const StructureCandidate* pick = nullptr;
    for (const StructureCandidate& c : out.candidates) {
      if (!counts(c) || !(c.fit_percent >= top - 0.1)) continue;
      if (pick == nullptr || c.na + c.nb < pick->na + pick->nb ||
          (c.na + c.nb == pick->na + pick->nb && c.na < pick->na))
        pick = &c;
    }
    return pick;
  };
  const StructureCandidate* first = choose({best_nk});
  PNEUMID_CHECK(first != nullptr, "{}: no structure could be estimated ({})", method,
                out.candidates.front().error);
  // 3. A higher order explains part of the delay a first-order model needs
  //    (poles 0.9 and 0.8 behind one sample of delay look like one pole
  //    behind four): with the orders chosen, the shorter delays too, by the
  //    fit on the estimation part as in 1 (candidates of equal size; the
  //    longest delay within 0.02 point of the best, since leading
  //    coefficients near zero fit as well as a longer delay), then the
  //    orders again with that delay.
  std::vector<int> delays{best_nk};
  if (first->na + first->nb > 2 && best_nk > 0) {
    const int na = first->na, nb = first->nb;
    std::vector<std::pair<int, double>> by_delay{{best_nk, first->record_fit_percent}};
    for (int nk = 0; nk < best_nk; ++nk) by_delay.emplace_back(nk, try_one(na, nb, nk));
    double top = -std::numeric_limits<double>::infinity();
    for (const auto& [nk, f] : by_delay) top = std::max(top, f);
    int nk2 = -1;
    for (const auto& [nk, f] : by_delay)
      if (f >= top - 0.02) nk2 = std::max(nk2, nk);
    if (nk2 >= 0 && nk2 != best_nk) {
      for (int a = 1; a <= 3; ++a)
        for (int b = 1; b <= 3; ++b)
          if (a != na || b != nb) try_one(a, b, nk2);
      delays = {nk2};
    }
  }
  const StructureCandidate* pick = choose(delays);
  out.na = pick->na;
  out.nb = pick->nb;
  out.nk = pick->nk;
  out.fit_percent = pick->fit_percent;
  return out;
}

IdentifiedModel IdentifyNonlinear(const std::string& method, const Dataset& data,
                                  const IdentifyRequest& request, const NonlinearOptions& options,
                                  const Dataset* held_out) {
  if (options.choose_structure && (IsBlockMethod(method) || method == "narx")) {
    StructureChoice c;
    try {
      c = ChooseBlockStructure(method, data, request, options, held_out);
    } catch (const InvalidArgument& e) {
      // No held-out part to choose on (too short, no excitation): the
      // request's orders, and a note that says why.
      NonlinearOptions o = options;
      o.choose_structure = false;
      IdentifiedModel m = IdentifyNonlinear(method, data, request, o);
      m.notes.insert(m.notes.begin(),
                     fmt::format("warning: structure not chosen on held-out data ({}); the default "
                                 "orders na = {}, nb = {}, nk = {} are used",
                                 e.what(), request.na, request.nb, request.nk));
      return m;
    }
    IdentifyRequest r = request;
    r.na = c.na;
    r.nb = c.nb;
    r.nk = c.nk;
    NonlinearOptions o = options;
    o.choose_structure = false;
    if (c.terms > 0) o.narx.max_terms = c.terms;
    IdentifiedModel m = method == "narx" && options.narx.focus == NarxFocus::kSimulation
                            ? NarxFromChoice(data, request, options, held_out, c)
                            : IdentifyNonlinear(method, data, r, o);
    if (!std::isfinite(m.fit_percent) && held_out == nullptr) {
      // The refit on all the data does not simulate: keep the model the
      // search scored, estimated on the first part, scored on all the data.
      IdentifiedModel part =
          IdentifyNonlinear(method, SplitDataset(data, options.structure_split).first, r, o);
      ScoreModel(data, request.input, request.output, &part);
      if (std::isfinite(part.fit_percent)) {
        part.notes.insert(part.notes.begin(),
                          fmt::format("the refit on all the data does not simulate (not "
                                      "finite): the model estimated on the first {:.0f} % is kept",
                                      100.0 * options.structure_split));
        m = std::move(part);
      }
    }
    m.notes.insert(m.notes.begin(), "structure chosen on held-out data: " + c.Describe());
    if (held_out != nullptr) m.structure_chosen_on = c.held_out;
    return m;
  }
  std::string why;
  PNEUMID_CHECK(IsNonlinearMethod(method), "unknown nonlinear method '{}' (valid: {})", method,
                fmt::join(NonlinearMethodNames(), ", "));
  PNEUMID_CHECK(request.IsValid(&why), "invalid identify request: {}", why);
  PNEUMID_CHECK(options.IsValid(&why), "{}", why);
  PNEUMID_CHECK(request.input >= 0 && request.input < data.num_inputs() && request.output >= 0 &&
                    request.output < data.num_outputs(),
                "input column {} / output column {} do not exist (the data have {} input(s) and "
                "{} output(s))",
                request.input, request.output, data.num_inputs(), data.num_outputs());
  data.RequireUniform();
  const Eigen::VectorXd u = data.u(request.input), y = data.y(request.output);
  const double Ts = data.SampleTime();
  IdentifiedModel m;
  m.method = method;
  if (method == "static-map") {
    const StaticMapFitResult r = FitStaticMap(u, y, Ts, options.static_map);
    m.structure = "static map";
    m.input_map = r.map;
    m.discrete = TransferFunction::Discrete({1.0}, {1.0}, Ts);
    m.tf = TransferFunction();
    m.params = {{"knots", static_cast<int>(r.map.size())},
                {"segments", r.summary.segments_used},
                {"Ts", Ts}};
    m.termination = r.summary.termination;
    m.notes.push_back(MapNote("map", r.map));
    m.notes.push_back(r.summary.BriefReport());
  } else if (method == "hammerstein" || method == "wiener") {
    const BlockModelOptions o = BlockOptions(request, options);
    const bool hammerstein = method == "hammerstein";
    const BlockModelResult r =
        hammerstein ? EstimateHammerstein(u, y, Ts, o) : EstimateWiener(u, y, Ts, o);
    m.structure = hammerstein ? "Hammerstein" : "Wiener";
    (hammerstein ? m.input_map : m.output_map) = r.map;
    SetLinearPart(r.linear, &m);
    m.notes.push_back(MapNote(hammerstein ? "input map f(u)" : "output map f(x)", r.map));
    AddSummary(r.summary, &m);
  } else if (method == "hw") {
    const BlockModelResult r = EstimateHammersteinWiener(u, y, Ts, BlockOptions(request, options));
    m.structure = "Hammerstein-Wiener";
    m.input_map = r.map;
    m.output_map = r.output_map;
    SetLinearPart(r.linear, &m);
    m.notes.push_back(MapNote("input map f(u)", r.map));
    m.notes.push_back(MapNote("output map g(x)", *r.output_map));
    AddSummary(r.summary, &m);
  } else if (method == "affine-narx") {
    AffineNarxOptions o;
    o.degree = options.narx.degree;
    o.nk = request.nk;
    o.knots = options.block.knots;
    o.num_knots = options.block.num_knots;
    const AffineNarxResult r = EstimateAffineNarx(u, y, Ts, o);
    m.structure = "input-affine NARX";
    m.narx = r.narx;
    m.input_map = r.map;
    m.discrete = TransferFunction::Discrete({1.0}, {1.0}, Ts);
    m.tf = TransferFunction();
    m.params = {
        {"degree", o.degree}, {"nk", o.nk}, {"knots", static_cast<int>(r.map.size())}, {"Ts", Ts}};
    m.notes.push_back(MapNote("input map f(u)", r.map));
    m.notes.push_back(r.narx.Equation() + " (u: the mapped input f(u))");
    m.notes.push_back(fmt::format("{}; one-step fit {:.2f} %, simulation fit {:.2f} %",
                                  r.summary.message, r.one_step_fit_percent,
                                  r.simulation_fit_percent));
    for (const std::string& w : r.summary.warnings) m.notes.push_back(w);
    m.termination = r.summary.termination;
  } else {  // narx
    NarxOptions o = options.narx;
    o.ny = request.na;
    o.nu = std::max(1, request.nb);
    o.nk = request.nk;
    SetNarxModel(EstimateNarx(u, y, Ts, o), &m);
  }
  if (m.input_map)
    for (const MapGap& gap : FindMapGaps(*m.input_map, u)) {
      m.notes.push_back("input map: " + gap.Describe());
      m.input_map_undetermined.emplace_back(gap.u_lo, gap.u_hi);
    }
  ScoreModel(data, request.input, request.output, &m);
  return m;
}

namespace {

// Warns when u goes more than 5 % of [c1, cm] beyond it: the range ('what')
// a model was estimated on; 'consequence' says what the model does there.
void InputRangeWarning(const Eigen::VectorXd& u, double c1, double cm, const std::string& what,
                       const std::string& name, const std::string& consequence,
                       std::vector<std::string>* w) {
  const double margin = 0.05 * (cm - c1);
  const double lo = u.minCoeff(), hi = u.maxCoeff();
  if (lo >= c1 - margin && hi <= cm + margin) return;
  const Eigen::Index outside = (u.array() < c1 - margin || u.array() > cm + margin).count();
  w->push_back(fmt::format(
      "the input reaches [{:g}, {:g}], beyond {} [{:g}, {:g}] that the model{} was estimated on "
      "({} of {} samples more than 5 % of that range outside): {}",
      lo, hi, what, c1, cm, name, outside, u.size(), consequence));
}

// The NARX parts of ExtrapolationWarnings: the input beyond the range the
// normalisation maps onto [-1, 1] (the estimation input's), and a free run
// held at its output band's edge.
void NarxExtrapolationWarnings(const IdentifiedModel& model, const Eigen::VectorXd& u,
                               const Eigen::VectorXd* simulated, std::vector<std::string>* w) {
  const NarxModel& n = *model.narx;
  const std::string name = model.method.empty() ? "" : " '" + model.method + "'";
  if (!model.input_map && !(n.u_offset == 0.0 && n.u_scale == 1.0) && n.u_scale > 0.0)
    InputRangeWarning(u, n.u_offset - n.u_scale, n.u_offset + n.u_scale, "the input range", name,
                      "its polynomial extrapolates there", w);
  if (simulated == nullptr || simulated->size() == 0 || !std::isfinite(n.y_min) ||
      !std::isfinite(n.y_max) || !(n.y_max > n.y_min))
    return;
  const double tol = 1e-9 * (n.y_max - n.y_min);
  const Eigen::Index low = (simulated->array() <= n.y_min + tol).count();
  const Eigen::Index high = (simulated->array() >= n.y_max - tol).count();
  if (low + high == 0) return;
  w->push_back(fmt::format(
      "the free run of the model{} is held at the edge of its output band [{:g}, {:g}] (the "
      "estimation output's range widened by a quarter each way) in {} of {} samples ({} at "
      "{:g}, {} at {:g}): there its polynomial ran away from the region it was estimated on, "
      "and the fit measures the band, not the model's dynamics",
      name, n.y_min, n.y_max, low + high, simulated->size(), low, n.y_min, high, n.y_max));
}

}  // namespace

std::vector<std::string> ExtrapolationWarnings(const IdentifiedModel& model, const Dataset& data,
                                               int input, const Eigen::VectorXd* simulated) {
  std::vector<std::string> w;
  if (input < 0 || input >= data.num_inputs() || data.size() == 0) return w;
  if (model.narx) NarxExtrapolationWarnings(model, data.u(input), simulated, &w);
  if (!model.input_map && model.output_map && model.output_map->size() >= 2 &&
      model.discrete) {
    // Wiener: the output map's argument x = G u (from rest at u(0)) beyond
    // the map's knots holds the map at its end value (a Wiener model
    // validated by 74.7 % on inputs 1.5 times the estimation's, unwarned).
    const Eigen::VectorXd u = data.u(input);
    const TransferFunction& g = *model.discrete;
    const double dc = g.DcGain();
    Eigen::VectorXd x;
    if (std::isfinite(dc)) {
      try {
        x = (Lsim(g, (u.array() - u[0]).matrix(), g.Ts()).array() + dc * u[0]).matrix();
      } catch (const std::exception&) {
        x.resize(0);
      }
    }
    const double c1 = model.output_map->u().front(), cm = model.output_map->u().back();
    const double margin = 0.05 * (cm - c1);
    if (x.size() > 0 && x.allFinite() &&
        (x.minCoeff() < c1 - margin || x.maxCoeff() > cm + margin)) {
      const Eigen::Index outside = (x.array() < c1 - margin || x.array() > cm + margin).count();
      w.push_back(fmt::format(
          "the linear part's output x = G u reaches [{:g}, {:g}], beyond the output map's range "
          "[{:g}, {:g}] that the model{} was estimated on ({} of {} samples more than 5 % of "
          "that range outside): the map is held at its end values there, an extrapolation the "
          "data do not support",
          x.minCoeff(), x.maxCoeff(), c1, cm,
          model.method.empty() ? "" : " '" + model.method + "'", outside, x.size()));
    }
  }
  if (!model.input_map) return w;
  const Eigen::VectorXd u = data.u(input);
  InputRangeWarning(u, model.input_map->u().front(), model.input_map->u().back(),
                    "the input map's range", model.method.empty() ? "" : " '" + model.method + "'",
                    "the map is held at its end values there, an extrapolation the data do not "
                    "support",
                    &w);
  for (const auto& [a, b] : model.input_map_undetermined) {
    const auto inside = static_cast<Eigen::Index>(std::count_if(
        u.begin(), u.end(), [a = a, b = b](double x) { return VisitsMapGap(x, a, b); }));
    if (inside == 0) continue;
    w.push_back(fmt::format(
        "the input visits ({:g}, {:g}) in {} of {} samples, where the data the model{} was "
        "estimated on leave its input map undetermined (a steep change between two visited "
        "levels, f = {:.4g} .. {:.4g}): the simulation there is a guess; an estimation "
        "experiment with levels inside that interval would place it",
        a, b, inside, u.size(), model.method.empty() ? "" : " '" + model.method + "'",
        model.input_map->Evaluate(a), model.input_map->Evaluate(b)));
  }
  return w;
}

Eigen::VectorXd SimulateNonlinear(const IdentifiedModel& model, const Dataset& data, int input,
                                  int output) {
  PNEUMID_CHECK(IsNonlinearModel(model), "the model{} has no nonlinear part",
                model.method.empty() ? "" : " '" + model.method + "'");
  PNEUMID_CHECK(input >= 0 && input < data.num_inputs(),
                "input column {} does not exist (the data have {} input(s))", input,
                data.num_inputs());
  data.RequireUniform();  // a gap is named as such, not as another sample time
  const double Ts = data.SampleTime();
  const double model_Ts = model.narx ? model.narx->Ts : model.discrete ? model.discrete->Ts() : Ts;
  PNEUMID_CHECK(std::abs(model_Ts - Ts) <= 1e-6 * Ts,
                "the model{} has sample time {} s, the data{} {} s",
                model.method.empty() ? "" : " '" + model.method + "'", model_Ts,
                data.source().empty() ? "" : " of " + data.source(), Ts);
  const Eigen::VectorXd u = data.u(input);
  if (model.narx) {
    PNEUMID_CHECK(output >= 0 && output < data.num_outputs(),
                  "a NARX simulation starts from the measured output: output column {} does "
                  "not exist (the data have {} output(s))",
                  output, data.num_outputs());
    // affine-narx: the NARX runs on the mapped input f(u).
    if (model.input_map) return model.narx->Simulate(model.input_map->Evaluate(u), data.y(output));
    return model.narx->Simulate(u, data.y(output));
  }
  PNEUMID_CHECK(model.discrete.has_value(),
                "the block-oriented model{} has no discrete linear part",
                model.method.empty() ? "" : " '" + model.method + "'");
  const TransferFunction g(model.discrete->num(), model.discrete->den(), Ts,
                           model.discrete->delay());
  // At rest at the first measured output when there is one (the record
  // starts at rest, wherever), else at rest at the first input.
  std::optional<double> y_first;
  if (output >= 0 && output < data.num_outputs() && data.size() > 0 &&
      std::isfinite(data.y(output)[0]))
    y_first = data.y(output)[0];
  const double dc = g.DcGain();
  const bool gain = std::isfinite(dc) && std::abs(dc) > 1e-9;
  const Eigen::VectorXd v = model.input_map ? model.input_map->Evaluate(u) : u;
  if (v.size() == 0) return v;
  // x = dc v_rest + G (v - v_rest): the linear part at rest with input v_rest.
  auto linear = [&](double v_rest) {
    return (Lsim(g, (v.array() - v_rest).matrix(), Ts).array() + dc * v_rest).matrix().eval();
  };
  if (model.output_map) {
    const StaticMap& out = *model.output_map;
    double v_rest = v[0];
    if (y_first && gain) {
      const auto [lo, hi] = std::minmax_element(out.y().begin(), out.y().end());
      if (*y_first > *lo && *y_first < *hi && out.IsMonotone()) {
        v_rest = out.Inverse(*y_first) / dc;
      } else {
        // A map that turns reaches y_first on several segments: the state
        // nearest the rest at the first input; beyond the map's values, the
        // knot of the nearest value (the estimators start a record alike).
        v_rest = out.NearestPreimageOrEnd(*y_first, dc * v[0]) / dc;
      }
    }
    return out.Evaluate(linear(v_rest));
  }
  return linear(y_first && gain ? *y_first / dc : v[0]);
}

}  // namespace pneumid
