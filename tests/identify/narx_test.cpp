// NARX term selection by FROLS on recorded data of a known polynomial system
// (gen_nonlinear_systems.py beside this file): exactly the true terms are
// selected, their coefficients recovered, the free run matches; bad input.
#include "pneumid/identify/nonlinear/narx.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <string>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "pneumid/common/check.hpp"
#include "pneumid/data/load.hpp"

namespace pneumid {
namespace {

using ::testing::ElementsAre;
using ::testing::HasSubstr;
using ::testing::ThrowsMessage;
using ::testing::UnorderedElementsAre;

Dataset Recorded(const std::string& output) {
  LoadOptions o;
  o.output_columns = {output};
  return LoadDataset(std::string(PNEUMID_SOURCE_DIR) + "/tests/identify/data/narx.csv", o);
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

}  // namespace
}  // namespace pneumid
