// Tests of the figure API (include/pneumid/report/plot.hpp).
#include "pneumid/report/plot.hpp"

#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "pneumid/common/check.hpp"

namespace pneumid {
namespace {

namespace fs = std::filesystem;

std::string ReadFile(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::ostringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

fs::path OutDir() {
  fs::path d = fs::path(PNEUMID_BINARY_DIR) / "test-output" / "report";
  fs::create_directories(d);
  return d;
}

Figure SampleFigure() {
  const int n = 201;
  Eigen::VectorXd t = Eigen::VectorXd::LinSpaced(n, 0.0, 2.0);
  Eigen::VectorXd y = 129.0 * (1.0 - (-t.array() / 0.245).exp());
  Eigen::VectorXd u = Eigen::VectorXd::Constant(n, 82.0);
  Figure fig(2);
  fig.title = "Step test";
  Axes& a = fig.axes(0);
  a.ylabel = "Force F [N]";
  a.AddLine(t, y, "FOPDT model");
  a.AddLine(t, y.array() * 0.98, "measured", LineStyle::kDotted);
  a.AddHorizontalLine(129.0, "final value");
  a.AddBand(t, y.array() - 5.0, y.array() + 5.0, "95 % band");
  Axes& b = fig.axes(1);
  b.xlabel = "Time t [s]";
  b.ylabel = "Duty cycle u [%]";
  b.AddStairs(t, u, "input");
  return fig;
}

TEST(PlotTest, WritesPngWithSignatureAndPlausibleSize) {
  const fs::path p = OutDir() / "plot_sample.png";
  fs::remove(p);
  SampleFigure().Save(p.string());
  ASSERT_TRUE(fs::exists(p));
  const std::string data = ReadFile(p);
  ASSERT_GE(data.size(), 8u);
  EXPECT_EQ(data.substr(0, 8), std::string("\x89PNG\r\n\x1a\n", 8));
  // A 960 x 700 plot with lines and text compresses to tens of kB; a blank
  // page would be about 3 kB.
  EXPECT_GT(data.size(), 10000u);
  // IHDR: width and height (big endian) at bytes 16..23.
  auto be32 = [&](std::size_t o) {
    return (static_cast<unsigned>(static_cast<unsigned char>(data[o])) << 24) |
           (static_cast<unsigned>(static_cast<unsigned char>(data[o + 1])) << 16) |
           (static_cast<unsigned>(static_cast<unsigned char>(data[o + 2])) << 8) |
           static_cast<unsigned>(static_cast<unsigned char>(data[o + 3]));
  };
  EXPECT_EQ(be32(16), 960u);
  EXPECT_EQ(be32(20), 2u * 330u + 40u);
}

TEST(PlotTest, WritesSvgByExtension) {
  const fs::path p = OutDir() / "plot_sample.svg";
  SampleFigure().Save(p.string());
  const std::string svg = ReadFile(p);
  EXPECT_THAT(svg, ::testing::HasSubstr("<svg"));
  EXPECT_THAT(svg, ::testing::HasSubstr("</svg>"));
  EXPECT_GT(svg.size(), 5000u);
}

TEST(PlotTest, InMemorySvgCarriesLabelsAndUniqueIds) {
  const std::string svg = SampleFigure().ToSvg("stepfig");
  EXPECT_EQ(svg.rfind("<svg", 0), 0u) << "no XML prolog expected";
  EXPECT_THAT(svg, ::testing::HasSubstr("<title>Step test</title>"));
  EXPECT_THAT(svg, ::testing::HasSubstr("Force F [N]"));
  EXPECT_THAT(svg, ::testing::HasSubstr("Time t [s]"));
  EXPECT_THAT(svg, ::testing::HasSubstr("line: FOPDT model"));
  EXPECT_THAT(svg, ::testing::HasSubstr("band: 95 % band"));
  EXPECT_THAT(svg, ::testing::HasSubstr("reference: final value"));
  // Every id carries the prefix.
  std::size_t pos = 0, ids = 0;
  while ((pos = svg.find(" id=\"", pos)) != std::string::npos) {
    EXPECT_EQ(svg.compare(pos + 5, 8, "stepfig-"), 0) << svg.substr(pos, 40);
    pos += 5;
    ++ids;
  }
  EXPECT_GT(ids, 0u);
}

TEST(PlotTest, PlotLiteralDoublesTheEscapeCharacter) {
  EXPECT_EQ(PlotLiteral("models.json#fit-p1d"), "models.json##fit-p1d");
  EXPECT_EQ(PlotLiteral("##"), "####");
  EXPECT_EQ(PlotLiteral("no escape"), "no escape");
  // The figure's plain-text description shows the literal text again.
  Figure fig(1);
  fig.title = PlotLiteral("MPC (model a.json#fit-p1d)");
  EXPECT_THAT(DescribeFigure(fig), ::testing::HasSubstr("MPC (model a.json#fit-p1d)"));
}

TEST(PlotTest, LogAxisAndSingleSubplot) {
  Eigen::VectorXd w = Eigen::VectorXd::LinSpaced(100, -1.0, 3.0);
  w = w.unaryExpr([](double e) { return std::pow(10.0, e); });
  Eigen::VectorXd mag = -10.0 * (1.0 + w.array().square()).log10();
  Figure fig(1);
  fig.axes(0).log_x = true;
  fig.axes(0).xlabel = "Frequency [rad/s]";
  fig.axes(0).ylabel = "Magnitude [dB]";
  fig.axes(0).AddLine(w, mag, "1/(s+1)");
  const fs::path p = OutDir() / "plot_log.png";
  fig.Save(p.string());
  EXPECT_GT(fs::file_size(p), 5000u);
}

TEST(PlotTest, ConstantDataStillPlots) {
  Figure fig;
  fig.axes(0).AddLine(Eigen::Vector2d(0.0, 1.0), Eigen::Vector2d(3.0, 3.0), "flat");
  const fs::path p = OutDir() / "plot_flat.png";
  fig.Save(p.string());
  EXPECT_GT(fs::file_size(p), 1000u);
}

TEST(PlotTest, BadArgumentsThrowWithClearMessages) {
  EXPECT_THROW(Figure(0), InvalidArgument);
  EXPECT_THROW(Figure(4), InvalidArgument);
  Figure fig;
  EXPECT_THROW(fig.axes(1), InvalidArgument);
  EXPECT_THAT([&] { fig.axes(0).AddLine(Eigen::Vector3d(1, 2, 3), Eigen::Vector2d(1, 2)); },
              ::testing::ThrowsMessage<InvalidArgument>(::testing::HasSubstr("same length")));
  EXPECT_THAT([&] { fig.Save((OutDir() / "empty.png").string()); },
              ::testing::ThrowsMessage<InvalidArgument>(::testing::HasSubstr("no data")));
  fig.axes(0).AddLine(Eigen::Vector2d(0, 1), Eigen::Vector2d(0, 1));
  EXPECT_THAT([&] { fig.Save((OutDir() / "plot.gif").string()); },
              ::testing::ThrowsMessage<InvalidArgument>(::testing::HasSubstr(".png or .svg")));
  EXPECT_THAT([&] { fig.Save("/nonexistent-dir/x/plot.png"); },
              ::testing::ThrowsMessage<DataError>(::testing::HasSubstr("cannot open")));
  fig.options().width = 10;
  EXPECT_THAT([&] { fig.Save((OutDir() / "narrow.png").string()); },
              ::testing::ThrowsMessage<InvalidArgument>(::testing::HasSubstr("width")));
}

TEST(PlotTest, EnumStringsRoundTrip) {
  for (auto s : {LineStyle::kSolid, LineStyle::kDashed, LineStyle::kDotted})
    EXPECT_EQ(LineStyleFromString(ToString(s)), s);
  EXPECT_EQ(ImageFormatFromString("SVG"), ImageFormat::kSvg);
  EXPECT_EQ(ImageFormatFromPath("a/b/fig.PNG"), ImageFormat::kPng);
  EXPECT_THROW(LineStyleFromString("wavy"), InvalidArgument);
  EXPECT_THROW(ImageFormatFromString("gif"), InvalidArgument);
}

}  // namespace
}  // namespace pneumid
