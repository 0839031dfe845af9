// TransferFunction, StateSpace and the polynomial helpers.
#include "pneumid/lti/transfer_function.hpp"

#include <cmath>
#include <complex>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "pneumid/common/check.hpp"
#include "pneumid/models/model_file.hpp"
#include "pneumid/lti/state_space.hpp"

namespace pneumid {
namespace {

using ::testing::HasSubstr;
using ::testing::ThrowsMessage;

// Sorts roots by (real, imag) for comparison.
std::vector<std::complex<double>> Sorted(const Eigen::VectorXcd& r) {
  std::vector<std::complex<double>> v(r.data(), r.data() + r.size());
  std::sort(v.begin(), v.end(), [](auto a, auto b) {
    return a.real() != b.real() ? a.real() < b.real() : a.imag() < b.imag();
  });
  return v;
}

TEST(TransferFunctionTest, PaperArxStaticGainAndPoles) {
  // docs/paper.md, reference value 2: static gain 1.59796, poles 0.95685, -0.17407 +/- 0.18062j.
  const TransferFunction g = PaperArxModel();
  EXPECT_TRUE(g.IsDiscrete());
  EXPECT_EQ(g.Order(), 3);
  EXPECT_NEAR(g.DcGain(), 1.59796, 5e-6);
  const auto p = Sorted(g.Poles());
  ASSERT_EQ(p.size(), 3u);
  EXPECT_NEAR(p[0].real(), -0.17407, 1e-5);
  EXPECT_NEAR(p[0].imag(), -0.18062, 1e-5);
  EXPECT_NEAR(p[1].real(), -0.17407, 1e-5);
  EXPECT_NEAR(p[1].imag(), 0.18062, 1e-5);
  EXPECT_NEAR(p[2].real(), 0.95685, 1e-5);
  EXPECT_TRUE(g.IsStable());
  // Zeros of b1 z^2 + b2 z + b3.
  const auto z = Sorted(g.Zeros());
  ASSERT_EQ(z.size(), 2u);
  for (const auto& zi : z) {
    EXPECT_NEAR(std::abs(0.03938 * zi * zi + 0.04506 * zi + 0.01286), 0.0, 1e-12);
  }
}

TEST(TransferFunctionTest, ContinuousBasics) {
  const TransferFunction g = TransferFunction::Continuous({2.0, 4.0}, {1.0, 3.0, 2.0});
  EXPECT_TRUE(g.IsContinuous());
  EXPECT_EQ(g.Order(), 2);
  EXPECT_DOUBLE_EQ(g.DcGain(), 2.0);
  const auto p = Sorted(g.Poles());
  EXPECT_NEAR(p[0].real(), -2.0, 1e-12);
  EXPECT_NEAR(p[1].real(), -1.0, 1e-12);
  const auto z = Sorted(g.Zeros());
  ASSERT_EQ(z.size(), 1u);
  EXPECT_NEAR(z[0].real(), -2.0, 1e-12);
  // G(j) = (2j + 4) / (-1 + 3j + 2) = (4 + 2j) / (1 + 3j)
  const std::complex<double> expected = std::complex<double>(4, 2) / std::complex<double>(1, 3);
  EXPECT_NEAR(std::abs(g.FrequencyResponse(1.0) - expected), 0.0, 1e-14);
  // A delay only rotates the phase: exp(-j w theta).
  const TransferFunction gd = g.WithDelay(0.3);
  EXPECT_NEAR(std::arg(gd.FrequencyResponse(1.0) / expected), -0.3, 1e-14);
  EXPECT_NEAR(std::abs(gd.FrequencyResponse(1.0)), std::abs(expected), 1e-14);
}

TEST(TransferFunctionTest, FopdtAndSopdt) {
  const TransferFunction f = TransferFunction::Fopdt(1.6, 0.245, 0.001);
  EXPECT_DOUBLE_EQ(f.DcGain(), 1.6);
  EXPECT_DOUBLE_EQ(f.delay(), 0.001);
  EXPECT_NEAR(f.Poles()[0].real(), -1.0 / 0.245, 1e-12);
  const TransferFunction s = TransferFunction::Sopdt(2.0, 1.0, 0.5, 0.1);
  const auto p = Sorted(s.Poles());
  EXPECT_NEAR(p[0].real(), -2.0, 1e-12);
  EXPECT_NEAR(p[1].real(), -1.0, 1e-12);
  EXPECT_DOUBLE_EQ(s.DcGain(), 2.0);
}

TEST(TransferFunctionTest, DiscreteDelayAndPadding) {
  const TransferFunction g = TransferFunction::Discrete({0.5}, {1.0, -0.5}, 0.1, 3);
  EXPECT_EQ(g.DelaySamples(), 3);
  EXPECT_NEAR(g.delay(), 0.3, 1e-15);
  EXPECT_EQ(g.num().size(), 2);  // padded to the denominator's length
  EXPECT_DOUBLE_EQ(g.DcGain(), 1.0);
  // G(e^{jwT}) z^-3: the phase includes -3 w T.
  const double w = 2.0;
  const std::complex<double> z = std::exp(std::complex<double>(0, w * 0.1));
  const std::complex<double> expected = 0.5 * z / (z - 0.5) * std::pow(z, -3);
  EXPECT_NEAR(std::abs(g.FrequencyResponse(w) - expected), 0.0, 1e-14);
  // round(delay / Ts), bounded: 3e9 samples would overflow an int (it
  // came back as a negative delay), 1e300 too; both name the count.
  EXPECT_EQ(DelayInSamples(0.3, 0.1), 3);
  EXPECT_EQ(DelayInSamples(1e6, 0.01), 100000000);
  EXPECT_THAT([] { DelayInSamples(3e7, 0.01); },
              ThrowsMessage<InvalidArgument>(HasSubstr("is 3000000000 samples")));
  EXPECT_THROW(DelayInSamples(1.0, 1e-300), InvalidArgument);
  EXPECT_THROW(DelayInSamples(-0.1, 0.1), InvalidArgument);
  // Common factors z^k are dropped.
  const TransferFunction h = TransferFunction::Discrete({1.0, 0.0, 0.0}, {1.0, 0.5, 0.0}, 0.1);
  EXPECT_EQ(h.Order(), 1);
}

TEST(TransferFunctionTest, NormalizedAndToString) {
  const TransferFunction g = TransferFunction::Continuous({0.0, 4.0, 2.0}, {2.0, 6.0, 4.0}, 0.5);
  const TransferFunction n = g.Normalized();
  EXPECT_DOUBLE_EQ(n.den()[0], 1.0);
  EXPECT_EQ(n.num().size(), 2);
  EXPECT_DOUBLE_EQ(n.num()[0], 2.0);
  EXPECT_EQ(n.ToString(), "(2 s + 1) / (s^2 + 3 s + 2) * exp(-0.5 s)");
  EXPECT_EQ(PaperArxModel().ToString(4),
            "(0.03938 z^-1 + 0.04506 z^-2 + 0.01286 z^-3) / (1 - 0.6087 z^-1 - 0.2702 z^-2 - "
            "0.06021 z^-3), Ts = 0.01");
}

TEST(TransferFunctionTest, InvalidArgumentsThrow) {
  EXPECT_THAT([] { TransferFunction::Continuous({1.0}, {}); },
              ThrowsMessage<InvalidArgument>(HasSubstr("denominator is empty")));
  EXPECT_THAT(
      [] {
        TransferFunction::Continuous({1.0}, {0.0, 0.0});
      },
      ThrowsMessage<InvalidArgument>(HasSubstr("all zero")));
  EXPECT_THAT(
      [] {
        TransferFunction::Continuous({1.0, 0.0, 0.0}, {1.0, 1.0});
      },
      ThrowsMessage<InvalidArgument>(HasSubstr("improper")));
  EXPECT_THAT(
      [] {
        TransferFunction::Continuous({1.0}, {1.0, 1.0}, -0.1);
      },
      ThrowsMessage<InvalidArgument>(HasSubstr("delay must be >= 0")));
  EXPECT_THAT([] { TransferFunction(Eigen::VectorXd::Ones(1), Eigen::VectorXd::Ones(2), -1.0); },
              ThrowsMessage<InvalidArgument>(HasSubstr("Ts = -1")));
  EXPECT_THAT(
      [] { TransferFunction(Eigen::VectorXd::Ones(1), Eigen::VectorXd::Ones(2), 0.1, 0.15); },
      ThrowsMessage<InvalidArgument>(HasSubstr("multiple of Ts")));
  EXPECT_THAT(
      [] {
        TransferFunction::Discrete({1.0}, {0.0, 1.0}, 0.1);
      },
      ThrowsMessage<InvalidArgument>(HasSubstr("causal")));
  EXPECT_THAT([] { TransferFunction::Continuous({NAN}, {1.0}); },
              ThrowsMessage<InvalidArgument>(HasSubstr("finite")));
  EXPECT_THAT([] { TransferFunction::Fopdt(1.0, 0.0, 0.0); },
              ThrowsMessage<InvalidArgument>(HasSubstr("tau must be > 0")));
  EXPECT_THAT(
      [] {
        TransferFunction::Continuous({1.0}, {1.0, 1.0}).DelaySamples();
      },
      ThrowsMessage<InvalidArgument>(HasSubstr("discrete")));
}

TEST(PolyTest, RootsFromRootsMultiplyAdd) {
  Eigen::VectorXcd r(3);
  r << std::complex<double>(-1, 2), std::complex<double>(-1, -2), -3.0;
  const Eigen::VectorXd p = poly::FromRoots(r);  // (s^2 + 2s + 5)(s + 3)
  Eigen::VectorXd expected(4);
  expected << 1, 5, 11, 15;
  EXPECT_LT((p - expected).norm(), 1e-12);
  const auto back = Sorted(poly::Roots(p));
  EXPECT_NEAR(back[0].real(), -3.0, 1e-12);
  EXPECT_NEAR(back[1].imag(), -2.0, 1e-12);
  Eigen::VectorXd a(2), b(3);
  a << 1, 2;
  b << 1, 0, -1;
  Eigen::VectorXd ab(4);
  ab << 1, 2, -1, -2;
  EXPECT_EQ(poly::Multiply(a, b), ab);
  Eigen::VectorXd sum(3);
  sum << 1, 1, 1;
  EXPECT_EQ(poly::Add(a, b), sum);
  EXPECT_EQ(poly::Evaluate(b, 2.0), std::complex<double>(3.0));
  Eigen::VectorXd lead(3);
  lead << 1e-20, 0, 1;
  EXPECT_EQ(poly::TrimLeading(lead, 1e-12).size(), 1);
  EXPECT_EQ(poly::TrimLeading(lead).size(), 3);
  // Exact roots at the origin.
  Eigen::VectorXd q(3);
  q << 1, 1, 0;
  const auto qr = Sorted(poly::Roots(q));
  EXPECT_EQ(qr[1], std::complex<double>(0.0));
}

TEST(StateSpaceTest, SizesPolesAndDcGain) {
  Eigen::MatrixXd A(2, 2), B(2, 1), C(1, 2), D(1, 1);
  A << -1, 0, 0, -2;
  B << 1, 1;
  C << 1, 1;
  D << 0.5;
  const StateSpace ss(A, B, C, D);
  EXPECT_EQ(ss.num_states(), 2);
  EXPECT_TRUE(ss.IsStable());
  EXPECT_NEAR(ss.DcGain()(0, 0), 0.5 + 1.0 + 0.5, 1e-14);
  const StateSpace sd(A * -0.5, B, C, D, 0.1);  // poles 0.5, 1.0
  EXPECT_FALSE(sd.IsStable());
  EXPECT_TRUE(std::isinf(sd.DcGain()(0, 0)));
  EXPECT_THAT([&] { StateSpace(A, Eigen::MatrixXd(3, 1), C, D); },
              ThrowsMessage<InvalidArgument>(HasSubstr("B must have nx = 2 rows")));
  EXPECT_THAT([&] { StateSpace(A, B, C, Eigen::MatrixXd(2, 1)); },
              ThrowsMessage<InvalidArgument>(HasSubstr("D must be ny x nu")));
  EXPECT_THAT([&] { StateSpace(A, B, C, D, -1.0); },
              ThrowsMessage<InvalidArgument>(HasSubstr("Ts = -1")));
}

}  // namespace
}  // namespace pneumid
