// Signals against their definitions (include/pneumid/plant/signal.hpp).
#include "pneumid/plant/signal.hpp"

#include <cmath>
#include <cstdio>
#include <fstream>
#include <numbers>
#include <string>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "pneumid/common/check.hpp"
#include "pneumid/plant/prbs.hpp"

namespace pneumid {
namespace {

using ::testing::HasSubstr;
using ::testing::ThrowsMessage;

TEST(SignalTest, StepSwitchesAtItsEdge) {
  auto s = ParseSignal("step:from=0.61,to=82,at=1.0");
  EXPECT_DOUBLE_EQ((*s)(0.0), 0.61);
  EXPECT_DOUBLE_EQ((*s)(0.999), 0.61);
  EXPECT_DOUBLE_EQ((*s)(1.0), 82.0);
  EXPECT_DOUBLE_EQ((*s)(3.0), 82.0);
  // On a sample grid: sample 100 at Ts = 0.01 is t = 1.0 and already switched,
  // even where k * Ts rounds below the edge (e.g. 0.07 * 100 = 7.000000000000001
  // but 0.1 * 3 = 0.30000000000000004 and 0.01 * 29 = 0.29).
  Eigen::VectorXd v = s->Sample(0.01, 400);
  EXPECT_DOUBLE_EQ(v[99], 0.61);
  EXPECT_DOUBLE_EQ(v[100], 82.0);
  auto s2 = ParseSignal("step:from=0,to=1,at=0.29");
  Eigen::VectorXd v2 = s2->Sample(0.01, 40);
  EXPECT_DOUBLE_EQ(v2[28], 0.0);
  EXPECT_DOUBLE_EQ(v2[29], 1.0);
  EXPECT_EQ(s->ToString(), "step:from=0.61,to=82,at=1");
}

TEST(SignalTest, OffsetAndLimitsApplyAfterTheShape) {
  auto s = ParseSignal("step:from=-5,to=120,at=1,offset=2,min=0,max=100");
  EXPECT_DOUBLE_EQ((*s)(0.0), 0.0);    // -5 + 2 clamped to 0
  EXPECT_DOUBLE_EQ((*s)(2.0), 100.0);  // 122 clamped to 100
  auto r = ParseSignal("ramp:from=0,to=10,at=1,duration=2,offset=1");
  EXPECT_DOUBLE_EQ((*r)(0.5), 1.0);
  EXPECT_DOUBLE_EQ((*r)(2.0), 6.0);
  EXPECT_DOUBLE_EQ((*r)(5.0), 11.0);
}

TEST(SignalTest, StaircaseHoldsEachLevelForItsDwell) {
  auto s = ParseSignal("staircase:levels=0 20 40 20,dwell=1.5,at=0.5");
  EXPECT_DOUBLE_EQ((*s)(0.0), 0.0);
  EXPECT_DOUBLE_EQ((*s)(0.5), 0.0);
  EXPECT_DOUBLE_EQ((*s)(1.99), 0.0);
  EXPECT_DOUBLE_EQ((*s)(2.0), 20.0);
  EXPECT_DOUBLE_EQ((*s)(3.5), 40.0);
  EXPECT_DOUBLE_EQ((*s)(5.0), 20.0);
  EXPECT_DOUBLE_EQ((*s)(100.0), 20.0);
  auto m = ParseSignal("multistep:levels=1;2;3,dwell=1");
  EXPECT_DOUBLE_EQ((*m)(1.0), 2.0);
  EXPECT_EQ(m->ToString(), "staircase:levels=1 2 3,dwell=1,at=0");
}

TEST(SignalTest, ChirpFollowsTheLinearSweep) {
  auto s = ParseSignal("chirp:from=10,to=50,f0=0.5,f1=5,at=1,duration=4");
  const double mid = 30.0, amp = 20.0;
  for (double tau : {0.1, 0.77, 1.9, 3.2}) {
    const double phase = 2 * std::numbers::pi * (0.5 * tau + 0.5 * 4.5 * tau * tau / 4.0);
    EXPECT_NEAR((*s)(1.0 + tau), mid + amp * std::sin(phase), 1e-12) << tau;
  }
  EXPECT_DOUBLE_EQ((*s)(0.5), mid);
  EXPECT_DOUBLE_EQ((*s)(6.0), mid);
  // Instantaneous frequency near the end: zero crossings about 1/(2 f1) apart.
}

TEST(SignalTest, SineOscillatesBetweenItsEndsFromItsStart) {
  auto s = ParseSignal("sine:from=0.03,to=0.07,frequency=0.5,at=1");
  for (double tau : {0.0, 0.25, 0.5, 0.77, 1.5, 9.1})
    EXPECT_NEAR((*s)(1.0 + tau), 0.05 + 0.02 * std::sin(std::numbers::pi * tau), 1e-15) << tau;
  EXPECT_DOUBLE_EQ((*s)(0.5), 0.05);
  auto ended = ParseSignal("sine:from=0,to=2,frequency=1,duration=2");
  EXPECT_DOUBLE_EQ((*ended)(2.5), 1.0);
  EXPECT_EQ(ParseSignal(ended->ToString())->ToString(), ended->ToString());
  EXPECT_EQ(ParseSignal(s->ToString())->ToString(), s->ToString());
  EXPECT_THAT([] { ParseSignal("sine:from=0,to=1,frequency=0"); },
              ThrowsMessage<InvalidArgument>(HasSubstr("frequency must be positive")));
  EXPECT_THAT([&] { s->Sample(1.5, 10); },  // 0.5 Hz at Ts = 1.5 s: Nyquist 0.33 Hz
              ThrowsMessage<InvalidArgument>(HasSubstr("Nyquist")));
}

// Reference sequences: tests/plant/gen_prbs.py (scipy.signal.max_len_seq).
struct PrbsReference {
  int order;
  unsigned seed;
  const char* bits;
};
const PrbsReference kPrbsReference[] = {
    {4, 15, "111101011001000"},
    {7, 127,
     "111111101010100110011101110100101100011011110110101101100100100011100001011111001010111001101"
     "0001001111000101000011000001000000"},
    {7, 5,
     "101000011000001000000111111101010100110011101110100101100011011110110101101100100100011100001"
     "0111110010101110011010001001111000"},
    {10, 1023,
     "111111111100011100010011101100101011101111010100011110100101010000010111111110101010101111010"
     "000111010010001100101101011001111010110001100111111001010101001100110010100111110100111000010"
     "001101100100010100110111101110101011100110011101110111001110101001110100000111101101110000110"
     "001001010010110011010001000101101001011101001100010110000001010010010111110111100011000110111"
     "011000011110010011100101100010000110111111100111000110101001010000100001001011011111010111000"
     "101110010000111110110101010001011110110011100111110000011100100101011001011110010111000001010"
     "110110011000011010110111010001010111111010001110011011100101000110100000011001001000100000100"
     "110110100111100110101011000010111011010001100001001111111011100011110000001110110110001010001"
     "001100100000110100100111101111100010101011010000101000000010110110111100111100010001111110110"
     "001110101101010000110011011000001100000000110110110101110101111000010101001000010110010011000"
     "00100010010000001000000000100100100110100110101111100110001111100100011101111110000111000000"
     "0"},
};

TEST(PrbsTest, MatchesScipyMaxLenSeq) {
  for (const auto& ref : kPrbsReference) {
    auto bits = MaxLengthSequence(ref.order, ref.seed);
    std::string got;
    for (auto b : bits) got += static_cast<char>('0' + b);
    EXPECT_EQ(got, ref.bits) << "order " << ref.order << " seed " << ref.seed;
  }
}

TEST(PrbsTest, HasMaximalPeriodAndBalance) {
  for (int order = 2; order <= 16; ++order) {
    auto bits = MaxLengthSequence(order, 1);
    const std::size_t n = (std::size_t{1} << order) - 1;
    ASSERT_EQ(bits.size(), n);
    std::size_t ones = 0;
    for (auto b : bits) ones += b;
    EXPECT_EQ(ones, (n + 1) / 2) << order;  // 2^(n-1) ones, 2^(n-1) - 1 zeros
    // No shorter period: the register state recurs only after n steps, so the
    // sequence is not periodic with any proper divisor of n.
    for (std::size_t p = 1; p < n; ++p) {
      if (n % p) continue;
      bool periodic = true;
      for (std::size_t i = p; i < n && periodic; ++i) periodic = bits[i] == bits[i - p];
      EXPECT_FALSE(periodic) << "order " << order << " period " << p;
    }
  }
}

TEST(SignalTest, PrbsHoldsEachBitForOneClockPeriodAndRepeats) {
  auto s = ParseSignal("prbs:low=10,high=60,order=5,clock=0.05,at=1");
  auto bits = MaxLengthSequence(5, 31);
  EXPECT_DOUBLE_EQ((*s)(0.5), 10.0);
  for (std::size_t k = 0; k < bits.size(); ++k) {
    const double expect = bits[k] ? 60.0 : 10.0;
    EXPECT_DOUBLE_EQ((*s)(1.0 + 0.05 * static_cast<double>(k)), expect) << k;
    EXPECT_DOUBLE_EQ((*s)(1.0 + 0.05 * (static_cast<double>(k) + 0.99)), expect) << k;
    EXPECT_DOUBLE_EQ((*s)(1.0 + 0.05 * static_cast<double>(k + 31)), expect) << k;
  }
  auto seeded = ParseSignal("prbs:low=0,high=1,order=10,clock=0.01,seed=77");
  auto ref = MaxLengthSequence(10, 77, 50);
  for (int k = 0; k < 50; ++k) EXPECT_DOUBLE_EQ((*seeded)(0.01 * k), ref[k]) << k;
}

TEST(SignalTest, FileInputIsHeldBetweenSamples) {
  const std::string path = std::string(PNEUMID_BINARY_DIR) + "/signal_test_input.csv";
  {
    std::ofstream out(path);
    out << "t [s],u [%],y\n0,1,100\n0.5,2,100\n1.0,4,100\n";
  }
  auto s = ParseSignal("file:" + path + ",col=u");
  EXPECT_DOUBLE_EQ((*s)(-1.0), 1.0);
  EXPECT_DOUBLE_EQ((*s)(0.49), 1.0);
  EXPECT_DOUBLE_EQ((*s)(0.5), 2.0);
  EXPECT_DOUBLE_EQ((*s)(7.0), 4.0);
  auto y = ParseSignal("file:" + path + ",col=y,offset=-50");
  EXPECT_DOUBLE_EQ((*y)(0.7), 50.0);
  {
    std::ofstream out(path);
    out << "t,u\n0,1\n0.5,abc\n";
  }
  try {
    ParseSignal("file:" + path);
    FAIL() << "expected DataError";
  } catch (const DataError& e) {
    EXPECT_THAT(e.what(), HasSubstr(":3:"));
    EXPECT_THAT(e.what(), HasSubstr("abc"));
  }
  EXPECT_THROW(ParseSignal("file:/nonexistent/input.csv"), DataError);
  std::remove(path.c_str());
}

TEST(SignalTest, FileInputErrorsNameTheFileAndTheInputColumn) {
  // A missing file is "no such file", whatever its name ends with.
  EXPECT_THAT([] { ParseSignal("file:/nonexistent"); },
              ::testing::ThrowsMessage<DataError>(
                  HasSubstr("/nonexistent: cannot open: No such file or directory")));
  const std::string path = std::string(PNEUMID_BINARY_DIR) + "/signal_test_columns.csv";
  {
    std::ofstream out(path);
    out << "t,u\n0,1\n1,2\n";
  }
  // The column feeds the plant input: the error must not call it an output.
  EXPECT_THAT([&] { ParseSignal("file:" + path + ",col=p"); },
              ::testing::ThrowsMessage<DataError>(::testing::AllOf(
                  HasSubstr("unknown input column 'p'"), ::testing::Not(HasSubstr("output")))));
  std::remove(path.c_str());
}

TEST(SignalTest, BadSpecsGiveClearErrors) {
  auto expect_error = [](const std::string& spec, const std::string& fragment) {
    try {
      ParseSignal(spec);
      ADD_FAILURE() << "no error for " << spec;
    } catch (const InvalidArgument& e) {
      EXPECT_THAT(e.what(), HasSubstr(fragment)) << spec;
    }
  };
  expect_error("", "empty signal spec");
  expect_error("square:f=1", "unknown kind 'square'");
  expect_error("sine:f=1", "missing key 'from'");
  expect_error("step:from=0,at=1", "needs 'to='");
  expect_error("step:from=0,to=x1,at=1", "key 'to': not a finite number: 'x1'");
  expect_error("step:to=1,speed=3", "unknown key 'speed'");
  expect_error("step:to=1,to=2", "given twice");
  expect_error("step:to=1,at", "expected key=value");
  expect_error("prbs:order=40,clock=0.1", "order must be an integer in 2..32");
  expect_error("prbs:order=4,clock=0.1,seed=0", "seed must be an integer in 1..2^order-1 = 15");
  expect_error("prbs:order=4,clock=0", "clock must be positive");
  expect_error("staircase:levels=,dwell=1", "key 'levels' has no values");
  expect_error("step:to=1,2", "key 'to' takes one number, got '1,2'");
  expect_error("ramp:to=1,duration=-1", "duration must be positive");
  expect_error("step:to=1,min=5,max=1", "min = 5 exceeds max = 1");
  expect_error("file:", "file needs a path");
  EXPECT_THAT(SignalSyntaxHelp(), HasSubstr("step:from=A,to=B,at=T"));
}

TEST(SignalTest, ListsMayBeWrittenWithCommas) {
  const auto a = ParseSignal("staircase:levels=0,20,40,dwell=1");
  const auto b = ParseSignal("staircase:levels=0 20 40,dwell=1");
  EXPECT_EQ(a->ToString(), b->ToString());
  EXPECT_DOUBLE_EQ((*a)(2.5), 40.0);
}

TEST(PrbsTest, BitAtIndexMatchesTheGenerator) {
  for (int order : {2, 7, 12, 16, 31, 32}) {
    const std::uint64_t seed = order == 2 ? 3 : 0x2B;
    MaxLengthSequenceGenerator gen(order, seed);
    for (std::uint64_t k = 0; k < 3000; ++k) {
      ASSERT_EQ(MaxLengthSequenceBit(order, seed, k), gen.Next())
          << "order " << order << " k " << k;
    }
  }
  // Periodic with period 2^n - 1.
  EXPECT_EQ(MaxLengthSequenceBit(20, 5, 12345), MaxLengthSequenceBit(20, 5, 12345 + 1048575));
}

TEST(SignalTest, PrbsFarBeyondItsCacheIsComputedInBoundedTime) {
  // 1e9 clock periods in 1 s: bit by bit this took minutes and gigabytes.
  const auto fast = ParseSignal("prbs:order=32,clock=1e-9");
  const auto gen_seed = (std::uint64_t{1} << 32) - 1;
  EXPECT_EQ((*fast)(1.0), MaxLengthSequenceBit(32, gen_seed, 1000000000) ? 1.0 : 0.0);
  const Eigen::VectorXd v = fast->Sample(0.001, 1001);
  EXPECT_EQ(v.size(), 1001);
  EXPECT_TRUE(((v.array() == 0.0) || (v.array() == 1.0)).all());
}

TEST(SignalTest, IndicesBeyondTheIntegersAreRangeChecked) {
  // (t - at) / dwell = 1e300: the last level, not an undefined cast.
  const auto stairs = ParseSignal("staircase:levels=1 2,dwell=1e-300");
  EXPECT_DOUBLE_EQ((*stairs)(0.0), 1.0);
  EXPECT_DOUBLE_EQ((*stairs)(1.0), 2.0);
  const auto prbs = ParseSignal("prbs:order=7,clock=1e-300");
  EXPECT_THAT([&] { (*prbs)(1.0); },
              ThrowsMessage<InvalidArgument>(HasSubstr("beyond the exact integers of a double")));
}

TEST(SignalTest, ChirpAboveNyquistIsRefused) {
  const auto chirp = ParseSignal("chirp:from=0,to=1,f0=1,f1=80,duration=1");
  EXPECT_NO_THROW(chirp->Sample(0.005, 10));     // Nyquist 100 Hz
  EXPECT_THAT([&] { chirp->Sample(0.01, 10); },  // Nyquist 50 Hz
              ThrowsMessage<InvalidArgument>(
                  HasSubstr("reaches 80 Hz, above the Nyquist frequency 50 Hz")));
}

}  // namespace
}  // namespace pneumid
