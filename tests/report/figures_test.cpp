// Tests of the ready-made figures (include/pneumid/report/figures.hpp).
#include "pneumid/report/figures.hpp"

#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "pneumid/common/check.hpp"
#include "pneumid/models/model_file.hpp"

namespace pneumid {
namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;

fs::path OutDir() {
  fs::path d = fs::path(PNEUMID_BINARY_DIR) / "test-output" / "report";
  fs::create_directories(d);
  return d;
}

bool IsPng(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  char sig[8] = {};
  in.read(sig, 8);
  return in && std::string(sig, 8) == std::string("\x89PNG\r\n\x1a\n", 8);
}

// The step test of the paper in closed form: u steps from 0.61 to 82 % at
// t = 0.5 s and a first-order plant K / (tau s + 1) answers from 0 N.
Dataset FirstOrderStepData(double K, double tau) {
  const double Ts = 0.01;
  const int n = 301;
  Eigen::VectorXd u(n), y(n);
  for (int k = 0; k < n; ++k) {
    const double t = k * Ts;
    u[k] = t >= 0.5 - 1e-12 ? 82.0 : 0.61;
    // zero-order hold: the step applied at sample 50 shows from sample 51 on.
    y[k] = t > 0.5 + 1e-12 ? K * (82.0 - 0.61) * (1.0 - std::exp(-(t - 0.5) / tau)) : 0.0;
  }
  return Dataset::FromUniform(Ts, u, y, 0.0, {"u", "%"}, {"F", "N"});
}

TEST(FiguresTest, SimulateOnDataMatchesClosedFormFirstOrder) {
  // Closed form of a first-order lag driven by a step, exact at the samples
  // for a zero-order-hold input.
  const double K = 1.6, tau = 0.245;
  const Dataset data = FirstOrderStepData(K, tau);
  const Eigen::VectorXd yhat = SimulateOnData(TransferFunction::Fopdt(K, tau, 0.0), data);
  ASSERT_EQ(yhat.size(), data.size());
  for (Eigen::Index k = 0; k < data.size(); ++k)
    EXPECT_NEAR(yhat[k], data.y()[k], 1e-9 * 130.0) << "k = " << k;
}

TEST(FiguresTest, SimulateOnDataRejectsMismatchedSampleTime) {
  const Dataset data = FirstOrderStepData(1.6, 0.245);
  const TransferFunction g = TransferFunction::Discrete({0.0, 0.5}, {1.0, -0.5}, 0.02);
  EXPECT_THAT([&] { SimulateOnData(g, data); },
              ::testing::ThrowsMessage<InvalidArgument>(HasSubstr("sample time")));
}

TEST(FiguresTest, ResidualCorrelationOfAlternatingSequence) {
  // e = +1, -1, +1, ...: r_ee(k)/r_ee(0) = (-1)^k (N - k) / N exactly.
  const int n = 200;
  Eigen::VectorXd e(n);
  for (int k = 0; k < n; ++k) e[k] = k % 2 == 0 ? 1.0 : -1.0;
  const ResidualCorrelation c = ComputeResidualCorrelation(e, e, 10, 0.99);
  ASSERT_EQ(c.autocorr.size(), 11);
  for (int k = 0; k <= 10; ++k)
    EXPECT_NEAR(c.autocorr[k], (k % 2 == 0 ? 1.0 : -1.0) * (n - k) / n, 1e-12);
  // With u = e the cross-correlation equals the autocorrelation, symmetric.
  EXPECT_NEAR(c.crosscorr[10], 1.0, 1e-12);
  EXPECT_NEAR(c.crosscorr[13], c.autocorr[3], 1e-12);
  EXPECT_NEAR(c.crosscorr[7], c.autocorr[3], 1e-12);
  // z_{0.995} = 2.5758293035489 (standard normal quantile).
  EXPECT_NEAR(c.bound, 2.5758293035489 / std::sqrt(200.0), 1e-9);
  EXPECT_DOUBLE_EQ(c.auto_outside, 1.0);
}

TEST(FiguresTest, ResidualCorrelationBadInput) {
  const Eigen::VectorXd e = Eigen::VectorXd::LinSpaced(50, 0.0, 1.0);
  EXPECT_THAT([&] { ComputeResidualCorrelation(e, e.head(10)); },
              ::testing::ThrowsMessage<InvalidArgument>(HasSubstr("differ in length")));
  EXPECT_THROW(ComputeResidualCorrelation(e, e, 0), InvalidArgument);
  EXPECT_THROW(ComputeResidualCorrelation(e, e, 60), InvalidArgument);
  EXPECT_THROW(ComputeResidualCorrelation(e, e, 5, 1.0), InvalidArgument);
  EXPECT_THAT([&] { ComputeResidualCorrelation(Eigen::VectorXd::Ones(50), e); },
              ::testing::ThrowsMessage<InvalidArgument>(HasSubstr("constant")));
}

TEST(FiguresTest, AllFiguresRenderToPngAndSvg) {
  const Dataset data = FirstOrderStepData(1.6, 0.245);
  const std::vector<NamedModel> models = {
      {"FOPDT (reaction curve)", PaperFopdtModel()},
      {"ARX(3,3,1)", PaperArxModel()},
  };
  StepFigureOptions so;
  so.amplitude = 82.0 - 0.61;
  so.t_final = 2.0;
  const Figure step = StepResponseFigure(models, so);
  ASSERT_EQ(step.axes(0).series.size(), 2u);
  const Figure cmp = ModelComparisonFigure(data, models);
  EXPECT_THAT(cmp.axes(0).series[1].label, HasSubstr("fit"));
  Eigen::VectorXd e = data.y() - SimulateOnData(PaperArxModel(), data);
  e += Eigen::VectorXd::LinSpaced(e.size(), 0.0, 1.0).array().sin().matrix();
  const Figure res = ResidualFigure(ComputeResidualCorrelation(e, data.u()));
  const Figure bode = BodeFigure(models);
  Eigen::VectorXd t = Eigen::VectorXd::LinSpaced(300, 0.0, 2.99);
  Eigen::VectorXd r = (t.array() >= 0.5).cast<double>() * 100.0;
  Eigen::VectorXd y1 =
      (t.array() >= 0.5).select(100.0 * (1.0 - (-(t.array() - 0.5) / 0.1).exp()), 0.0);
  Eigen::VectorXd y2 =
      (t.array() >= 0.5).select(100.0 * (1.0 - (-(t.array() - 0.5) / 0.08).exp()), 0.0);
  ClosedLoopFigureOptions co;
  co.disturbance_time = 2.0;
  const Figure loop = ClosedLoopFigure(
      t, r, {{"conventional (M = 5)", y1, y1 / 1.6}, {"modified (M = 10)", y2, y2 / 1.6}}, co);
  const std::vector<std::pair<std::string, const Figure*>> all = {{"fig_step", &step},
                                                                  {"fig_compare", &cmp},
                                                                  {"fig_resid", &res},
                                                                  {"fig_bode", &bode},
                                                                  {"fig_loop", &loop}};
  for (const auto& [name, fig] : all) {
    const fs::path png = OutDir() / (name + ".png");
    fig->Save(png.string());
    EXPECT_TRUE(IsPng(png)) << name;
    EXPECT_GT(fs::file_size(png), 15000u) << name;
    const std::string svg = fig->ToSvg(name);
    EXPECT_THAT(svg, HasSubstr("<desc>")) << name;
  }
  EXPECT_THAT(loop.ToSvg(), HasSubstr("set-point"));
  EXPECT_THAT(bode.ToSvg(), HasSubstr("Phase [deg]"));
}

// Impulse response of the paper's FOPDT, K/tau exp(-(t - theta)/tau) for
// t > theta: the curve peaks at K/tau (within one sample of decay, dt = tau/200)
// and the discrete ARX model is drawn as a staircase.
TEST(FiguresTest, ImpulseResponseFigureDrawsEachModel) {
  StepFigureOptions so;
  so.t_final = 2.0;
  so.title = "Impulse response";
  const Figure fig =
      ImpulseResponseFigure({{"FOPDT", PaperFopdtModel()}, {"ARX(3,3,1)", PaperArxModel()}}, so);
  ASSERT_EQ(fig.axes(0).series.size(), 2u);
  const Curve& fopdt = fig.axes(0).series[0];
  EXPECT_NEAR(fopdt.y.maxCoeff() / (1.6 / 0.245), 1.0, 0.01);
  EXPECT_GE(fopdt.x.maxCoeff(), 2.0);
  EXPECT_FALSE(fopdt.stairs);
  EXPECT_TRUE(fig.axes(0).series[1].stairs);
  EXPECT_THAT(fig.ToSvg(), HasSubstr("Impulse response"));
  EXPECT_THAT(
      [] { ImpulseResponseFigure({}); },
      ::testing::ThrowsMessage<InvalidArgument>(HasSubstr("ImpulseResponseFigure: no models")));
}

TEST(FiguresTest, BodeOfDiscreteModelStopsAtNyquist) {
  const Figure bode = BodeFigure({{"ARX", PaperArxModel()}});
  const auto& x = bode.axes(0).series[0].x;
  EXPECT_LE(x.maxCoeff(), M_PI / 0.01 * (1.0 + 1e-9));
}

TEST(FiguresTest, BadArgumentsThrow) {
  EXPECT_THAT([] { StepResponseFigure({}); },
              ::testing::ThrowsMessage<InvalidArgument>(HasSubstr("no models")));
  StepFigureOptions so;
  so.amplitude = 0.0;
  EXPECT_THAT(
      [&] {
        StepResponseFigure({{"a", PaperFopdtModel()}}, so);
      },
      ::testing::ThrowsMessage<InvalidArgument>(HasSubstr("amplitude")));
  const Eigen::VectorXd t = Eigen::VectorXd::LinSpaced(10, 0.0, 1.0);
  EXPECT_THAT(
      [&] {
        ClosedLoopFigure(t, t, {{"x", t.head(5), t}});
      },
      ::testing::ThrowsMessage<InvalidArgument>(HasSubstr("'x'")));
  ComparisonFigureOptions co;
  co.output = 3;
  EXPECT_THAT(
      [&] {
        ModelComparisonFigure(FirstOrderStepData(1, 1), {{"a", PaperFopdtModel()}}, co);
      },
      ::testing::ThrowsMessage<InvalidArgument>(HasSubstr("output channel 3")));
}

}  // namespace
}  // namespace pneumid
