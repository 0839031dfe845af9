#include "pneumid/data/preprocess.hpp"

#include <cmath>
#include <random>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "pneumid/common/check.hpp"
#include "pneumid/data/load.hpp"
#include "pneumid/data/preprocess_io.hpp"

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

/// `d` with every input and output value raised by 5.
Dataset Rebuild5(const Dataset& d) {
  return Dataset(d.time(), d.inputs().array() + 5.0, d.outputs().array() + 5.0);
}

// Reference: tests/data/gen_filter.py writes preprocess_golden.csv, a recorded
// signal pair (u, y) at 100 Hz and what numpy / scipy 1.10.1 make of it.
Dataset Golden(const std::vector<std::string>& columns) {
  CsvReadOptions o;
  o.input_columns = {columns[0]};
  o.output_columns = {columns[1]};
  return ReadCsv(std::string(PNEUMID_SOURCE_DIR) + "/tests/data/preprocess_golden.csv", o);
}

Dataset GoldenInput() { return Golden({"u", "y"}); }

/// Largest deviation of the channels of `got` from the golden columns `u_KEY`, `y_KEY`.
double GoldenError(const Dataset& got, const std::string& key) {
  const Dataset want = Golden({"u_" + key, "y_" + key});
  EXPECT_EQ(got.size(), want.size());
  if (got.size() != want.size()) return INFINITY;
  return std::max((got.u() - want.u()).cwiseAbs().maxCoeff(),
                  (got.y() - want.y()).cwiseAbs().maxCoeff());
}

TEST(PreprocessTest, RemoveMeansReproducesNumpy) {
  // numpy: x - x.mean(), values of 40..140 to 1e-12.
  const Dataset d = GoldenInput();
  OperatingPoint op;
  const Dataset r = RemoveMeans(d, ChannelSet::kBoth, &op);
  EXPECT_LT(GoldenError(r, "mean"), 1e-12);
  EXPECT_NEAR(op.u0[0], d.u().mean(), 1e-12);
  EXPECT_EQ(r.source(), d.source());
}

TEST(PreprocessTest, DetrendReproducesScipyLinearDetrend) {
  // scipy.signal.detrend(x, type='linear') to 1e-12; the removed line is
  // level + slope (t - time), with the mean as level.
  const Dataset d = GoldenInput();
  LinearTrend trend;
  const Dataset r = Detrend(d, ChannelSet::kBoth, &trend);
  EXPECT_LT(GoldenError(r, "linear"), 1e-12);
  EXPECT_NEAR(trend.time, d.time().mean(), 1e-15);
  EXPECT_NEAR(trend.level.y0[0], d.y().mean(), 1e-12);
  EXPECT_GT(trend.slope.y0[0], 3.0);  // the output drifts by 3.5 N/s plus the step
  for (Eigen::Index i : {0, 123, 399}) {
    const double line = trend.level.y0[0] + trend.slope.y0[0] * (d.time()[i] - trend.time);
    EXPECT_NEAR(r.y()[i], d.y()[i] - line, 1e-12);
  }
}

TEST(PreprocessTest, FilterMatchesScipySosfiltfilt) {
  // sosfiltfilt(butter(N, Wn, btype, fs=100, output='sos'), x) to 1e-10.
  const Dataset d = GoldenInput();
  EXPECT_LT(GoldenError(Filter(d, FilterSpec::Parse("lowpass:10")), "lp10"), 1e-10);
  EXPECT_LT(GoldenError(Filter(d, FilterSpec::Parse("lowpass:20,order=2")), "lp20o2"), 1e-10);
  EXPECT_LT(GoldenError(Filter(d, FilterSpec::Parse("bandpass:2,15")), "bp2_15"), 1e-10);
  EXPECT_LT(GoldenError(Filter(d, FilterSpec::Parse("bandpass:1,30,order=4")), "bp1_30o4"), 1e-10);
}

