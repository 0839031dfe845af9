#include "pneumid/identify/arx_streaming.hpp"

#include <cstdio>
#include <fstream>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "parametric_test_util.hpp"
#include "pneumid/common/check.hpp"

namespace pneumid {
namespace {

using ::testing::HasSubstr;

std::string TempPath(const std::string& name) {
  return std::string(PNEUMID_BINARY_DIR) + "/arx_streaming_" + name;
}

TEST(ArxStreaming, EqualsTheInMemoryFit) {
  const PolynomialModel truth = testing::PaperArx();
  const Eigen::Index n = 20000;
  const Eigen::VectorXd u = testing::Prbs(n, 10, 90, 3, 4);
  const Eigen::VectorXd y = testing::SimulateArx(truth, u, testing::WhiteNoise(n, 0.5, 5));
  const std::string path = TempPath("data.csv");
  {
    std::ofstream f(path);
    f << "# generated\nt,u,F\n";
    f.precision(17);
    for (Eigen::Index k = 0; k < n; ++k) f << k * 0.01 << "," << u[k] << "," << y[k] << "\n";
  }
  StreamingArxOptions o;
  o.output_column = "F";
  o.chunk_bytes = 4096;  // many chunk boundaries inside lines
  double last_progress = 0;
  o.progress = [&](double p) { last_progress = p; };
  const StreamingArxResult r = EstimateArxFromFile(path, o);
  EXPECT_EQ(r.num_samples, n);
  EXPECT_DOUBLE_EQ(last_progress, 1.0);
  const ArxResult mem = EstimateArx(y, Eigen::MatrixXd(u), 0.01, ArxOptions{});
  EXPECT_NEAR(r.arx.model.Ts, 0.01, 1e-12);
  EXPECT_LT((r.arx.model.Parameters() - mem.model.Parameters()).norm(),
            1e-12 * mem.model.Parameters().norm());
  std::remove(path.c_str());
}

TEST(ArxStreaming, ErrorsNameFileLineAndColumn) {
  const std::string path = TempPath("bad.csv");
  {
    std::ofstream f(path);
    f << "t;u;y\n0;1;2\n0.01;1;2\n0.02;abc;2\n";
  }
  StreamingArxOptions o;
  try {
    EstimateArxFromFile(path, o);
    FAIL();
  } catch (const DataError& e) {
    EXPECT_THAT(e.what(), HasSubstr(":4: column 'u': not a number: 'abc'"));
  }
  o.input_column = "v";
  try {
    EstimateArxFromFile(path, o);
    FAIL();
  } catch (const DataError& e) {
    EXPECT_THAT(e.what(), HasSubstr("input column 'v' not found (columns: t, u, y)"));
  }
  EXPECT_THROW(EstimateArxFromFile(TempPath("missing.csv"), StreamingArxOptions{}), DataError);
  o.arx.nb = {3, 3};
  o.arx.nk = {1, 1};
  EXPECT_THROW(EstimateArxFromFile(path, o), InvalidArgument);
  std::remove(path.c_str());
}

}  // namespace
}  // namespace pneumid
