// GPC: CARIMA form, Diophantine predictor against simulation, and the
// conditions under which GPC and unconstrained DMC give the same moves
// (see gpc.hpp): noise-free nominal plant with any T; model mismatch and
// disturbances with T = A only.
#include "pneumid/control/gpc.hpp"

#include <cmath>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "pneumid/common/check.hpp"
#include "pneumid/control/closed_loop.hpp"
#include "pneumid/control/dmc.hpp"
#include "pneumid/models/model_file.hpp"
#include "pneumid/plant/linear_plant.hpp"
#include "pneumid/plant/signal.hpp"

namespace pneumid {
namespace {

constexpr double kTs = 0.01;

TEST(CarimaTest, ArxModelPolynomials) {
  // Paper Eq. 5: A = 1 - 0.6087 q^-1 - 0.2702 q^-2 - 0.06021 q^-3,
  // q^-1 B = 0.03938 q^-1 + 0.04506 q^-2 + 0.01286 q^-3.
  const CarimaModel c = ToCarima(PaperArxModel(), kTs);
  ASSERT_EQ(c.A.size(), 4);
  EXPECT_NEAR(c.A(1), -0.60870, 1e-12);
  EXPECT_NEAR(c.A(2), -0.27020, 1e-12);
  EXPECT_NEAR(c.A(3), -0.06021, 1e-12);
  ASSERT_EQ(c.B.size(), 3);
  EXPECT_NEAR(c.B(0), 0.03938, 1e-12);
  EXPECT_NEAR(c.B(1), 0.04506, 1e-12);
  EXPECT_NEAR(c.B(2), 0.01286, 1e-12);
  // A direct feedthrough is rejected.
  const TransferFunction biproper = TransferFunction::Discrete({1.0, 0.5}, {1.0, -0.5}, kTs);
  EXPECT_THROW(ToCarima(biproper, kTs), InvalidArgument);
}

TEST(GpcTest, DynamicMatrixIsTheStepResponse) {
  GpcOptions o;
  o.N1 = 1;
  o.N2 = 30;
  o.Nu = 4;
  o.lambda = 0.3;
  GpcController gpc(PaperArxModel(), kTs, o);
  const Eigen::MatrixXd A =
      DynamicMatrix(PredictionModel(PaperArxModel(), kTs).StepResponse(40), 30, 4);
  EXPECT_LT((gpc.dynamic_matrix() - A).cwiseAbs().maxCoeff(), 1e-12);
}

TEST(GpcTest, PredictorMatchesSimulationWithTFilter) {
  // Drive the ARX plant with an arbitrary input history, then compare the
  // free response f_j (future moves zero) with the plant simulated forward
  // with the input held: the Diophantine predictor is exact for a
  // noise-free plant, for T = 1 and for a filter T = 1 - 0.8 q^-1.
  for (bool filter : {false, true}) {
    GpcOptions o;
    o.N1 = 2;
    o.N2 = 25;
    o.Nu = 3;
    o.lambda = 1.0;
    if (filter) {
      o.t_polynomial.resize(2);
      o.t_polynomial << 1.0, -0.8;
    }
    GpcController gpc(PaperArxModel(), kTs, o);
    LinearPlant plant(PaperArxModel(), kTs);
    gpc.Reset(0.0, 0.0);
    double u = 0.0;
    for (int k = 0; k < 40; ++k) {
      const double y = plant.Measure();
      // GPC acting on a varying set-point makes an irregular input history.
      u = gpc.Update(std::sin(0.3 * k) * 10.0, y);
      plant.Advance(u);
    }
    // Free response from the next sample: Update computes it with Delta u(t) = 0 assumed.
    const double y = plant.Measure();
    gpc.Update(0.0, y);  // computes the free response at t
    const Eigen::VectorXd f = gpc.free_response();
    // Simulate forward holding u at its value before this last Update.
    LinearPlant copy = plant;
    for (int j = 1; j <= o.N2; ++j) {
      copy.Advance(u);
      if (j >= o.N1)
        EXPECT_NEAR(f(j - o.N1), copy.Measure(), 1e-9) << "j = " << j << " T filter " << filter;
    }
  }
}

// Runs DMC and GPC on copies of the same scenario and returns max |u_dmc - u_gpc|.
double MaxMoveDifference(const TransferFunction& model, const TransferFunction& plant_model,
                         bool t_equals_a, const std::vector<LoadStep>& loads, double* max_u) {
  DmcOptions d;
  d.P = 60;
  d.M = 5;
  d.lambda = 2.25;
  GpcOptions g;
  g.N1 = 1;
  g.N2 = 60;
  g.Nu = 5;
  g.lambda = 2.25;
  g.t_equals_a = t_equals_a;
  DmcController dmc(model, kTs, d);
  GpcController gpc(model, kTs, g);
  LinearPlant p1(plant_model, kTs), p2(plant_model, kTs);
  auto sp = ParseSignal("staircase:levels=0 1 3 2,dwell=0.4");
  ClosedLoopOptions cl;
  cl.duration = 1.6;
  cl.load_steps = loads;
  const auto r1 = SimulateClosedLoop(dmc, p1, *sp, cl);
  const auto r2 = SimulateClosedLoop(gpc, p2, *sp, cl);
  if (max_u) *max_u = r1.u.cwiseAbs().maxCoeff();
  return (r1.u - r2.u).cwiseAbs().maxCoeff();
}

TEST(GpcDmcEquivalenceTest, NominalNoiseFreeAnyT) {
  // Plant = model, no disturbance, both at rest: identical moves for T = 1
  // and T = A (DMC's model horizon lets its step response settle to 1e-9).
  for (const TransferFunction& model :
       {PaperArxModel(), TransferFunction::Fopdt(1.6, 0.245, 0.001)}) {
    double umax = 0.0;
    const double diff_t1 = MaxMoveDifference(model, model, false, {}, &umax);
    EXPECT_GT(umax, 1.0);
    EXPECT_LT(diff_t1, 1e-9 * umax);
    const double diff_ta = MaxMoveDifference(model, model, true, {}, &umax);
    EXPECT_LT(diff_ta, 1e-9 * umax);
  }
}

TEST(GpcDmcEquivalenceTest, MismatchAndLoadNeedTEqualsA) {
  // Controller from the FOPDT, plant = ARX, load step: DMC's bias correction
  // is GPC's predictor with T = A, not with T = 1.
  const TransferFunction fopdt = TransferFunction::Fopdt(1.6, 0.245, 0.001);
  const std::vector<LoadStep> loads = {{1.0, -0.5}};
  double umax = 0.0;
  const double diff_ta = MaxMoveDifference(fopdt, PaperArxModel(), true, loads, &umax);
  EXPECT_GT(umax, 1.0);
  EXPECT_LT(diff_ta, 1e-9 * umax);
  const double diff_t1 = MaxMoveDifference(fopdt, PaperArxModel(), false, loads, &umax);
  EXPECT_GT(diff_t1, 1e-3 * umax);
}

TEST(GpcTest, OffsetFreeWithTEqualsOne) {
  GpcOptions g;
  g.N2 = 126;
  g.Nu = 5;
  g.lambda = 2.25;
  GpcController gpc(TransferFunction::Fopdt(1.6, 0.245, 0.001), kTs, g);
  LinearPlant plant(PaperArxModel(), kTs);
  auto sp = ParseSignal("step:from=0,to=50,at=0.1");
  ClosedLoopOptions cl;
  cl.duration = 4.0;
  cl.load_steps = {{2.0, 10.0}};
  const auto r = SimulateClosedLoop(gpc, plant, *sp, cl);
  EXPECT_NEAR(r.metrics.steady_state_error, 0.0, 1e-4);
  EXPECT_GT(r.metrics.load_peak_deviation, 1.0);
  EXPECT_LT(r.metrics.load_recovery_time, 1.0);
}

TEST(GpcTest, RejectsBadInput) {
  GpcOptions o;
  o.N1 = 0;
  EXPECT_THROW(GpcController(PaperArxModel(), kTs, o), InvalidArgument);
  GpcOptions t;
  t.t_polynomial.resize(2);
  t.t_polynomial << 1.0, -1.5;  // root at 1.5: unstable filter
  EXPECT_THAT([&] { GpcController(PaperArxModel(), kTs, t); },
              ::testing::ThrowsMessage<InvalidArgument>(::testing::HasSubstr("unit circle")));
  GpcOptions nm;
  nm.t_polynomial.resize(2);
  nm.t_polynomial << 2.0, -0.5;
  EXPECT_THROW(GpcController(PaperArxModel(), kTs, nm), InvalidArgument);
  EXPECT_THROW(GpcController(PaperArxModel(), 0.02, GpcOptions{}), InvalidArgument);
}

}  // namespace
}  // namespace pneumid