TEST(PreprocessTest, FilterSelectedChannelsKeepTimesAndLines) {
  const Dataset d = GoldenInput();
  const Dataset r = Filter(d, FilterSpec::Parse("lowpass:10"), ChannelSet::kOutputs);
  EXPECT_EQ(r.u(), d.u());
  EXPECT_EQ(r.time(), d.time());
  EXPECT_EQ(r.SourceLine(0), d.SourceLine(0));
  EXPECT_EQ(r.Where(5), d.Where(5));
  // Zero phase and unit DC gain: a constant passes unchanged.
  const Dataset c = Uniform(Eigen::VectorXd::Constant(200, 3.5), Eigen::VectorXd::Zero(200));
  EXPECT_LT((Filter(c, FilterSpec::Parse("lowpass:5")).u().array() - 3.5).abs().maxCoeff(), 1e-12);
  // A band-pass removes the constant.
  EXPECT_LT(Filter(c, FilterSpec::Parse("bandpass:1,5")).u().cwiseAbs().maxCoeff(), 1e-12);
}

TEST(PreprocessTest, FilterSpecParsesAndPrints) {
  const FilterSpec lp = FilterSpec::Parse("lowpass:10");
  EXPECT_EQ(lp.kind, FilterKind::kLowpass);
  EXPECT_EQ(lp.high_hz, 10.0);
  EXPECT_EQ(lp.order, FilterSpec::kDefaultOrder);
  EXPECT_EQ(lp.ToString(), "lowpass:10");
  const FilterSpec bp = FilterSpec::Parse(" BandPass: 0.5 , 20 ,order=3");
  EXPECT_EQ(bp.kind, FilterKind::kBandpass);
  EXPECT_EQ(bp.low_hz, 0.5);
  EXPECT_EQ(bp.high_hz, 20.0);
  EXPECT_EQ(bp.order, 3);
  EXPECT_EQ(bp.ToString(), "bandpass:0.5,20,order=3");
  EXPECT_EQ(FilterSpec::Parse(bp.ToString()).ToString(), bp.ToString());
  EXPECT_EQ(FilterKindFromString(ToString(FilterKind::kBandpass)), FilterKind::kBandpass);
  auto fails = [](const std::string& text, const std::string& message) {
    EXPECT_THAT([&] { FilterSpec::Parse(text); },
                ThrowsMessage<InvalidArgument>(
                    AllOf(HasSubstr("filter '" + text + "'"), HasSubstr(message))))
        << text;
  };
  fails("10", "expected lowpass:F or bandpass:F1,F2");
  fails("highpass:10", "unknown filter kind 'highpass'");
  fails("lowpass:abc", "'abc' is not a frequency in Hz");
  fails("lowpass:10,20", "one cutoff frequency F");
  fails("bandpass:10", "two band edges F1,F2");
  fails("bandpass:20,5", "need F1 < F2, got F1 = 20 Hz, F2 = 5 Hz");
  fails("lowpass:-3", "cutoff must be > 0 Hz");
  fails("lowpass:10,order=0", "order must be in [1, 10]");
  fails("lowpass:10,order=2.5", "order must be an integer");
  fails("lowpass:10,gain=2", "unknown key 'gain'");
}

TEST(PreprocessTest, FilterAboveNyquistNamesTheFile) {
  Dataset d = Uniform(Eigen::VectorXd::Zero(100), Eigen::VectorXd::Zero(100));
  d.set_source("data.csv");
  EXPECT_THAT([&] { Filter(d, FilterSpec::Parse("lowpass:60")); },
              ThrowsMessage<DataError>(HasSubstr(
                  "filter cutoff 60 Hz is above the Nyquist frequency 50 Hz of data.csv")));
  EXPECT_THAT([&] { Filter(d, FilterSpec::Parse("bandpass:10,50")); },
              ThrowsMessage<DataError>(HasSubstr(
                  "filter upper edge F2 = 50 Hz is at the Nyquist frequency 50 Hz of data.csv")));
  const Dataset shortd = Uniform(Eigen::VectorXd::Zero(18), Eigen::VectorXd::Zero(18));
  EXPECT_THAT([&] { Filter(shortd, FilterSpec::Parse("lowpass:10")); },
              ThrowsMessage<DataError>(HasSubstr("needs more than 18 samples")));
}

