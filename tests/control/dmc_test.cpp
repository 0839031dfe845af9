// DMC and QDMC (step coefficients: prediction_model_test.cpp): the paper's two
// predictive-control settings against an independent simulation
// (gen_dmc_reference.py), offset-free tracking under model mismatch, and the
// constraints of the QP form.
#include "pneumid/control/dmc.hpp"

#include <cmath>
#include <memory>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "pneumid/common/check.hpp"
#include "pneumid/control/closed_loop.hpp"
#include "pneumid/models/model_file.hpp"
#include "pneumid/plant/linear_plant.hpp"
#include "pneumid/plant/signal.hpp"

namespace pneumid {
namespace {

constexpr double kTs = 0.01;

TransferFunction PaperFopdt() { return TransferFunction::Fopdt(1.6, 0.245, 0.001); }

struct PaperCase {
  int M;
  double lambda;
  // gen_dmc_reference.py
  double first_move, rise, overshoot, settling;
  // docs/paper.md, reference value 6
  double paper_first_move, paper_rise, paper_overshoot, paper_settling;
};

class DmcPaperTest : public ::testing::TestWithParam<PaperCase> {};

TEST_P(DmcPaperTest, NominalFopdtReproducesReferenceFigures) {
  const PaperCase c = GetParam();
  DmcOptions o;
  o.P = 126;
  o.M = c.M;
  o.lambda = c.lambda;
  DmcController dmc(PaperFopdt(), kTs, o);
  LinearPlant plant(PaperFopdt(), kTs);
  auto setpoint = ParseSignal("step:from=0,to=1,at=0");
  ClosedLoopOptions cl;
  cl.duration = 3.0;
  const ClosedLoopResult r = SimulateClosedLoop(dmc, plant, *setpoint, cl);
  const ClosedLoopMetrics& m = r.metrics;
  EXPECT_NEAR(m.first_move, c.first_move, 1e-6);
  EXPECT_NEAR(m.rise_time, c.rise, 2e-3);
  EXPECT_NEAR(m.overshoot_percent, c.overshoot, 0.02);
  EXPECT_NEAR(m.settling_time, c.settling, 2e-3);
  EXPECT_NEAR(m.steady_state_error, 0.0, 1e-9);
  // The paper's rounded figures: first move to 3 decimals, times within one
  // sample, overshoot within 0.1 percentage point.
  EXPECT_NEAR(m.first_move, c.paper_first_move, 6e-4);
  EXPECT_NEAR(m.rise_time, c.paper_rise, kTs);
  EXPECT_NEAR(m.overshoot_percent, c.paper_overshoot, 0.1);
  EXPECT_NEAR(m.settling_time, c.paper_settling, kTs);
}

INSTANTIATE_TEST_SUITE_P(PaperSettings, DmcPaperTest,
                         ::testing::Values(PaperCase{5, 2.25, 0.672059, 0.105520, 2.035261,
                                                     0.225007, 0.672, 0.110, 2.0, 0.23},
                                           PaperCase{10, 1.92, 0.761218, 0.091650, 3.639621,
                                                     0.241213, 0.761, 0.090, 3.6, 0.25}));

TEST(DmcTest, OffsetFreeUnderModelMismatchAndLoad) {
  // Controller from the FOPDT, plant = the paper's ARX model (Eq. 5), with a
  // load step: the bias correction removes the steady-state error.
  DmcOptions o;
  o.P = 126;
  o.M = 5;
  o.lambda = 2.25;
  DmcController dmc(PaperFopdt(), kTs, o);
  LinearPlant plant(PaperArxModel(), kTs);
  auto setpoint = ParseSignal("staircase:levels=0 20 40 20,dwell=1.5");
  ClosedLoopOptions cl;
  cl.duration = 7.0;
  cl.load_steps = {{5.0, -5.0}};
  const ClosedLoopResult r = SimulateClosedLoop(dmc, plant, *setpoint, cl);
  ASSERT_EQ(r.metrics.steps.size(), 3u);
  // The first two steps settle within their 1.5 s windows; the last step's
  // window ends at the load step, 0.5 s after it, still within 0.5 %.
  EXPECT_NEAR(r.metrics.steps[0].steady_state_error, 0.0, 1e-3 * 20);
  EXPECT_NEAR(r.metrics.steps[1].steady_state_error, 0.0, 1e-3 * 20);
  EXPECT_NEAR(r.metrics.steps[2].steady_state_error, 0.0, 5e-3 * 20);
  // Offset-free after the load: the end of the record.
  EXPECT_NEAR(r.metrics.steady_state_error, 0.0, 1e-3);
  EXPECT_LT(r.metrics.load_peak_deviation, -1.0);  // the load pulled the output down
  EXPECT_GT(r.metrics.load_recovery_time, 0.0);
  EXPECT_LT(r.metrics.load_recovery_time, 0.5);
}

TEST(DmcTest, UnconstrainedMoveIsGainTimesPredictedError) {
  DmcOptions o;
  o.P = 20;
  o.M = 3;
  o.lambda = 0.5;
  DmcController dmc(PaperFopdt(), kTs, o);
  // Closed form of the first row of (A'A + lambda I)^-1 A'.
  const Eigen::MatrixXd& A = dmc.dynamic_matrix();
  const Eigen::MatrixXd K =
      (A.transpose() * A + 0.5 * Eigen::MatrixXd::Identity(3, 3)).ldlt().solve(A.transpose());
  EXPECT_LT((dmc.gain() - K.row(0)).norm(), 1e-12 * K.row(0).norm());
  dmc.Reset(0.0, 0.0);
  const double u = dmc.Update(2.0, 0.0);
  EXPECT_NEAR(u, 2.0 * K.row(0).sum(), 1e-12);
  // After the move the free response includes it: f = s * u.
  dmc.Update(2.0, 0.0);  // plant did not respond (measurement 0): bias = -yhat_0
  const Eigen::VectorXd& s = dmc.step_coefficients();
  for (int i = 0; i < 20; ++i) EXPECT_NEAR(dmc.free_response()(i), s(i + 2) * u - s(1) * u, 1e-12);
}

TEST(QdmcTest, LooseBoundsGiveTheUnconstrainedMoves) {
  DmcOptions o;
  o.P = 126;
  o.M = 10;
  o.lambda = 1.92;
  DmcOptions oc = o;
  oc.constrained = true;
  oc.limits.u_min = -100;
  oc.limits.u_max = 100;
  oc.limits.du_max = 50;
  DmcController a(PaperFopdt(), kTs, o), b(PaperFopdt(), kTs, oc);
  LinearPlant pa(PaperFopdt(), kTs), pb(PaperFopdt(), kTs);
  auto sp = ParseSignal("staircase:levels=0 1 -1 0.5,dwell=0.5");
  ClosedLoopOptions cl;
  cl.duration = 2.0;
  const auto ra = SimulateClosedLoop(a, pa, *sp, cl);
  const auto rb = SimulateClosedLoop(b, pb, *sp, cl);
  EXPECT_LT((ra.u - rb.u).cwiseAbs().maxCoeff(), 1e-9);
  EXPECT_EQ(b.qp_failures(), 0);
}

TEST(QdmcTest, RespectsInputAndRateBoundsAndBeatsClipping) {
  DmcOptions o;
  o.P = 126;
  o.M = 10;
  o.lambda = 1.92;
  o.limits.u_min = 0.0;
  o.limits.u_max = 0.9;
  o.limits.du_max = 0.2;
  DmcOptions oc = o;
  oc.constrained = true;
  DmcController clip(PaperFopdt(), kTs, o), qdmc(PaperFopdt(), kTs, oc);
  LinearPlant p1(PaperFopdt(), kTs), p2(PaperFopdt(), kTs);
  auto sp = ParseSignal("step:from=0,to=1.3,at=0.05");
  ClosedLoopOptions cl;
  cl.duration = 2.0;
  const auto r1 = SimulateClosedLoop(clip, p1, *sp, cl);
  const auto r2 = SimulateClosedLoop(qdmc, p2, *sp, cl);
  for (const auto* r : {&r1, &r2}) {
    EXPECT_GE(r->metrics.u_min, -1e-12);
    EXPECT_LE(r->metrics.u_max, 0.9 + 1e-12);
    Eigen::VectorXd du = r->u;
    du.tail(du.size() - 1) -= r->u.head(du.size() - 1);
    EXPECT_LE(du.cwiseAbs().maxCoeff(), 0.2 + 1e-12);
  }
  EXPECT_EQ(qdmc.qp_failures(), 0);
  EXPECT_EQ(qdmc.last_qp_summary().status, QpStatus::kSolved);
  // The QP knows the constraints over the whole horizon: its tracking error
  // is no worse than clipping the unconstrained move.
  EXPECT_LE(r2.metrics.ise, r1.metrics.ise * (1.0 + 1e-9));
}

TEST(QdmcTest, SoftOutputBoundLimitsOvershoot) {
  DmcOptions o;
  o.P = 126;
  o.M = 10;
  o.lambda = 1.92;
  o.constrained = true;
  LinearPlant p(PaperFopdt(), kTs);
  auto sp = ParseSignal("step:from=0,to=1,at=0");
  ClosedLoopOptions cl;
  cl.duration = 2.0;
  DmcController free_dmc(PaperFopdt(), kTs, o);
  const double free_overshoot = SimulateClosedLoop(free_dmc, p, *sp, cl).metrics.overshoot_percent;
  o.y_max = 1.005;
  DmcController bounded(PaperFopdt(), kTs, o);
  const auto r = SimulateClosedLoop(bounded, p, *sp, cl);
  EXPECT_GT(free_overshoot, 3.0);
  EXPECT_LT(r.metrics.overshoot_percent, 0.6);
  EXPECT_NEAR(r.metrics.steady_state_error, 0.0, 1e-6);
  EXPECT_EQ(bounded.qp_failures(), 0);
}

TEST(DmcTest, RejectsBadInput) {
  DmcOptions o;
  o.M = 200;
  std::string error;
  EXPECT_FALSE(o.IsValid(&error));
  EXPECT_THAT(error, ::testing::HasSubstr("M <= P"));
  EXPECT_THROW(DmcController(PaperFopdt(), kTs, o), InvalidArgument);
  DmcOptions ok;
  const TransferFunction unstable = TransferFunction::Continuous({1.0}, {1.0, -1.0});
  EXPECT_THAT([&] { DmcController(unstable, kTs, ok); },
              ::testing::ThrowsMessage<InvalidArgument>(::testing::HasSubstr("stable")));
  EXPECT_THROW(DmcController(PaperArxModel(), 0.02, ok), InvalidArgument);
  EXPECT_THROW(DmcController(PaperFopdt(), -1.0, ok), InvalidArgument);
  DmcOptions bad_limits;
  bad_limits.limits.u_min = 1;
  bad_limits.limits.u_max = 0;
  EXPECT_THROW(DmcController(PaperFopdt(), kTs, bad_limits), InvalidArgument);
}

}  // namespace
}  // namespace pneumid
