// SISO transfer function for both time domains, after python-control's
// xferfcn.py and Drake's linear_system.h (a sample time of 0 means continuous).
//
//   continuous:  G(s) = (b0 s^m + ... + bm) / (a0 s^n + ... + an) * exp(-theta s)
//   discrete:    G(z) = (b0 + b1 z^-1 + ... ) / (a0 + a1 z^-1 + ...) * z^-d,  d = theta / Ts
//
// Storage: `num` and `den` hold coefficients in descending powers of s for a
// continuous model, and in ascending powers of z^-1 for a discrete model (the
// System Identification convention: B(q) = b0 + b1 q^-1 + ...). For a discrete
// model both vectors are kept the same length (padded with trailing zeros), so
// that they are at the same time the descending powers of z.
// The input delay `delay` is always in seconds; for a discrete model it must
// be an integer multiple of Ts (see DelaySamples()).
// A discrete model needs a0 != 0 (causality); common trailing zeros of the
// two vectors (a cancelling factor z^k) are removed. A continuous denominator
// is stored without leading zeros.
#pragma once

#include <complex>
#include <string>
#include <vector>

#include <Eigen/Core>

namespace pneumid {

/// SISO transfer function, continuous (Ts = 0) or discrete, with an input delay in s
/// (storage conventions above).
class TransferFunction {
 public:
  /// The static gain 1, continuous.
  TransferFunction();
  /// Throws InvalidArgument for an empty or all-zero denominator, Ts < 0,
  /// delay < 0, a discrete delay that is not a multiple of Ts, or an improper
  /// continuous model (deg num > deg den).
  TransferFunction(Eigen::VectorXd num, Eigen::VectorXd den, double Ts = 0.0, double delay = 0.0);

  /// Continuous model, coefficients in descending powers of s, delay in seconds.
  static TransferFunction Continuous(const std::vector<double>& num, const std::vector<double>& den,
                                     double delay = 0.0);
  /// Discrete model, coefficients in ascending powers of z^-1, delay in samples.
  static TransferFunction Discrete(const std::vector<double>& num_zinv,
                                   const std::vector<double>& den_zinv, double Ts,
                                   int delay_samples = 0);
  /// K exp(-theta s) / (tau s + 1).
  static TransferFunction Fopdt(double K, double tau, double theta);
  /// K exp(-theta s) / ((tau1 s + 1)(tau2 s + 1)).
  static TransferFunction Sopdt(double K, double tau1, double tau2, double theta);

  /// Numerator: descending powers of s, or ascending powers of z^-1 (see above).
  const Eigen::VectorXd& num() const { return num_; }
  /// Denominator, same convention as num() (same length as num() when discrete).
  const Eigen::VectorXd& den() const { return den_; }
  double Ts() const { return Ts_; }                 ///< sample time in s; 0 for continuous
  bool IsDiscrete() const { return Ts_ > 0.0; }     ///< Ts > 0
  bool IsContinuous() const { return Ts_ == 0.0; }  ///< Ts == 0
  /// Input delay in seconds.
  double delay() const { return delay_; }
  /// Input delay in samples (discrete models only; throws otherwise).
  int DelaySamples() const;
  /// Copy with another delay (seconds).
  TransferFunction WithDelay(double delay) const;

  /// Number of poles (degree of the denominator after removing leading zeros).
  int Order() const;
  /// Roots of the denominator / numerator in s or z.
  Eigen::VectorXcd Poles() const;
  Eigen::VectorXcd Zeros() const;  ///< roots of the numerator (see Poles)
  /// G(0) continuous, G(1) discrete; +-inf for a pole at the origin / at 1.
  double DcGain() const;
  /// All poles in the open left half plane / strictly inside the unit circle.
  bool IsStable() const;

  /// Value of the rational part at a complex point (s or z), without delay.
  std::complex<double> Evaluate(std::complex<double> point) const;
  /// Frequency response at angular frequency w (rad/s) including the delay:
  /// G(jw) continuous, G(exp(jw Ts)) discrete.
  std::complex<double> FrequencyResponse(double w) const;

  /// Same model with a monic denominator (leading coefficient a0 = 1) and
  /// leading zeros of the numerator (continuous) removed.
  TransferFunction Normalized() const;

  /// Human-readable form, e.g. "(6.102 s^2 - 91.95 s + 5.2e+05) / (s^3 + ...)".
  std::string ToString(int precision = 6) const;

 private:
  Eigen::VectorXd num_;
  Eigen::VectorXd den_;
  double Ts_ = 0.0;
  double delay_ = 0.0;
};

/// Largest delay in samples that a model may carry (1e8): a delay is held
/// as an int count of samples and, in state space, as that many states.
inline constexpr double kMaxDelaySamples = 1e8;

/// round(delay / Ts), the delay of `delay` s in samples of `Ts` s.
/// @throws InvalidArgument (naming both and the count) for a negative or
/// non-finite count or one above kMaxDelaySamples: the conversion to int
/// would overflow, and a model that long has no use.
int DelayInSamples(double delay, double Ts);

/// Polynomial helpers (descending powers).
namespace poly {
/// Roots of p(x) = p0 x^n + ... + pn (companion matrix eigenvalues).
Eigen::VectorXcd Roots(const Eigen::VectorXd& p);
/// Monic real polynomial with the given roots (complex roots in conjugate pairs).
Eigen::VectorXd FromRoots(const Eigen::VectorXcd& roots);
/// Product a b (convolution of the coefficients); [0] when either is empty.
Eigen::VectorXd Multiply(const Eigen::VectorXd& a, const Eigen::VectorXd& b);
/// Sum a + b, the shorter aligned at the constant term (zero-padded in front).
Eigen::VectorXd Add(const Eigen::VectorXd& a, const Eigen::VectorXd& b);
/// p(x) by Horner's rule; 0 for an empty p.
std::complex<double> Evaluate(const Eigen::VectorXd& p, std::complex<double> x);
/// Drops leading coefficients whose magnitude is <= tol * max|p|.
Eigen::VectorXd TrimLeading(const Eigen::VectorXd& p, double tol = 0.0);
}  // namespace poly

}  // namespace pneumid