TEST(PreprocessTest, TimeWindowParses) {
  const TimeWindow w = TimeWindow::Parse("5:9");
  EXPECT_EQ(w.start, 5.0);
  EXPECT_EQ(w.end, 9.0);
  EXPECT_EQ(w.ToString(), "5:9");
  EXPECT_EQ(TimeWindow::Parse("2.5:").ToString(), "2.5:");
  EXPECT_EQ(TimeWindow::Parse(":9").ToString(), ":9");
  EXPECT_TRUE(TimeWindow::Parse(":9").IsSet());
  EXPECT_FALSE(TimeWindow().IsSet());
  EXPECT_THAT(
      [] { TimeWindow::Parse("9:5"); },
      ThrowsMessage<InvalidArgument>(HasSubstr("window '9:5': start 9 s is after end 5 s")));
  EXPECT_THAT([] { TimeWindow::Parse("5"); },
              ThrowsMessage<InvalidArgument>(HasSubstr("expected T0:T1")));
  EXPECT_THAT([] { TimeWindow::Parse("a:5"); },
              ThrowsMessage<InvalidArgument>(HasSubstr("start 'a' is not a time")));
}

TEST(PreprocessTest, DetrendKindStrings) {
  for (auto k : {DetrendKind::kNone, DetrendKind::kConstant, DetrendKind::kLinear}) {
    EXPECT_EQ(DetrendKindFromString(ToString(k)), k);
  }
  EXPECT_EQ(DetrendKindFromString("mean"), DetrendKind::kConstant);
  EXPECT_THROW(DetrendKindFromString("quadratic"), InvalidArgument);
}

TEST(PreprocessTest, PreprocessOptionsValidation) {
  auto invalid = [](const PreprocessOptions& o, const std::string& message) {
    std::string error;
    EXPECT_FALSE(o.IsValid(&error));
    EXPECT_THAT(error, HasSubstr(message));
    const Dataset d = Uniform(Eigen::VectorXd::Zero(100), Eigen::VectorXd::Zero(100));
    EXPECT_THAT([&] { Preprocess(d, o); }, ThrowsMessage<InvalidArgument>(HasSubstr(message)));
  };
  PreprocessOptions o;
  EXPECT_TRUE(o.IsValid(nullptr));
  EXPECT_TRUE(o.IsIdentity());
  o.decimate = 0;
  invalid(o, "decimation factor must be >= 1, got 0");
  o = {};
  o.remove_initial = true;
  o.detrend = DetrendKind::kLinear;
  invalid(o, "remove-initial and detrend linear are alternatives");
  o = {};
  o.resample_ts = -0.1;
  invalid(o, "resample sample time must be > 0 s");
  o = {};
  o.filter = FilterSpec{FilterKind::kBandpass, 5.0, 2.0, 5};
  invalid(o, "need F1 < F2");
}

// --remove-initial on a rest followed by a small step and a binary sequence
// whose largest jump (23 <-> 17) comes later: the level is the mean over the
// rest itself (40 samples), not over everything before that jump.
TEST(PreprocessTest, RemoveInitialTakesTheRestBeforeTheFirstChange) {
  const int n = 200, rest = 40;
  Eigen::VectorXd t(n), u(n), y(n);
  for (int k = 0; k < n; ++k) {
    t[k] = 0.1 * k;
    u[k] = k < rest ? 20.0 : (k < 100 ? 21.0 : ((k / 25) % 2 == 0 ? 23.0 : 17.0));
    y[k] = k < rest ? 50.0 : 50.0 + 2.0 * (u[k] - 20.0);
  }
  const Dataset d(t, u, y);
  PreprocessOptions o;
  o.remove_initial = true;
  PreprocessRecord r;
  const Dataset out = Preprocess(d, o, &r);
  EXPECT_DOUBLE_EQ(out.u()[0], 0.0);
  EXPECT_DOUBLE_EQ(out.y()[0], 0.0);
  EXPECT_THAT(r.steps.back(), HasSubstr("mean of the 40 samples before the step at t = 4 s"));
}

