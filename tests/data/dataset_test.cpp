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

TEST(DatasetTest, CopiesShareTheSamples) {
  Dataset d(Eigen::VectorXd::LinSpaced(5, 0, 4), Eigen::MatrixXd::Random(5, 2),
            Eigen::MatrixXd::Random(5, 1));
  d.set_source("a.csv");
  Dataset copy = d;
  EXPECT_EQ(copy.time().data(), d.time().data());
  EXPECT_EQ(copy.inputs().data(), d.inputs().data());
  // Metadata stays per object.
  copy.set_source("b.csv");
  EXPECT_EQ(d.source(), "a.csv");
  const std::vector<Dataset> several{d, d};
  EXPECT_EQ(several[1].outputs().data(), d.outputs().data());
  // A default dataset is empty, also after being moved from.
  Dataset moved = std::move(copy);
  EXPECT_EQ(moved.size(), 5);
  EXPECT_EQ(Dataset().size(), 0);
  EXPECT_EQ(Dataset().num_inputs(), 0);
}

TEST(DatasetTest, SelectChannels) {
  Eigen::MatrixXd u(4, 2), y(4, 2);
  u << 1, 10, 2, 20, 3, 30, 4, 40;
  y << 5, 50, 6, 60, 7, 70, 8, 80;
  Dataset d(Eigen::VectorXd::LinSpaced(4, 0, 3), u, y, {{"a", "%"}, {"b", "V"}},
            {{"p", "N"}, {"q", "m"}});
  d.set_source("s.csv");
  d.set_source_lines({0}, {3});
  const Dataset all = d.SelectChannels({0, 1}, {0, 1});
  EXPECT_EQ(all.inputs().data(), d.inputs().data());  // shared, not copied
  const Dataset one = d.SelectChannels({1}, {0});
  EXPECT_EQ(one.num_inputs(), 1);
  EXPECT_EQ(one.num_outputs(), 1);
  EXPECT_EQ(one.u(), u.col(1));
  EXPECT_EQ(one.y(), y.col(0));
  EXPECT_EQ(one.input_channels()[0].name, "b");
  EXPECT_EQ(one.output_channels()[0].unit, "N");
  EXPECT_EQ(one.Where(2), "s.csv:5");
  EXPECT_EQ(d.SelectChannels({}, {1}).num_inputs(), 0);
  EXPECT_THAT([&] { d.SelectChannels({2}, {0}); },
              ThrowsMessage<InvalidArgument>(HasSubstr("input 2 out of range [0, 2)")));
}

TEST(DatasetTest, UniformityFastPathAgreesWithTheMedianTest) {
  // Intervals 0.01 with one interval off by 2e-5 (0.2 %): not uniform at
  // 0.1 %, uniform at 0.5 %; all intervals equal: uniform at tolerance 0.
  Eigen::VectorXd t = Eigen::VectorXd::LinSpaced(101, 0.0, 1.0);
  const Dataset exact(t, Eigen::MatrixXd::Zero(101, 1), Eigen::MatrixXd::Zero(101, 1));
  EXPECT_TRUE(exact.IsUniform(1e-9));
  for (Eigen::Index i = 50; i < 101; ++i) t[i] += 2e-5;
  Dataset jitter(t, Eigen::MatrixXd::Zero(101, 1), Eigen::MatrixXd::Zero(101, 1));
  jitter.set_source("j.csv");
  EXPECT_FALSE(jitter.IsUniform(1e-3));
  EXPECT_TRUE(jitter.IsUniform(5e-3));
  EXPECT_THAT([&] { jitter.RequireUniform(1e-3); },
              ThrowsMessage<DataError>(HasSubstr("sampling is not uniform")));
  EXPECT_NO_THROW(jitter.RequireUniform(5e-3));
}

}  // namespace
}  // namespace pneumid
