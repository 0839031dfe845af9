#include "pneumid/identify/parametric/arx_streaming.hpp"

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
  const ArxResult mem = EstimateArx(y, Eigen::MatrixXd(u), 0.01, ArxOptions{});
  // Block sizes that put block boundaries inside the regressor history (1, 2),
  // at odd places (997) and none (one block holds the file).
  for (const std::size_t block_rows : {std::size_t{1}, std::size_t{2}, std::size_t{997},
                                       std::size_t{1} << 16}) {
    o.block_rows = block_rows;
    int calls = 0;
    double last_progress = 0;
    o.progress = [&](double p) {
      EXPECT_GE(p, last_progress);
      last_progress = p;
      ++calls;
    };
    const StreamingArxResult r = EstimateArxFromFile(path, o);
    EXPECT_EQ(r.num_samples, n);
    EXPECT_EQ(calls, (n + static_cast<Eigen::Index>(block_rows) - 1) /
                         static_cast<Eigen::Index>(block_rows));
    EXPECT_DOUBLE_EQ(last_progress, 1.0);
    EXPECT_GT(r.bytes, 0.0);
    EXPECT_NEAR(r.arx.model.Ts, 0.01, 1e-12);
    EXPECT_LT((r.arx.model.Parameters() - mem.model.Parameters()).norm(),
              1e-12 * mem.model.Parameters().norm())
        << "block_rows = " << block_rows;
  }
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
    // The data area's message: the unknown column and the available ones.
    EXPECT_THAT(e.what(), HasSubstr("input column 'v'"));
    EXPECT_THAT(e.what(), HasSubstr("'t', 'u', 'y'"));
  }
  EXPECT_THROW(EstimateArxFromFile(TempPath("missing.csv"), StreamingArxOptions{}), DataError);
  o.input_column = "u";
  o.block_rows = 0;
  EXPECT_THAT([&] { EstimateArxFromFile(path, o); },
              ::testing::ThrowsMessage<InvalidArgument>(HasSubstr("block_rows must be >= 1")));
  o.block_rows = 1 << 16;
  o.arx.nb = {3, 3};
  o.arx.nk = {1, 1};
  EXPECT_THROW(EstimateArxFromFile(path, o), InvalidArgument);
  std::remove(path.c_str());
}

}  // namespace
}  // namespace pneumid