TEST(PreprocessTest, PreprocessWithoutStepsReturnsTheData) {
  const Dataset d = GoldenInput();
  PreprocessRecord r;
  const Dataset out = Preprocess(d, {}, &r);
  EXPECT_EQ(out.u(), d.u());
  EXPECT_EQ(out.Where(3), d.Where(3));
  EXPECT_TRUE(r.IsIdentity());
  EXPECT_TRUE(r.steps.empty());
  EXPECT_EQ(r.OutputOffsetAt(1.0), Eigen::VectorXd::Zero(1));
}

TEST(PreprocessTest, PreprocessRunsTheStepsInOrder) {
  // window -> resample -> detrend -> filter -> decimate, each equal to the
  // function applied alone in that order.
  const Dataset d = GoldenInput();
  PreprocessOptions o;
  o.window = TimeWindow::Parse("0.5:3.5");
  o.resample_ts = 0.005;
  o.detrend = DetrendKind::kLinear;
  o.filter = FilterSpec::Parse("lowpass:20");
  o.decimate = 2;
  PreprocessRecord r;
  const Dataset out = Preprocess(d, o, &r);
  LinearTrend trend;
  const Dataset expected = Decimate(
      Filter(Detrend(Resample(SelectWindow(d, 0.5, 3.5), 0.005), ChannelSet::kBoth, &trend),
             *o.filter),
      2);
  ASSERT_EQ(out.size(), expected.size());
  EXPECT_EQ(out.u(), expected.u());
  EXPECT_EQ(out.y(), expected.y());
  EXPECT_EQ(out.time(), expected.time());
  EXPECT_EQ(r.window.ToString(), "0.5:3.5");
  EXPECT_EQ(r.resample_ts, 0.005);
  EXPECT_EQ(r.offsets, "linear");
  EXPECT_EQ(r.level.y0, trend.level.y0);
  EXPECT_EQ(r.slope.y0, trend.slope.y0);
  EXPECT_EQ(r.trend_time, trend.time);
  ASSERT_TRUE(r.filter.has_value());
  EXPECT_EQ(r.filter->ToString(), "lowpass:20");
  EXPECT_EQ(r.decimate, 2);
  ASSERT_EQ(r.steps.size(), 5u);
  EXPECT_THAT(r.steps[0], HasSubstr("window 0.5:3.5 s"));
  EXPECT_THAT(r.steps[2], HasSubstr("detrend linear"));
  EXPECT_THAT(r.steps[4], HasSubstr("decimate by 2"));
  EXPECT_NEAR(r.OutputOffsetAt(r.trend_time + 1.0)[0], trend.level.y0[0] + trend.slope.y0[0],
              1e-12);
}

TEST(PreprocessTest, PreprocessRemovesInitialLevelBeforeTheStep) {
  // The golden input steps from about 40 to 65 at t = 1 s (sample 100).
  const Dataset d = GoldenInput();
  PreprocessOptions o;
  o.remove_initial = true;
  PreprocessRecord r;
  const Dataset out = Preprocess(d, o, &r);
  EXPECT_EQ(r.offsets, "initial");
  EXPECT_NEAR(r.level.u0[0], d.u().head(100).mean(), 1e-12);
  EXPECT_NEAR(r.level.y0[0], d.y().head(100).mean(), 1e-12);
  EXPECT_NEAR(out.y()[7], d.y()[7] - r.level.y0[0], 1e-12);
  EXPECT_THAT(r.steps[0], HasSubstr("100 samples before the step at t = 1 s"));
  o.initial_samples = 20;
  Preprocess(d, o, &r);
  EXPECT_NEAR(r.level.u0[0], d.u().head(20).mean(), 1e-12);
  EXPECT_EQ(r.slope.u0, Eigen::VectorXd::Zero(1));
}

