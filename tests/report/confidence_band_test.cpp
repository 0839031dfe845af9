// Confidence bands of the step and Bode figures (figures.hpp, StepFigureOptions::confidence).
#include <memory>

#include <gtest/gtest.h>

#include "pneumid/common/check.hpp"
#include "pneumid/identify/identified_model_io.hpp"
#include "pneumid/identify/evaluation/model_uncertainty.hpp"
#include "pneumid/identify/parametric/parametric_model.hpp"
#include "pneumid/report/figures.hpp"

namespace pneumid {
namespace {

// y(t) = 0.8 y(t-1) + 0.3 u(t-1) with a covariance of (a1, b1); drawn discrete.
NamedModel FirstOrder(bool with_covariance) {
  PolynomialModel pm;
  pm.Ts = 0.1;
  pm.a = Eigen::Vector2d(1.0, -0.8);
  pm.b = {Eigen::Vector2d(0.0, 0.3)};
  pm.nk = {1};
  auto m = std::make_shared<IdentifiedModel>();
  m->method = "arx";
  m->structure = "ARX";
  m->params = ModelParamsFromJson(pm.ParamsJson());
  m->discrete = pm.ToTransferFunction(0);
  m->tf = *m->discrete;
  if (with_covariance)
    m->covariance = ParameterCovariance{{"a1", "b1"}, 1e-4 * Eigen::Matrix2d::Identity()};
  NamedModel nm{"arx", *m->discrete};
  nm.identified = m;
  return nm;
}

TEST(ConfidenceBandTest, StepFigureBandIsKStandardDeviations) {
  StepFigureOptions o;
  o.t_final = 2.0;
  o.amplitude = 2.0;
  o.confidence = 3.0;
  const NamedModel nm = FirstOrder(true);
  const Figure fig = StepResponseFigure({nm}, o);
  const Axes& ax = fig.axes(0);
  ASSERT_EQ(ax.bands.size(), 1u);
  const Band& b = ax.bands[0];
  EXPECT_EQ(b.label, "arx \u00b13 sd");
  UncertaintyOptions uo;
  uo.discrete = true;
  const Eigen::VectorXd sd = StepResponseStd(*nm.identified, b.x, uo);
  EXPECT_TRUE((b.upper - b.lower).isApprox(2.0 * 3.0 * 2.0 * sd, 1e-12));
  EXPECT_TRUE((0.5 * (b.upper + b.lower)).isApprox(ax.series[0].y, 1e-12));
  o.confidence = 0.0;
  EXPECT_TRUE(StepResponseFigure({nm}, o).axes(0).bands.empty());
  o.confidence = -1.0;
  EXPECT_THROW(StepResponseFigure({nm}, o), InvalidArgument);
}

TEST(ConfidenceBandTest, BodeFigureBandsOnMagnitudeAndPhase) {
  const NamedModel nm = FirstOrder(true);
  const Figure fig = BodeFigure({nm}, Eigen::VectorXd(), "Bode", 2.0);
  ASSERT_EQ(fig.axes(0).bands.size(), 1u);
  ASSERT_EQ(fig.axes(1).bands.size(), 1u);
  EXPECT_GT((fig.axes(1).bands[0].upper - fig.axes(1).bands[0].lower).maxCoeff(), 0.0);
  EXPECT_THROW(BodeFigure({nm}, Eigen::VectorXd(), "Bode", -1.0), InvalidArgument);
  EXPECT_FALSE(fig.ToSvg().empty());
}

TEST(ConfidenceBandTest, ModelWithoutCovarianceOrIdentifiedModelHasNoBand) {
  StepFigureOptions o;
  o.confidence = 3.0;
  NamedModel plain = FirstOrder(false);
  EXPECT_TRUE(StepResponseFigure({plain}, o).axes(0).bands.empty());
  plain.identified.reset();
  EXPECT_TRUE(StepResponseFigure({plain}, o).axes(0).bands.empty());
  EXPECT_TRUE(BodeFigure({plain}, Eigen::VectorXd(), "Bode", 3.0).axes(0).bands.empty());
}

}  // namespace
}  // namespace pneumid
