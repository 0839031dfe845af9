#include "pneumid/data/preprocess.hpp"

#include <cmath>
#include <random>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "pneumid/common/check.hpp"
#include "pneumid/data/load.hpp"

namespace pneumid {
namespace {

using ::testing::AllOf;
using ::testing::HasSubstr;
using ::testing::ThrowsMessage;

Dataset Uniform(const Eigen::VectorXd& u, const Eigen::VectorXd& y, double Ts = 0.01) {
  return Dataset::FromUniform(Ts, u, y);
}

/// Step of the paper's reaction-curve test (sec. 4): duty 0.61 -> 82 at sample `at`.
Eigen::VectorXd StepInput(int n, int at, double before = 0.61, double after = 82.0) {
  Eigen::VectorXd u(n);
  for (int i = 0; i < n; ++i) u[i] = i < at ? before : after;
  return u;
}

TEST(PreprocessTest, ChannelSetStrings) {
  for (auto s : {ChannelSet::kInputs, ChannelSet::kOutputs, ChannelSet::kBoth}) {
    EXPECT_EQ(ChannelSetFromString(ToString(s)), s);
  }
  EXPECT_THROW(ChannelSetFromString("all"), InvalidArgument);
}

TEST(PreprocessTest, RemoveMeans) {
  const Dataset d = Uniform(Eigen::Vector4d(1, 2, 3, 6), Eigen::Vector4d(10, 10, 20, 20));
  OperatingPoint op;
  const Dataset r = RemoveMeans(d, ChannelSet::kBoth, &op);
  EXPECT_TRUE(r.u().isApprox(Eigen::Vector4d(-2, -1, 0, 3)));
  EXPECT_TRUE(r.y().isApprox(Eigen::Vector4d(-5, -5, 5, 5)));
  EXPECT_DOUBLE_EQ(op.u0[0], 3.0);
  EXPECT_DOUBLE_EQ(op.y0[0], 15.0);
  const Dataset o = RemoveMeans(d, ChannelSet::kOutputs, &op);
  EXPECT_EQ(o.u(), d.u());
  EXPECT_DOUBLE_EQ(op.u0[0], 0.0);
  EXPECT_EQ(o.time(), d.time());
}

TEST(PreprocessTest, RemoveInitialOffsetOverFirstSamples) {
  const Dataset d = Uniform(Eigen::Vector3d(1, 1, 5), Eigen::Vector3d(4, 6, 10));
  OperatingPoint op;
  const Dataset r = RemoveInitialOffset(d, 2, ChannelSet::kBoth, &op);
  EXPECT_TRUE(r.u().isApprox(Eigen::Vector3d(0, 0, 4)));
  EXPECT_TRUE(r.y().isApprox(Eigen::Vector3d(-1, 1, 5)));
  EXPECT_DOUBLE_EQ(op.y0[0], 5.0);
  EXPECT_THROW(RemoveInitialOffset(d, 0), InvalidArgument);
  EXPECT_THAT([&] { RemoveInitialOffset(d, 4); },
              ThrowsMessage<DataError>(HasSubstr("at least 4 samples")));
}

TEST(PreprocessTest, DetrendRemovesLeastSquaresLine) {
  // x = 2 + 3 t + r with r orthogonal to 1 and t (t = 0..4 s): detrend gives r.
  Eigen::VectorXd r(5), x(5), t(5);
  r << 1, -2, 0, 2, -1;
  for (int i = 0; i < 5; ++i) {
    t[i] = i;
    x[i] = 2.0 + 3.0 * i + r[i];
  }
  const Dataset d = Uniform(x, 7.0 - 0.5 * t.array(), 1.0);
  const Dataset out = Detrend(d);
  EXPECT_LT((out.u() - r).cwiseAbs().maxCoeff(), 1e-12);
  EXPECT_LT(out.y().cwiseAbs().maxCoeff(), 1e-12);
  const Dataset only_inputs = Detrend(d, ChannelSet::kInputs);
  EXPECT_EQ(only_inputs.y(), d.y());
}

TEST(PreprocessTest, DetectsCleanStep) {
  const int n = 100, at = 30;
  Eigen::VectorXd y = Eigen::VectorXd::Constant(n, 3.0);
  for (int i = at; i < n; ++i) y[i] = 3.0 + 129.0 * (1.0 - std::exp(-(i - at) * 0.01 / 0.245));
  const Dataset d = Uniform(StepInput(n, at), y);
  const StepEvent e = DetectStep(d);
  EXPECT_EQ(e.index, at);
  EXPECT_NEAR(e.time, 0.30, 1e-12);
  EXPECT_NEAR(e.baseline_before, 0.61, 1e-12);
  EXPECT_NEAR(e.level_after, 82.0, 1e-12);
  EXPECT_NEAR(e.size, 81.39, 1e-12);
  ASSERT_EQ(e.outputs_before.size(), 1);
  EXPECT_NEAR(e.outputs_before[0], 3.0, 1e-12);
  EXPECT_TRUE(std::isinf(e.significance));

  OperatingPoint op;
  const Dataset r = RemoveInitialOffset(d, e, ChannelSet::kBoth, &op);
  EXPECT_NEAR(r.u()[0], 0.0, 1e-12);
  EXPECT_NEAR(r.u()[n - 1], 81.39, 1e-12);
  EXPECT_NEAR(r.y()[at - 1], 0.0, 1e-12);
  EXPECT_NEAR(op.y0[0], 3.0, 1e-12);
}

TEST(PreprocessTest, DetectsStepNearTheEnds) {
  for (int at : {1, 2, 48, 49}) {
    const StepEvent e =
        DetectStep(Uniform(StepInput(50, at, 1.0, -1.0), Eigen::VectorXd::Zero(50)));
    EXPECT_EQ(e.index, at);
    EXPECT_NEAR(e.size, -2.0, 1e-12);
  }
  const Dataset d = Uniform(StepInput(50, 0 + 1), Eigen::VectorXd::Zero(50));
  StepEvent first = DetectStep(d);
  first.index = 0;
  EXPECT_THAT([&] { RemoveInitialOffset(d, first); },
              ThrowsMessage<DataError>(HasSubstr("first sample")));
}

TEST(PreprocessTest, DetectsNoisyStepWithinOneSample) {
  std::mt19937 rng(7);
  std::normal_distribution<double> noise(0.0, 2.0);
  const int n = 400, at = 123;
  Eigen::VectorXd u = StepInput(n, at, 0.0, 20.0);  // step = 10 noise std
  for (int i = 0; i < n; ++i) u[i] += noise(rng);
  const StepEvent e = DetectStep(Uniform(u, Eigen::VectorXd::Zero(n)));
  EXPECT_LE(std::abs(e.index - at), 1);
  EXPECT_NEAR(e.size, 20.0, 2.0);
  EXPECT_GT(e.significance, 5.0);
}

TEST(PreprocessTest, NoStepGivesClearError) {
  const int n = 200;
  Eigen::VectorXd y = Eigen::VectorXd::Zero(n);
  Dataset constant = Uniform(Eigen::VectorXd::Constant(n, 5.0), y);
  constant.set_source("flat.csv");
  EXPECT_THAT([&] { DetectStep(constant); },
              ThrowsMessage<DataError>(
                  AllOf(HasSubstr("flat.csv"), HasSubstr("input 'u'"), HasSubstr("constant"))));
  Eigen::VectorXd ramp(n);
  for (int i = 0; i < n; ++i) ramp[i] = 0.1 * i;
  EXPECT_THAT([&] { DetectStep(Uniform(ramp, y)); },
              ThrowsMessage<DataError>(HasSubstr("no step found in input 'u'")));
  std::mt19937 rng(3);
  std::normal_distribution<double> noise(0.0, 1.0);
  Eigen::VectorXd white(n);
  for (int i = 0; i < n; ++i) white[i] = noise(rng);
  EXPECT_THAT([&] { DetectStep(Uniform(white, y)); },
              ThrowsMessage<DataError>(HasSubstr("no step found")));
  // A real but small step is rejected by min_size.
  StepDetectOptions o;
  o.min_size = 100.0;
  EXPECT_THAT([&] { DetectStep(Uniform(StepInput(n, 50), y), o); },
              ThrowsMessage<DataError>(HasSubstr("size >= 100")));
  o = {};
  o.input = 1;
  EXPECT_THROW(DetectStep(Uniform(StepInput(n, 50), y), o), InvalidArgument);
}

TEST(PreprocessTest, ResampleInterpolatesLinearly) {
  // Non-uniform time; signals linear in t are reproduced exactly.
  Eigen::VectorXd t(5);
  t << 0.0, 0.1, 0.3, 0.35, 0.6;
  const Eigen::VectorXd u = 2.0 * t.array() + 1.0;
  Eigen::VectorXd y(5);
  y << 0, 1, 0, 0, 5;
  const Dataset d(t, u, y);
  EXPECT_FALSE(d.IsUniform());
  const Dataset r = Resample(d, 0.05);
  ASSERT_EQ(r.size(), 13);
  EXPECT_TRUE(r.IsUniform(1e-9));
  EXPECT_NEAR(r.SampleTime(), 0.05, 1e-15);
  for (Eigen::Index k = 0; k < r.size(); ++k) {
    EXPECT_NEAR(r.u()[k], 2.0 * r.time()[k] + 1.0, 1e-12);
  }
  EXPECT_NEAR(r.y()[1], 0.5, 1e-12);   // t = 0.05: halfway 0 -> 1
  EXPECT_NEAR(r.y()[3], 0.75, 1e-12);  // t = 0.15: a quarter of the way 1 -> 0
  EXPECT_NEAR(r.y()[10], 3.0, 1e-12);  // t = 0.5: (0.5 - 0.35) / 0.25 * 5
  EXPECT_NEAR(r.y()[12], 5.0, 1e-12);
  const Dataset shifted = Resample(d, 0.1, 0.05);
  EXPECT_NEAR(shifted.time()[0], 0.05, 1e-15);
  EXPECT_EQ(shifted.size(), 6);
  EXPECT_THROW(Resample(d, 0.0), InvalidArgument);
  EXPECT_THROW(Resample(d, 0.1, 1.0), InvalidArgument);
}

// Reference: tests/data/gen_decimate.py (scipy 1.10.1 sosfiltfilt + butter).
const std::vector<double> kDecimated = {
    7.3526200939960391e-05, 0.237342025205173,  0.47213613154075096, 0.68304922779864863,
    0.87284320509305313,    1.0576915633356998, 1.142115271728124,   1.3014303872063624,
    1.3013378217913751,     1.278569586628463,  2.2100037788052775,  2.8704868354003272,
    2.6245801149866197,     2.5274580507253228, 2.4147409630247099,  2.224367485250538,
    2.0904658117173525,     1.9224647012746647, 1.7758459468320438,  1.6504271506081989,
    1.5421422746169464,     1.4674913528678832, 1.4309998898087377,  1.4236494248189133,
    1.4634193650703731,     1.5487259697391396, 1.6384752201043329,  1.834404987398492,
    1.9625318564458305,     2.1937908266570618};
const std::vector<double> kDecimatedOrder4 = {
    0.00070842288903413819, 0.17847414676516252, 0.35477972083874487, 0.52458334927719952,
    0.68590028416350757,    0.83420142820973553, 0.96063135259465382, 1.06800664621631,
    1.1769623647177421,     1.2769698566926004,  1.2912629305197578,  1.2258321168330524,
    1.3612636264143678,     1.9413310760919802,  2.6059169643471551,  2.8307266863832878,
    2.694928746243888,      2.5378209989256542,  2.4522702734819894,  2.3654376435224833,
    2.2468232710527447,     2.1197567349953399,  2.000269247617998,   1.886817652916351,
    1.77812956549143,       1.6783675485095779,  1.592046324983317,   1.5215864406864157,
    1.4684591934356968,     1.4345499497546848,  1.4223984041609785,  1.4332283527737422,
    1.4644731197640986,     1.5142047334333051,  1.5907286691079292,  1.7020932352117251,
    1.8216014666189519,     1.9096720609109838,  2.038176839747273,   2.3937203975504269};

Dataset DecimateInput() {
  const int n = 120;
  Eigen::VectorXd x(n);
  for (int k = 0; k < n; ++k) {
    x[k] = std::sin(0.05 * k) + 0.5 * std::sin(2.5 * k) + 0.01 * k + (k >= 40 ? 1.5 : 0.0);
  }
  return Uniform(x, Eigen::VectorXd::Constant(n, 4.25), 0.01);
}

TEST(PreprocessTest, DecimateMatchesScipySosfiltfilt) {
  const Dataset d = DecimateInput();
  const Dataset r = Decimate(d, 4);
  ASSERT_EQ(r.size(), static_cast<Eigen::Index>(kDecimated.size()));
  for (Eigen::Index k = 0; k < r.size(); ++k) {
    EXPECT_NEAR(r.u()[k], kDecimated[static_cast<std::size_t>(k)], 1e-10) << k;
    EXPECT_NEAR(r.y()[k], 4.25, 1e-12) << k;  // DC gain exactly 1
    EXPECT_DOUBLE_EQ(r.time()[k], d.time()[4 * k]);
  }
  EXPECT_NEAR(r.SampleTime(), 0.04, 1e-12);
  DecimateOptions o;
  o.order = 4;
  o.cutoff = 0.5;
  const Dataset r3 = Decimate(d, 3, o);
  ASSERT_EQ(r3.size(), static_cast<Eigen::Index>(kDecimatedOrder4.size()));
  for (Eigen::Index k = 0; k < r3.size(); ++k) {
    EXPECT_NEAR(r3.u()[k], kDecimatedOrder4[static_cast<std::size_t>(k)], 1e-10) << k;
  }
}

TEST(PreprocessTest, DecimateRemovesAliasAndKeepsSlowSignal) {
  // 1 Hz (kept) + 40 Hz (above the new Nyquist 12.5 Hz) at fs = 100 Hz, q = 4.
  const int n = 2000;
  Eigen::VectorXd slow(n), x(n);
  for (int k = 0; k < n; ++k) {
    const double t = 0.01 * k;
    slow[k] = std::sin(2 * M_PI * 1.0 * t);
    x[k] = slow[k] + std::sin(2 * M_PI * 40.0 * t);
  }
  const Dataset r = Decimate(Uniform(x, slow), 4);
  // Away from the ends: |H(1 Hz)|^2 = 1 - O(1e-13), |H(40 Hz)|^2 < 1e-8.
  for (Eigen::Index k = 50; k < r.size() - 50; ++k) {
    EXPECT_NEAR(r.u()[k], std::sin(2 * M_PI * r.time()[k]), 1e-6) << k;
  }
}

TEST(PreprocessTest, DecimateErrors) {
  Eigen::VectorXd t(40);
  for (int i = 0; i < 40; ++i) t[i] = 0.01 * i + (i > 20 ? 0.005 : 0.0);
  const Dataset nonuniform(t, Eigen::MatrixXd::Zero(40, 1), Eigen::MatrixXd::Zero(40, 1));
  EXPECT_THAT([&] { Decimate(nonuniform, 2); }, ThrowsMessage<DataError>(HasSubstr("not uniform")));
  const Dataset shortd = Uniform(Eigen::VectorXd::Zero(27), Eigen::VectorXd::Zero(27));
  EXPECT_THAT([&] { Decimate(shortd, 2); },
              ThrowsMessage<DataError>(HasSubstr("needs more than 27 samples")));
  EXPECT_THROW(Decimate(shortd, 0), InvalidArgument);
  DecimateOptions o;
  o.order = 3;
  EXPECT_THROW(Decimate(shortd, 2, o), InvalidArgument);
  EXPECT_EQ(Decimate(shortd, 1).size(), 27);
}

TEST(PreprocessTest, SelectWindowKeepsFileLines) {
  Dataset d = Uniform(Eigen::VectorXd::LinSpaced(100, 0, 99), Eigen::VectorXd::Zero(100));
  d.set_source("w.csv");
  d.set_source_lines({0, 50}, {3, 60});
  const Dataset w = SelectWindow(d, 0.45, 0.55);
  ASSERT_EQ(w.size(), 11);
  EXPECT_NEAR(w.time()[0], 0.45, 1e-12);
  EXPECT_DOUBLE_EQ(w.u()[0], 45.0);
  EXPECT_EQ(w.SourceLine(0), 48);
  EXPECT_EQ(w.SourceLine(5), 60);
  EXPECT_EQ(w.Where(6), "w.csv:61");
  EXPECT_THAT([&] { SelectWindow(d, 5.0, 6.0); },
              ThrowsMessage<DataError>(
                  AllOf(HasSubstr("w.csv"), HasSubstr("no sample in the time window"))));
  EXPECT_THROW(SelectWindow(d, 0.5, 0.4), InvalidArgument);
}

TEST(PreprocessTest, ExampleStepTestGivesThePapersStaticGain) {
  // data/ipa_step.csv: the paper's ARX model (Eq. 4-5) under a 0.61 -> 82 % step
  // at t = 0.5 s with 0.3 N noise; its static gain is 1.59796 N/% (paper sec. 2).
  const Dataset d = LoadDataset(std::string(PNEUMID_SOURCE_DIR) + "/data/ipa_step.csv");
  ASSERT_EQ(d.size(), 301);
  EXPECT_TRUE(d.IsUniform());
  EXPECT_EQ(d.output_channels()[0].unit, "N");
  const StepEvent e = DetectStep(d);
  EXPECT_NEAR(e.time, 0.5, 0.5 * d.SampleTime());
  EXPECT_NEAR(e.size, 81.39, 1e-9);
  const Dataset r = RemoveInitialOffset(d, e);
  const double y_final = r.y().tail(100).mean();
  EXPECT_NEAR(y_final / e.size, 1.59796, 0.005 * 1.59796);
}

}  // namespace
}  // namespace pneumid
