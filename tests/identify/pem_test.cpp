#include "pneumid/identify/parametric/pem.hpp"

#include <cmath>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "parametric_test_util.hpp"
#include "pneumid/common/check.hpp"
#include "pneumid/identify/parametric/arx.hpp"
#include "pneumid/identify/parametric/iv.hpp"
#include "pneumid/lti/transfer_function.hpp"

namespace pneumid {
namespace {

// True plant G = B / F (Ljung 1999, Example 8.x style second-order system):
// F = 1 - 1.5 q^-1 + 0.7 q^-2, B = q^-1 + 0.5 q^-2.
PolynomialModel TrueOe() {
  PolynomialModel m;
  m.Ts = 1.0;
  m.structure = "OE";
  m.b = {Eigen::Vector3d(0, 1.0, 0.5)};
  m.nk = {1};
  m.f = {Eigen::Vector3d(1, -1.5, 0.7)};
  return m;
}

struct OeData {
  Eigen::VectorXd u, y;
};

OeData MakeOeData(Eigen::Index n, double noise, unsigned seed) {
  OeData d;
  d.u = testing::Prbs(n, -1.0, 1.0, 1, seed);
  Eigen::MatrixXd um = d.u;
  d.y = Simulate(TrueOe(), um) + testing::WhiteNoise(n, noise, seed + 1);
  return d;
}

TEST(Pem, OutputErrorRemovesTheBiasOfArx) {
  // White measurement noise on the output is coloured as seen by the ARX
  // structure (its equation error is F e), so least squares is biased
  // (Ljung 1999, sec. 8.3); the OE predictor is correct and consistent.
  const OeData d = MakeOeData(4000, 1.0, 3);
  Eigen::MatrixXd um = d.u;
  ArxOptions ao;
  ao.na = 2;
  ao.nb = {2};
  ao.nk = {1};
  const ArxResult arx = EstimateArx(d.y, um, 1.0, ao);
  const Eigen::Vector2d f_true(-1.5, 0.7);
  const double arx_err = (arx.model.a.tail(2) - f_true).norm();
  PemOrders o;
  o.nb = 2;
  o.nf = 2;
  o.nk = 1;
  const PemResult oe = EstimatePolynomial(PolynomialStructure::kOe, o, d.y, d.u, 1.0);
  ASSERT_EQ(oe.summary.termination, Termination::kConvergence) << oe.summary.message;
  ASSERT_EQ(oe.model.f.size(), 1u);
  const double oe_err = (oe.model.f[0].tail(2) - f_true).norm();
  EXPECT_GT(arx_err, 0.1) << arx.model.a.transpose();    // the bias
  EXPECT_LT(oe_err, 0.02) << oe.model.f[0].transpose();  // its removal
  // The estimate lies within 4 standard deviations of the truth.
  const Eigen::VectorXd sd = oe.model.ParameterStd();
  ASSERT_EQ(sd.size(), 4);
  const Eigen::Vector4d truth(1.0, 0.5, -1.5, 0.7);  // b1 b2 f1 f2
  for (int i = 0; i < 4; ++i)
    EXPECT_LT(std::abs(oe.model.Parameters()[i] - truth[i]), 4 * sd[i]) << i;
  // The noise variance is that of the added white noise.
  EXPECT_NEAR(oe.model.noise_variance, 1.0, 0.1);
}

TEST(Pem, Iv4IsConsistentWhereLeastSquaresIsBiased) {
  const OeData d = MakeOeData(4000, 1.0, 5);
  IvOptions io;
  io.na = 2;
  io.nb = 2;
  io.nk = 1;
  const IvResult iv = EstimateIv4(d.y, d.u, 1.0, io);
  ASSERT_EQ(iv.summary.termination, Termination::kConvergence) << iv.summary.message;
  EXPECT_LT((iv.model.a.tail(2) - Eigen::Vector2d(-1.5, 0.7)).norm(), 0.05)
      << iv.model.a.transpose();
  EXPECT_LT((iv.model.b[0].tail(2) - Eigen::Vector2d(1.0, 0.5)).norm(), 0.1);
}

TEST(Pem, Iv4WithOrdersAboveTheDataStaysStable) {
  // IV4(3, 3) on a second-order plant: the least-squares model has a
  // near-common factor of A and B, so the instruments it generates are nearly
  // collinear and the plain IV solution amplifies noise along the near-null
  // direction (an unstable model). Solved in the determined subspace, the
  // model is stable, keeps the plant's static gain B(1)/F(1) = 1.5/0.2 = 7.5
  // and simulates the noise-free output; a warning names the cause.
  const OeData d = MakeOeData(4000, 0.01, 7);
  IvOptions io;
  io.na = 3;
  io.nb = 3;
  io.nk = 1;
  const IvResult iv = EstimateIv4(d.y, d.u, 1.0, io);
  ASSERT_EQ(iv.summary.termination, Termination::kConvergence) << iv.summary.message;
  const Eigen::VectorXcd poles = poly::Roots(iv.model.a);
  for (Eigen::Index i = 0; i < poles.size(); ++i) EXPECT_LT(std::abs(poles[i]), 1.0) << poles[i];
  const double gain = iv.model.b[0].sum() / iv.model.a.sum();
  EXPECT_NEAR(gain, 7.5, 0.01 * 7.5);
  Eigen::MatrixXd um = d.u;
  const Eigen::VectorXd clean = Simulate(TrueOe(), um);
  const Eigen::VectorXd sim = Simulate(iv.model, um);
  EXPECT_LT((sim - clean).norm() / clean.norm(), 0.01);
  bool warned = false;
  for (const std::string& w : iv.summary.warnings) warned |= w.find("nearly collinear") != std::string::npos;
  EXPECT_TRUE(warned);
}

TEST(Pem, ArmaxRecoversTheNoiseModelWhereArxIsBiased) {
  // A y = B u + C e with C = 1 - 0.9 q^-1 + 0.2 q^-2: ARX is biased.
  const Eigen::Index n = 5000;
  PolynomialModel truth;
  truth.Ts = 0.01;
  truth.structure = "ARMAX";
  truth.a = Eigen::Vector3d(1, -1.5, 0.7);
  truth.b = {Eigen::Vector3d(0, 1.0, 0.5)};
  truth.nk = {1};
  truth.c = Eigen::Vector3d(1, -0.9, 0.2);
  const Eigen::VectorXd u = testing::Prbs(n, -1, 1, 1, 9);
  const Eigen::VectorXd e = testing::WhiteNoise(n, 0.5, 21);
  PolynomialModel noise = truth;  // C / A e
  noise.b = {truth.c};
  noise.nk = {0};
  noise.c = Eigen::VectorXd::Ones(1);
  Eigen::MatrixXd um = u;
  const Eigen::VectorXd y = Simulate(truth, um) + Simulate(noise, e);
  ArxOptions ao;
  ao.na = 2;
  ao.nb = {2};
  ao.nk = {1};
  const ArxResult arx = EstimateArx(y, um, 0.01, ao);
  PemOrders o;
  o.na = 2;
  o.nb = 2;
  o.nc = 2;
  o.nk = 1;
  const PemResult armax = EstimatePolynomial(PolynomialStructure::kArmax, o, y, u, 0.01);
  ASSERT_TRUE(armax.summary.IsSolutionUsable()) << armax.summary.message;
  const Eigen::VectorXd truth_theta = truth.Parameters();  // a1 a2 b1 b2 c1 c2
  const double arx_err = (arx.model.Parameters() - truth_theta.head(4)).norm();
  const double armax_err = (armax.model.Parameters() - truth_theta).norm();
  EXPECT_GT(arx_err, 0.1);
  EXPECT_LT(armax_err, 0.05) << armax.model.Parameters().transpose();
  EXPECT_LE(armax.summary.loss, armax.summary.initial_loss);
  EXPECT_NEAR(armax.model.noise_variance, 0.25, 0.02);
}

TEST(Pem, BoxJenkinsRecoversPlantAndNoiseModel) {
  const Eigen::Index n = 6000;
  PolynomialModel truth = TrueOe();
  truth.structure = "BJ";
  truth.c = Eigen::Vector2d(1, 0.5);
  truth.d = Eigen::Vector2d(1, -0.85);
  const Eigen::VectorXd u = testing::Prbs(n, -1, 1, 1, 13);
  Eigen::MatrixXd um = u;
  PolynomialModel noise;  // C / D e
  noise.Ts = 1.0;
  noise.a = truth.d;
  noise.b = {truth.c};
  noise.nk = {0};
  const Eigen::VectorXd y = Simulate(truth, um) + Simulate(noise, testing::WhiteNoise(n, 0.3, 17));
  PemOrders o;
  o.nb = 2;
  o.nc = 1;
  o.nd = 1;
  o.nf = 2;
  o.nk = 1;
  const PemResult bj = EstimatePolynomial(PolynomialStructure::kBj, o, y, u, 1.0);
  ASSERT_TRUE(bj.summary.IsSolutionUsable()) << bj.summary.message;
  EXPECT_EQ(bj.model.structure, "BJ");
  const Eigen::VectorXd p = bj.model.Parameters();  // b1 b2 c1 d1 f1 f2
  const Eigen::VectorXd t = truth.Parameters();
  ASSERT_EQ(p.size(), 6);
  EXPECT_LT((p - t).cwiseAbs().maxCoeff(), 0.05) << p.transpose() << "\n" << t.transpose();
}

TEST(Pem, ReflectUnstableRootsKeepsMagnitudeResponseShape) {
  // 1 - 2.5 q^-1 + q^-2 has roots 2 and 0.5; reflection gives a double root at 0.5.
  const Eigen::VectorXd r = ReflectUnstableRoots(Eigen::Vector3d(1, -2.5, 1));
  EXPECT_NEAR(r[1], -1.0, 1e-12);
  EXPECT_NEAR(r[2], 0.25, 1e-12);
  const Eigen::VectorXd stable = Eigen::Vector3d(1, -0.5, 0.06);
  EXPECT_EQ(ReflectUnstableRoots(stable), stable);
}

TEST(Pem, InvalidArgumentsThrow) {
  const Eigen::VectorXd y = Eigen::VectorXd::Ones(100), u = Eigen::VectorXd::Ones(99);
  EXPECT_THROW(EstimatePolynomial(PolynomialStructure::kOe, PemOrders{}, y, u, 1.0),
               InvalidArgument);
  PemOrders bad;
  bad.nb = 0;
  EXPECT_THROW(EstimatePolynomial(PolynomialStructure::kOe, bad, y, y, 1.0), InvalidArgument);
  EXPECT_THROW(PolynomialStructureFromString("arma"), InvalidArgument);
  EXPECT_EQ(PolynomialStructureFromString("bj"), PolynomialStructure::kBj);
  PemOptions po;
  po.max_iterations = -1;
  std::string error;
  EXPECT_FALSE(po.IsValid(&error));
  EXPECT_THAT(error, ::testing::HasSubstr("max_iterations"));
}

}  // namespace
}  // namespace pneumid