TEST(PreprocessTest, PreprocessErrorsNameTheData) {
  Dataset d = Uniform(Eigen::VectorXd::Zero(401), Eigen::VectorXd::Zero(401));
  d.set_source("FILE.csv");
  PreprocessOptions o;
  o.window = TimeWindow::Parse("5:9");
  EXPECT_THAT(
      [&] { Preprocess(d, o); },
      ThrowsMessage<DataError>(HasSubstr("window 5:9 s lies outside the data 0..4 s of FILE.csv")));
  o = {};
  o.filter = FilterSpec::Parse("lowpass:60");
  EXPECT_THAT([&] { Preprocess(d, o); },
              ThrowsMessage<DataError>(HasSubstr(
                  "filter cutoff 60 Hz is above the Nyquist frequency 50 Hz of FILE.csv")));
  o = {};
  o.remove_initial = true;
  EXPECT_THAT([&] { Preprocess(d, o); },
              ThrowsMessage<DataError>(HasSubstr("FILE.csv: input 'u' is constant")));
}

TEST(PreprocessTest, ApplyRecordedUsesTheRecordedOffsets) {
  const Dataset d = GoldenInput();
  PreprocessOptions o;
  o.detrend = DetrendKind::kConstant;
  o.filter = FilterSpec::Parse("lowpass:15");
  PreprocessRecord r;
  const Dataset out = Preprocess(d, o, &r);
  // The same data: the same result.
  const Dataset again = ApplyRecorded(d, r);
  EXPECT_LT((again.y() - out.y()).cwiseAbs().maxCoeff(), 1e-12);
  // Other data (the same signals shifted by +5): the estimation offsets are
  // removed, not the new means, so the shift survives.
  const Dataset shifted = Rebuild5(d);
  const Dataset v = ApplyRecorded(shifted, r);
  EXPECT_LT((v.y().array() - out.y().array() - 5.0).abs().maxCoeff(), 1e-9);
  EXPECT_LT((v.u().array() - out.u().array() - 5.0).abs().maxCoeff(), 1e-9);
  // A linear trend is re-applied as the recorded line.
  o.detrend = DetrendKind::kLinear;
  o.filter.reset();
  Preprocess(d, o, &r);
  EXPECT_LT((ApplyRecorded(shifted, r).y().array() - Detrend(d).y().array() - 5.0).abs().maxCoeff(),
            1e-9);
  // Channel counts must match the record.
  const Dataset two(d.time(), Eigen::MatrixXd::Zero(d.size(), 2), d.outputs());
  EXPECT_THAT([&] { ApplyRecorded(two, r); },
              ThrowsMessage<DataError>(HasSubstr("has 2 inputs, the recorded preprocessing")));
}

TEST(PreprocessTest, PreprocessRecordJsonRoundTrip) {
  const Dataset d = GoldenInput();
  PreprocessOptions o;
  o.window = TimeWindow::Parse("0.5:");
  o.detrend = DetrendKind::kLinear;
  o.filter = FilterSpec::Parse("bandpass:1,20,order=3");
  o.decimate = 2;
  o.channels = ChannelSet::kOutputs;
  PreprocessRecord r;
  Preprocess(d, o, &r);
  const nlohmann::json j = ToJson(r);
  EXPECT_EQ(j.at("window"), "0.5:");
  EXPECT_EQ(j.at("filter"), "bandpass:1,20,order=3");
  EXPECT_EQ(j.at("channels"), "outputs");
  const PreprocessRecord back = PreprocessRecordFromJson(nlohmann::json::parse(j.dump()));
  EXPECT_EQ(ToJson(back), j);
  EXPECT_EQ(back.slope.y0, r.slope.y0);
  EXPECT_EQ(back.trend_time, r.trend_time);
  EXPECT_EQ(ApplyRecorded(d, back).y(), ApplyRecorded(d, r).y());
  EXPECT_TRUE(PreprocessRecordFromJson(nlohmann::json::object()).IsIdentity());
  EXPECT_THAT(
      [] {
        PreprocessRecordFromJson(nlohmann::json{{"filter", "lowpass:x"}});
      },
      ThrowsMessage<InvalidArgument>(
          AllOf(HasSubstr("preprocessing: key 'filter'"), HasSubstr("not a frequency"))));
  EXPECT_THAT(
      [] {
        PreprocessRecordFromJson(nlohmann::json{{"decimate", "4"}});
      },
      ThrowsMessage<InvalidArgument>(HasSubstr("preprocessing: key 'decimate'")));
}

}  // namespace
}  // namespace pneumid
