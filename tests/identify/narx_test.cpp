// NARX term selection by FROLS on recorded data of a known polynomial system
// (gen_nonlinear_systems.py beside this file): exactly the true terms are
// selected, their coefficients recovered, the free run matches; bad input.
#include "pneumid/identify/nonlinear/narx.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <string>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "pneumid/common/check.hpp"
#include "pneumid/data/load.hpp"
#include "pneumid/identify/evaluation/fit_metrics.hpp"
#include "pneumid/identify/evaluation/validation.hpp"
#include "pneumid/identify/nonlinear/narx_simulation_fit.hpp"
#include "pneumid/identify/nonlinear/nonlinear.hpp"

namespace pneumid {
namespace {

using ::testing::AllOf;
using ::testing::ElementsAre;
using ::testing::HasSubstr;
using ::testing::ThrowsMessage;
using ::testing::UnorderedElementsAre;

Dataset Recorded(const std::string& output, const std::string& file = "narx.csv") {
  LoadOptions o;
  o.output_columns = {output};
  return LoadDataset(std::string(PNEUMID_SOURCE_DIR) + "/tests/identify/data/" + file, o);
}

TEST(NarxTest, CandidatesAreEveryMonomial) {
  // n = 3 regressors, degree 2: C(5, 2) = 10 monomials with the constant.
  const std::vector<NarxTerm> c = NarxCandidates(1, 2, 2);
  EXPECT_EQ(c.size(), 10u);
  EXPECT_THAT(c, ElementsAre(NarxTerm{}, NarxTerm{0}, NarxTerm{1}, NarxTerm{2}, NarxTerm{0, 0},
                             NarxTerm{0, 1}, NarxTerm{0, 2}, NarxTerm{1, 1}, NarxTerm{1, 2},
                             NarxTerm{2, 2}));
  EXPECT_EQ(NarxCandidates(2, 2, 3).size(), 35u);  // C(7, 3)
}

TEST(NarxTest, SelectsTheTrueTermsOfAKnownSystem) {
  // y(t) = -0.605 y(t-1) - 0.163 y(t-2)^2 + 0.588 v(t-1) - 0.240 v(t-2) + e,
  // v = u / 50 - 1. The input covers [0, 100] exactly, so the normalised
  // input is v and, with y := y / s (s = max |y|), the normalised model is
  //   y(t) = -0.605 y(t-1) - 0.163 s y(t-2)^2 + (0.588 / s) u(t-1) - (0.240 / s) u(t-2).
  const Dataset d = Recorded("y");
  NarxOptions o;
  o.ny = 2;
  o.nu = 2;
  o.nk = 1;
  o.degree = 2;
  // Stop at the noise floor: the noise's share of y'y, N sigma^2 / y'y with
  // sigma = 0.01 (normalising y does not change the ratio), with a margin.
  const double floor = static_cast<double>(d.size()) * 1e-4 / d.y().squaredNorm();
  o.err_tolerance = 1.3 * floor;
  const NarxResult r = EstimateNarx(d.u(), d.y(), d.SampleTime(), o);
  EXPECT_EQ(r.model.u_offset, 50.0);
  EXPECT_EQ(r.model.u_scale, 50.0);
  const double s = d.y().cwiseAbs().maxCoeff();
  EXPECT_EQ(r.model.y_scale, s);
  std::vector<std::string> names;
  for (const NarxTerm& t : r.model.terms) names.push_back(r.model.TermName(t));
  ASSERT_THAT(names, UnorderedElementsAre("y(t-1)", "y(t-2)^2", "u(t-1)", "u(t-2)"))
      << r.summary.message << ", noise floor " << floor;
  const std::map<std::string, double> truth = {
      {"y(t-1)", -0.605}, {"y(t-2)^2", -0.163 * s}, {"u(t-1)", 0.588 / s}, {"u(t-2)", -0.240 / s}};
  for (std::size_t i = 0; i < names.size(); ++i)
    EXPECT_NEAR(r.model.theta[i], truth.at(names[i]), 0.02 * std::abs(truth.at(names[i])))
        << names[i];
  // The free run against the measured output, which carries the equation
  // noise propagated through the dynamics (92 % here) ...
  EXPECT_GT(r.simulation_fit_percent, 90.0);
  // ... and against the noise-free system.
  const Dataset truth_run = Recorded("y_true");
  const Eigen::VectorXd sim = r.model.Simulate(d.u(), truth_run.y());
  EXPECT_LT((sim - truth_run.y()).cwiseAbs().maxCoeff(), 0.02);
  EXPECT_THAT(r.model.Equation(), HasSubstr("(normalised: y := y / "));
}

TEST(NarxTest, RoundTripsThroughJson) {
  NarxModel m;
  m.ny = 2;
  m.nu = 2;
  m.nk = 1;
  m.Ts = 0.01;
  m.terms = {NarxTerm{}, NarxTerm{1, 1}, NarxTerm{0, 2}, NarxTerm{3}};
  m.theta = {1, 2, 3, 4};
  m.err = {0.5, 0.2, 0.1, 0.05};
  const nlohmann::json j = ToJson(m);
  EXPECT_EQ(j.at("terms"), nlohmann::json({"1", "y(t-2)^2", "y(t-1)*u(t-1)", "u(t-2)"}));
  EXPECT_EQ(NarxModelFromJson(j), m);
  nlohmann::json bad = j;
  bad["terms"][1] = "y(t-5)";
  EXPECT_THAT([&] { NarxModelFromJson(bad); },
              ThrowsMessage<InvalidArgument>(HasSubstr("y lag 5 outside 1..ny = 2")));
  bad["terms"][1] = "x(t-1)";
  EXPECT_THAT([&] { NarxModelFromJson(bad); },
              ThrowsMessage<InvalidArgument>(HasSubstr("factor 'x(t-1)' is not y(t-K)")));
  // Without a band (a file written before it): none; with one, kept.
  EXPECT_FALSE(j.contains("y_min") || j.contains("y_max"));
  m.y_min = -2.5;
  m.y_max = 7.0;
  const nlohmann::json banded = ToJson(m);
  EXPECT_EQ(banded.at("y_min"), -2.5);
  EXPECT_EQ(NarxModelFromJson(banded), m);
  bad = banded;
  bad["y_max"] = -3.0;
  EXPECT_THAT(
      [&] { NarxModelFromJson(bad); },
      ThrowsMessage<InvalidArgument>(HasSubstr("y_min must lie below y_max, got -2.5 and -3")));
  bad["y_max"] = "high";
  EXPECT_THAT([&] { NarxModelFromJson(bad); },
              ThrowsMessage<InvalidArgument>(HasSubstr("'y_max' must be a finite number")));
}

// y(t) = 2 y(t-1) + u(t-1) with the output band [-1, 10].
NarxModel DoublingModel() {
  NarxModel m;
  m.ny = 1;
  m.nu = 1;
  m.nk = 1;
  m.degree = 1;
  m.terms = {NarxTerm{0}, NarxTerm{1}};
  m.theta = {2.0, 1.0};
  m.y_max = 10.0;
  m.y_min = -1.0;
  return m;
}

// The free run is held within the band: the doubling model from y = 1
// doubles each sample until it meets y_max, and stays there.
TEST(NarxTest, TheFreeRunIsHeldWithinTheOutputBand) {
  const NarxModel m = DoublingModel();
  const Eigen::VectorXd u = Eigen::VectorXd::Zero(8);
  Eigen::VectorXd y = Eigen::VectorXd::Zero(8);
  y(0) = 1.0;
  const Eigen::VectorXd s = m.Simulate(u, y);
  const std::vector<double> expected{1, 2, 4, 8, 10, 10, 10, 10};
  for (Eigen::Index t = 0; t < s.size(); ++t)
    EXPECT_EQ(s(t), expected[static_cast<std::size_t>(t)]);
}

// validate warns where a NARX run leaves what its estimation data support:
// the doubling run above is held at y_max in 4 of its 8 samples; an input
// beyond the range the normalisation maps onto [-1, 1] (u_offset +- u_scale)
// by more than 5 % of it.
TEST(NarxTest, ExtrapolationWarningsNameTheOutputBandAndTheInputRange) {
  IdentifiedModel im;
  im.method = "narx";
  NarxModel& m = im.narx.emplace(DoublingModel());
  Eigen::VectorXd t(8), u = Eigen::VectorXd::Zero(8), y = Eigen::VectorXd::Zero(8);
  for (Eigen::Index i = 0; i < 8; ++i) t(i) = 0.1 * static_cast<double>(i);
  y(0) = 1.0;
  const Dataset data(t, u, y, {{"u", ""}}, {{"y", ""}});
  const Eigen::VectorXd run = m.Simulate(u, y);
  EXPECT_THAT(ExtrapolationWarnings(im, data, 0, &run),
              ElementsAre(AllOf(HasSubstr("the free run of the model 'narx' is held at the "
                                          "edge of its output band [-1, 10]"),
                                HasSubstr("in 4 of 8 samples (0 at -1, 4 at 10)"))));
  EXPECT_TRUE(ExtrapolationWarnings(im, data).empty());  // no run given
  m.theta = {0.5, 1.0};                                  // y(t) = 0.5 y(t-1): inside the band
  const Eigen::VectorXd stable = m.Simulate(u, y);
  EXPECT_TRUE(ExtrapolationWarnings(im, data, 0, &stable).empty());
  // Estimated on u in [0, 10]: up to 10.5 is within 5 % of that range.
  m.u_offset = 5.0;
  m.u_scale = 5.0;
  Eigen::VectorXd inside(8), outside(8);
  inside << 0, 2, 4, 6, 8, 10, 10.5, -0.5;
  outside << 0, 2, 4, 6, 8, 10, 10.6, 12;
  EXPECT_TRUE(ExtrapolationWarnings(im, Dataset(t, inside, y, {{"u", ""}}, {{"y", ""}})).empty());
  EXPECT_THAT(
      ExtrapolationWarnings(im, Dataset(t, outside, y, {{"u", ""}}, {{"y", ""}})),
      ElementsAre(AllOf(HasSubstr("the input reaches [0, 12], beyond the input range [0, 10]"),
                        HasSubstr("(2 of 8 samples more than 5 % of that range outside)"))));
}

// ForgetsItsStart against its definition: runs from the first outputs
// shifted by -+shift must come within shift / 5 of the nominal run over the
// second half of the samples.
TEST(NarxTest, ForgetsItsStartAsTheRunOfAStablePlantDoes) {
  const auto model = [](std::vector<NarxTerm> terms, std::vector<double> theta) {
    NarxModel m;
    m.degree = 3;
    m.terms = std::move(terms);
    m.theta = std::move(theta);
    return m;
  };
  const Eigen::VectorXd u = Eigen::VectorXd::Ones(41);
  // y(t) = 0.5 y(t-1) + u(t-1): the shift halves every sample.
  const NarxModel stable = model({NarxTerm{0}, NarxTerm{1}}, {0.5, 1.0});
  EXPECT_TRUE(stable.ForgetsItsStart(u, Eigen::VectorXd::Constant(41, 2.0), 1.0));
  // An integrator keeps the shift for ever; no shift is always forgotten.
  const NarxModel integrator = model({NarxTerm{0}, NarxTerm{1}}, {1.0, 0.1});
  EXPECT_FALSE(integrator.ForgetsItsStart(u, Eigen::VectorXd::Zero(41), 1.0));
  EXPECT_TRUE(integrator.ForgetsItsStart(u, Eigen::VectorXd::Zero(41), 0.0));
  // y(t) = 1.5 y(t-1) - 0.5 y(t-1)^3 rests at +-1 (0 is unstable): from 1
  // shifted by 0.2 it returns to 1, shifted by 1.2 (to -0.2) it runs to -1.
  const Eigen::VectorXd zero = Eigen::VectorXd::Zero(41), one = Eigen::VectorXd::Ones(41);
  const NarxModel bistable = model({NarxTerm{0}, NarxTerm{0, 0, 0}}, {1.5, -0.5});
  EXPECT_TRUE(bistable.ForgetsItsStart(zero, one, 0.2));
  EXPECT_FALSE(bistable.ForgetsItsStart(zero, one, 1.2));
  // y(t) = 0.99 y(t-1) from 0: a shift s is 0.99^t s at t, above s / 5 until
  // t = 161. 51 samples: the second half starts at t = 26 (0.77 s), not
  // forgotten; 401 samples: at t = 201 (0.133 s), forgotten.
  const NarxModel slow = model({NarxTerm{0}, NarxTerm{1}}, {0.99, 0.0});
  EXPECT_FALSE(slow.ForgetsItsStart(Eigen::VectorXd::Zero(51), Eigen::VectorXd::Zero(51), 1.0));
  EXPECT_TRUE(slow.ForgetsItsStart(Eigen::VectorXd::Zero(401), Eigen::VectorXd::Zero(401), 1.0));
  // y(t) = 2 y(t-1) without an output band: a shifted run overflows.
  const NarxModel unstable = model({NarxTerm{0}, NarxTerm{1}}, {2.0, 0.0});
  EXPECT_FALSE(
      unstable.ForgetsItsStart(Eigen::VectorXd::Zero(2001), Eigen::VectorXd::Zero(2001), 1.0));
  // The nominal run, when given, must match the record.
  const Eigen::VectorXd short_run = Eigen::VectorXd::Zero(5);
  EXPECT_THROW(stable.ForgetsItsStart(u, one, 1.0, &short_run), InvalidArgument);
}

TEST(NarxTest, RejectsMoreCandidatesThanSamples) {
  const Eigen::VectorXd u = Eigen::VectorXd::LinSpaced(30, 0, 1);
  const Eigen::VectorXd y = Eigen::VectorXd::LinSpaced(30, 1, 2);
  NarxOptions o;
  o.ny = 3;
  o.nu = 3;
  o.degree = 3;  // C(9, 3) = 84 candidates, 27 rows
  EXPECT_THAT([&] { EstimateNarx(u, y, 0.01, o); },
              ThrowsMessage<InvalidArgument>(HasSubstr(
                  "84 candidate terms (ny = 3, nu = 3, degree = 3) exceed the 27 regression rows "
                  "of the 30 samples")));
  o.degree = 4;
  EXPECT_THAT([&] { EstimateNarx(u, y, 0.01, o); },
              ThrowsMessage<InvalidArgument>(HasSubstr("degree must be 1, 2 or 3, got 4")));
}

TEST(NarxTest, SimulationFitStartsFromADivergentModelAndRecoversTheSystem) {
  // The true terms of narx.csv with the least-squares theta, then y(t-1)'s
  // coefficient set to 1.5: that free run leaves every bound (overflows), so
  // only the clip band keeps the criterion finite for the search.
  const Dataset d = Recorded("y");
  const Dataset truth_run = Recorded("y_true");
  NarxOptions o;
  o.ny = 2;
  o.nu = 2;
  o.nk = 1;
  o.degree = 2;
  o.max_terms = 4;
  const NarxModel ls = EstimateNarx(d.u(), d.y(), d.SampleTime(), o).model;
  NarxModel m = ls;
  const auto y1 = std::find(m.terms.begin(), m.terms.end(), NarxTerm{0}) - m.terms.begin();
  ASSERT_LT(y1, 4);
  m.theta[static_cast<std::size_t>(y1)] = 1.5;
  NarxModel unbanded = m;
  unbanded.y_min = -std::numeric_limits<double>::infinity();
  unbanded.y_max = std::numeric_limits<double>::infinity();
  EXPECT_FALSE(unbanded.Simulate(d.u(), d.y()).allFinite());
  // The model's output band (the estimation output's range widened by a
  // quarter of it each way) holds the run at its edge instead.
  const Eigen::VectorXd banded = m.Simulate(d.u(), d.y());
  const double range = d.y().maxCoeff() - d.y().minCoeff();
  EXPECT_DOUBLE_EQ(m.y_max, d.y().maxCoeff() + 0.25 * range);
  EXPECT_DOUBLE_EQ(m.y_min, d.y().minCoeff() - 0.25 * range);
  EXPECT_TRUE(banded.allFinite());
  EXPECT_TRUE((banded.array() == m.y_max).any() || (banded.array() == m.y_min).any());
  const NarxSimulationFitResult r = FitNarxSimulation(&m, d.u(), d.y());
  EXPECT_EQ(r.summary.termination, Termination::kConvergence) << r.summary.message;
  EXPECT_FALSE(r.diverges);
  EXPECT_EQ(r.clipped, 0);
  EXPECT_TRUE(r.summary.warnings.empty());
  // Back at the system: the coefficients within 3 % of least squares' (on
  // equation noise of std 0.01 both estimates are near the truth) ...
  for (std::size_t i = 0; i < m.theta.size(); ++i)
    EXPECT_NEAR(m.theta[i], ls.theta[i], 0.03 * std::abs(ls.theta[i])) << m.TermName(m.terms[i]);
  // ... a simulation error below least squares' (the criterion it minimises) ...
  const auto mse = [&](const NarxModel& x) {
    return (x.Simulate(d.u(), d.y()) - d.y()).tail(d.size() - 2).squaredNorm() /
           static_cast<double>(d.size() - 2);
  };
  EXPECT_LE(mse(m), mse(ls) * (1.0 + 1e-9));
  EXPECT_NEAR(r.summary.loss, mse(m), 1e-9 * mse(m));
  EXPECT_GT(r.summary.initial_loss, 100.0 * r.summary.loss);
  // ... and a free run within 0.02 of the noise-free output.
  EXPECT_LT((m.Simulate(d.u(), truth_run.y()) - truth_run.y()).cwiseAbs().maxCoeff(), 0.02);
}

// Two cascaded tanks with square-root outflow and overflow
// (gen_two_tanks.py): a fixed NARX structure of degree 3 whose one-step
// least-squares theta simulates poorly on a second record (validation fit
// 48 %, started away from rest); the simulation focus gives 86 %.
TEST(NarxTest, SimulationFocusRecoversTwoTanks) {
  const Dataset est = Recorded("y", "two_tanks_est.csv");
  const Dataset val = Recorded("y", "two_tanks_val.csv");
  const Dataset val_true = Recorded("y_true", "two_tanks_val.csv");
  NarxOptions o;
  o.ny = 2;
  o.nu = 2;
  o.nk = 1;
  o.degree = 3;
  o.max_terms = 10;
  const NarxResult p = EstimateNarx(est.u(), est.y(), est.SampleTime(), o);
  o.focus = NarxFocus::kSimulation;
  const NarxResult s = EstimateNarx(est.u(), est.y(), est.SampleTime(), o);
  EXPECT_EQ(s.model.terms, p.model.terms);  // FROLS chooses the terms either way
  EXPECT_EQ(s.summary.termination, Termination::kConvergence) << s.summary.message;
  EXPECT_THAT(s.summary.message, HasSubstr("focus simulation"));
  EXPECT_TRUE(s.summary.warnings.empty());
  EXPECT_LT(p.simulation_fit_percent, 70.0);
  EXPECT_GT(s.simulation_fit_percent, 93.0);
  const auto fit = [&](const NarxModel& m, const Dataset& d) {
    const Eigen::Index n0 = m.FirstSample(), n = d.size() - n0;
    return NrmseFit(d.y().tail(n).eval(), m.Simulate(val.u(), d.y()).tail(n).eval());
  };
  EXPECT_LT(fit(p.model, val), 60.0);
  EXPECT_GT(fit(s.model, val), 83.0);
  EXPECT_GT(fit(s.model, val_true), 83.0);
}

// The structure search with the simulation focus (lags 1..3, up to 15
// terms, on the last 30 % of the estimation record), then the chosen
// candidate refined on all of it, validated on the second record: 86 %,
// the prediction focus's search 69 %.
TEST(NarxTest, SimulationFocusStructureSearchOnTwoTanks) {
  const Dataset est = Recorded("y", "two_tanks_est.csv");
  const Dataset val = Recorded("y", "two_tanks_val.csv");
  IdentifyRequest request;
  NonlinearOptions o;
  o.choose_structure = true;
  o.max_narx_lag = 3;
  o.max_narx_terms = 15;
  o.narx.degree = 3;
  o.narx.focus = NarxFocus::kSimulation;
  const IdentifiedModel m = IdentifyNonlinear("narx", est, request, o);
  ASSERT_TRUE(m.narx.has_value());
  ASSERT_GE(m.notes.size(), 4u);
  EXPECT_THAT(m.notes[0], HasSubstr("structure chosen on held-out data"));
  EXPECT_THAT(m.notes[3], HasSubstr("refined on all the data"));
  EXPECT_NE(m.termination, Termination::kFailure);
  const Eigen::Index n0 = m.narx->FirstSample(), n = val.size() - n0;
  const double fit =
      NrmseFit(val.y().tail(n).eval(), m.narx->Simulate(val.u(), val.y()).tail(n).eval());
  EXPECT_GT(fit, 80.0) << m.notes[0];
  o.narx.focus = NarxFocus::kPrediction;
  const IdentifiedModel p = IdentifyNonlinear("narx", est, request, o);
  const Eigen::VectorXd sp = p.narx->Simulate(val.u(), val.y());
  const Eigen::Index np = val.size() - p.narx->FirstSample();
  const double fit_p =
      sp.allFinite() ? NrmseFit(val.y().tail(np).eval(), sp.tail(np).eval()) : -1e9;
  EXPECT_GT(fit, fit_p + 10.0);  // 86 % against 69 %
}

// The structure search of narx, degree 3, focus simulation.
NonlinearOptions SimulationFocusSearch() {
  NonlinearOptions o;
  o.choose_structure = true;
  o.narx.degree = 3;
  o.narx.focus = NarxFocus::kSimulation;
  return o;
}

// Two tanks whose validation record starts away from rest and visits
// outputs below the estimation record's (gen_two_tanks.py, seeds 41/42).
// The simulation-focus search on the last 30 % chooses a 7-lag, 40-term
// candidate (held-out fit 96 %); refined once more on the estimation part,
// its free run no longer forgets its start and validated by -326 %. The
// candidate as the search scored it is kept instead: 83 %.
TEST(NarxTest, TheRefinedChoiceMustStillForgetItsStart) {
#ifdef PNEUMID_SANITIZED_BUILD
  GTEST_SKIP() << "a 4 s structure search in a release build";
#endif
  const Dataset val = Recorded("y", "two_tanks_41_val.csv");
  const auto [head, tail] = SplitDataset(Recorded("y", "two_tanks_41_est.csv"), 0.7);
  const IdentifyRequest request;
  NonlinearOptions o = SimulationFocusSearch();
  o.max_narx_lag = 7;
  o.max_narx_terms = 40;
  const IdentifiedModel m = IdentifyNonlinear("narx", head, request, o, &tail);
  ASSERT_TRUE(m.narx.has_value());
  ASSERT_GE(m.notes.size(), 4u);
  EXPECT_THAT(m.notes[0], HasSubstr("ny = nu = 7, nk = 1, 40 terms"));
  EXPECT_THAT(m.notes[3], HasSubstr("no longer forgets its start"));
  EXPECT_EQ(m.termination, Termination::kConvergence);
  const Eigen::VectorXd yh = head.y();
  EXPECT_TRUE(m.narx->ForgetsItsStart(tail.u(), tail.y(), 0.25 * (yh.maxCoeff() - yh.minCoeff())));
  const Eigen::Index n0 = m.narx->FirstSample(), n = val.size() - n0;
  const double fit =
      NrmseFit(val.y().tail(n).eval(), m.narx->Simulate(val.u(), val.y()).tail(n).eval());
  EXPECT_GT(fit, 60.0) << m.notes[0];
}

// The 31/32 pair of gen_two_tanks.py: by the held-out fit alone the
// simulation-focus search on the last 30 % chose a candidate that does not
// forget its start (`identify --split 0.7` then validated it by -351 %);
// passed over, the choice validates by 88 %.
TEST(NarxTest, TheStructureSearchPassesOverCandidatesThatDoNotForgetTheirStart) {
#ifdef PNEUMID_SANITIZED_BUILD
  GTEST_SKIP() << "a 9 s structure search in a release build";
#endif
  const auto [head, tail] = SplitDataset(Recorded("y", "two_tanks_31_est.csv"), 0.7);
  const StructureChoice c =
      ChooseBlockStructure("narx", head, IdentifyRequest(), SimulationFocusSearch(), &tail);
  const auto chosen = std::find_if(c.candidates.begin(), c.candidates.end(), [&](const auto& k) {
    return k.na == c.na && k.nk == c.nk && k.terms == c.terms;
  });
  ASSERT_NE(chosen, c.candidates.end());
  EXPECT_TRUE(chosen->forgets_start);
  const auto best =
      std::max_element(c.candidates.begin(), c.candidates.end(),
                       [](const auto& a, const auto& b) { return a.fit_percent < b.fit_percent; });
  EXPECT_FALSE(best->forgets_start);  // the held-out fit alone would choose it
  EXPECT_THAT(c.Describe(), HasSubstr("* does not forget its start"));
}

TEST(NarxTest, FocusNamesRoundTrip) {
  EXPECT_EQ(NarxFocusFromString(ToString(NarxFocus::kSimulation)), NarxFocus::kSimulation);
  EXPECT_EQ(NarxFocusFromString(ToString(NarxFocus::kPrediction)), NarxFocus::kPrediction);
  EXPECT_THAT([] { NarxFocusFromString("sim"); },
              ThrowsMessage<InvalidArgument>(HasSubstr("unknown NARX focus 'sim'")));
  NarxOptions o;
  o.max_iterations = 0;
  std::string why;
  EXPECT_FALSE(o.IsValid(&why));
  EXPECT_THAT(why, HasSubstr("max_iterations must be >= 1"));
}

}  // namespace
}  // namespace pneumid
