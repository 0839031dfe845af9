#include "pneumid/data/dataset.hpp"

#include <cmath>
#include <limits>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "pneumid/common/check.hpp"

namespace pneumid {
namespace {

using ::testing::AllOf;
using ::testing::HasSubstr;
using ::testing::ThrowsMessage;

TEST(DatasetTest, FromUniform) {
  Eigen::VectorXd u(4), y(4);
  u << 0, 1, 1, 1;
  y << 0, 0.5, 0.75, 0.875;
  const Dataset d = Dataset::FromUniform(0.01, u, y, 1.0, {"duty", "%"}, {"F", "N"});
  EXPECT_EQ(d.size(), 4);
  EXPECT_DOUBLE_EQ(d.time()[3], 1.03);
  EXPECT_NEAR(d.SampleTime(), 0.01, 1e-15);
  EXPECT_TRUE(d.IsUniform());
  EXPECT_EQ(d.input_channels()[0].name, "duty");
  EXPECT_EQ(d.output_channels()[0].unit, "N");
  EXPECT_EQ(d.time_channel().name, "t");
  EXPECT_EQ(d.SourceLine(0), 0);
  EXPECT_EQ(d.Where(2), "sample 2");
}

TEST(DatasetTest, DefaultChannelNames) {
  const Dataset d(Eigen::Vector3d(0, 1, 2), Eigen::MatrixXd::Zero(3, 2),
                  Eigen::MatrixXd::Zero(3, 1));
  EXPECT_EQ(d.input_channels()[0].name, "u1");
  EXPECT_EQ(d.input_channels()[1].name, "u2");
  EXPECT_EQ(d.output_channels()[0].name, "y");
}

TEST(DatasetTest, RejectsBadConstruction) {
  const Eigen::Vector3d t(0, 1, 2);
  EXPECT_THAT([&] { Dataset(t, Eigen::MatrixXd::Zero(2, 1), Eigen::MatrixXd::Zero(3, 1)); },
              ThrowsMessage<InvalidArgument>(HasSubstr("length mismatch")));
  EXPECT_THAT(
      [&] {
        Dataset(Eigen::Vector3d(0, 2, 1), Eigen::MatrixXd::Zero(3, 1), Eigen::MatrixXd::Zero(3, 1));
      },
      ThrowsMessage<InvalidArgument>(HasSubstr("not strictly increasing at sample 2")));
  Eigen::MatrixXd y = Eigen::MatrixXd::Zero(3, 1);
  y(1, 0) = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THAT([&] { Dataset(t, Eigen::MatrixXd::Zero(3, 1), y); },
              ThrowsMessage<InvalidArgument>(HasSubstr("output (1, 0) is not finite")));
  EXPECT_THROW(
      Dataset(t, Eigen::MatrixXd::Zero(3, 1), Eigen::MatrixXd::Zero(3, 1), {{"a", ""}, {"b", ""}}),
      InvalidArgument);
  EXPECT_THROW(Dataset::FromUniform(0.0, Eigen::VectorXd::Zero(3), Eigen::VectorXd::Zero(3)),
               InvalidArgument);
  EXPECT_THROW(Dataset::FromUniform(0.1, Eigen::VectorXd::Zero(3), Eigen::VectorXd::Zero(2)),
               InvalidArgument);
}

TEST(DatasetTest, ChannelAccessOutOfRange) {
  const Dataset d = Dataset::FromUniform(1.0, Eigen::VectorXd::Zero(3), Eigen::VectorXd::Zero(3));
  EXPECT_THROW(d.u(1), InvalidArgument);
  EXPECT_THROW(d.y(-1), InvalidArgument);
}

TEST(DatasetTest, UniformityWithinTolerance) {
  Eigen::VectorXd t(5);
  t << 0, 0.01, 0.02, 0.03005, 0.04;  // one interval 0.5 % long
  Dataset d(t, Eigen::MatrixXd::Zero(5, 1), Eigen::MatrixXd::Zero(5, 1));
  d.set_source("log.mat");
  EXPECT_FALSE(d.IsUniform(1e-3));
  EXPECT_TRUE(d.IsUniform(1e-2));
  EXPECT_NO_THROW(d.RequireUniform(1e-2));
  // Without line information the message names the sample.
  EXPECT_THAT([&] { d.RequireUniform(1e-3); },
              ThrowsMessage<DataError>(AllOf(HasSubstr("log.mat: sample 3"),
                                             HasSubstr("column 't'"), HasSubstr("resample"))));
}

TEST(DatasetTest, SampleTimeNeedsTwoSamples) {
  const Dataset d(Eigen::VectorXd::Zero(1), Eigen::MatrixXd::Zero(1, 1),
                  Eigen::MatrixXd::Zero(1, 1));
  EXPECT_THROW(d.SampleTime(), InvalidArgument);
  EXPECT_TRUE(d.IsUniform());
}

TEST(DatasetTest, RequireSamplesNamesSourceAndMethod) {
  Dataset d = Dataset::FromUniform(1.0, Eigen::VectorXd::Zero(3), Eigen::VectorXd::Zero(3));
  d.set_source("run1.csv");
  EXPECT_THAT(
      [&] { d.RequireSamples(4, "correlation analysis"); },
      ThrowsMessage<DataError>(AllOf(HasSubstr("run1.csv"), HasSubstr("correlation analysis"),
                                     HasSubstr("at least 4 samples, the data has 3"))));
}

TEST(DatasetTest, SourceLinesMap) {
  Dataset d = Dataset::FromUniform(1.0, Eigen::VectorXd::Zero(6), Eigen::VectorXd::Zero(6));
  d.set_source("f.csv");
  d.set_source_lines({0, 3}, {2, 10});
  EXPECT_EQ(d.SourceLine(0), 2);
  EXPECT_EQ(d.SourceLine(2), 4);
  EXPECT_EQ(d.SourceLine(3), 10);
  EXPECT_EQ(d.SourceLine(5), 12);
  EXPECT_EQ(d.Where(4), "f.csv:11");
  EXPECT_THROW(d.SourceLine(6), InvalidArgument);
  EXPECT_THROW(d.set_source_lines({1}, {2}), InvalidArgument);
  EXPECT_THROW(d.set_source_lines({0, 0}, {2, 3}), InvalidArgument);
}

}  // namespace
}  // namespace pneumid
