#include "pneumid/lti/transfer_function.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>
#include <utility>

#include <fmt/format.h>
#include <Eigen/Eigenvalues>

#include "pneumid/common/check.hpp"

namespace pneumid {

namespace {

bool AllFinite(const Eigen::VectorXd& v) { return v.allFinite(); }

// Number of whole samples in `delay`, accepting a relative rounding error.
bool IsSampleMultiple(double delay, double Ts, int* samples) {
  const double r = delay / Ts;
  const double n = std::round(r);
  if (std::abs(r - n) > 1e-9 * std::max(1.0, std::abs(r))) return false;
  if (n > static_cast<double>(std::numeric_limits<int>::max())) return false;
  if (samples != nullptr) *samples = static_cast<int>(n);
  return true;
}

std::string FormatCoefficient(double c, int precision) {
  return fmt::format("{:.{}g}", c, precision);
}

// Writes sum c_i * term(i) with signs, skipping zero coefficients.
template <typename TermFn>
std::string FormatPolynomial(const Eigen::VectorXd& p, int precision, TermFn term) {
  std::string out;
  for (Eigen::Index i = 0; i < p.size(); ++i) {
    const double c = p[i];
    if (c == 0.0) continue;
    const std::string t = term(i);
    const double mag = std::abs(c);
    std::string coef;
    if (t.empty() || mag != 1.0) coef = FormatCoefficient(mag, precision);
    if (out.empty()) {
      if (c < 0) out += "-";
    } else {
      out += c < 0 ? " - " : " + ";
    }
    out += coef;
    if (!coef.empty() && !t.empty()) out += " ";
    out += t;
  }
  return out.empty() ? "0" : out;
}

}  // namespace

TransferFunction::TransferFunction()
    : num_(Eigen::VectorXd::Ones(1)), den_(Eigen::VectorXd::Ones(1)) {}

TransferFunction::TransferFunction(Eigen::VectorXd num, Eigen::VectorXd den, double Ts,
                                   double delay)
    : num_(std::move(num)), den_(std::move(den)), Ts_(Ts), delay_(delay) {
  PNEUMID_CHECK(den_.size() > 0, "transfer function: the denominator is empty");
  if (num_.size() == 0) num_ = Eigen::VectorXd::Zero(1);
  PNEUMID_CHECK(AllFinite(num_) && AllFinite(den_),
                "transfer function: coefficients must be finite, got num = [{}], den = [{}]",
                fmt::join(num_.begin(), num_.end(), ", "),
                fmt::join(den_.begin(), den_.end(), ", "));
  PNEUMID_CHECK(den_.cwiseAbs().maxCoeff() > 0.0,
                "transfer function: the denominator is all zero, den = [{}]",
                fmt::join(den_.begin(), den_.end(), ", "));
  PNEUMID_CHECK(std::isfinite(Ts) && Ts >= 0.0,
                "transfer function: sample time must be >= 0 (0 = continuous), got Ts = {}", Ts);
  PNEUMID_CHECK(std::isfinite(delay) && delay >= 0.0,
                "transfer function: delay must be >= 0 seconds, got delay = {}", delay);
  if (Ts_ == 0.0) {
    den_ = poly::TrimLeading(den_);
    const Eigen::VectorXd n = poly::TrimLeading(num_);
    const bool num_zero = n.size() == 1 && n[0] == 0.0;
    PNEUMID_CHECK(num_zero || n.size() <= den_.size(),
                  "transfer function: improper continuous model, numerator degree {} > "
                  "denominator degree {}",
                  n.size() - 1, den_.size() - 1);
    if (num_.size() > den_.size()) num_ = n;  // only leading zeros were dropped
  } else {
    PNEUMID_CHECK(den_[0] != 0.0,
                  "transfer function: the first denominator coefficient a0 (of z^0) must be "
                  "nonzero for a causal discrete model, got den = [{}]",
                  fmt::join(den_.begin(), den_.end(), ", "));
    int d = 0;
    PNEUMID_CHECK(IsSampleMultiple(delay, Ts, &d),
                  "transfer function: a discrete delay must be a multiple of Ts, got delay = {} "
                  "s with Ts = {} s ({} samples)",
                  delay, Ts, delay / Ts);
    delay_ = d * Ts;
    const Eigen::Index n = std::max(num_.size(), den_.size());
    Eigen::VectorXd nn = Eigen::VectorXd::Zero(n), dd = Eigen::VectorXd::Zero(n);
    nn.head(num_.size()) = num_;
    dd.head(den_.size()) = den_;
    // Common trailing zeros are a cancelling factor z^k.
    Eigen::Index len = n;
    while (len > 1 && nn[len - 1] == 0.0 && dd[len - 1] == 0.0) --len;
    num_ = nn.head(len);
    den_ = dd.head(len);
  }
}

TransferFunction TransferFunction::Continuous(const std::vector<double>& num,
                                              const std::vector<double>& den, double delay) {
  return TransferFunction(Eigen::Map<const Eigen::VectorXd>(num.data(), num.size()),
                          Eigen::Map<const Eigen::VectorXd>(den.data(), den.size()), 0.0, delay);
}

TransferFunction TransferFunction::Discrete(const std::vector<double>& num_zinv,
                                            const std::vector<double>& den_zinv, double Ts,
                                            int delay_samples) {
  PNEUMID_CHECK(Ts > 0.0, "discrete transfer function: sample time must be > 0, got Ts = {}", Ts);
  PNEUMID_CHECK(delay_samples >= 0,
                "discrete transfer function: delay must be >= 0 samples, got {}", delay_samples);
  return TransferFunction(Eigen::Map<const Eigen::VectorXd>(num_zinv.data(), num_zinv.size()),
                          Eigen::Map<const Eigen::VectorXd>(den_zinv.data(), den_zinv.size()), Ts,
                          delay_samples * Ts);
}

TransferFunction TransferFunction::Fopdt(double K, double tau, double theta) {
  PNEUMID_CHECK(std::isfinite(K), "FOPDT: gain K must be finite, got K = {}", K);
  PNEUMID_CHECK(std::isfinite(tau) && tau > 0.0,
                "FOPDT: time constant tau must be > 0 s, got tau = {}", tau);
  PNEUMID_CHECK(std::isfinite(theta) && theta >= 0.0,
                "FOPDT: dead time theta must be >= 0 s, got theta = {}", theta);
  return Continuous({K}, {tau, 1.0}, theta);
}

TransferFunction TransferFunction::Sopdt(double K, double tau1, double tau2, double theta) {
  PNEUMID_CHECK(std::isfinite(K), "SOPDT: gain K must be finite, got K = {}", K);
  PNEUMID_CHECK(std::isfinite(tau1) && tau1 > 0.0,
                "SOPDT: time constant tau1 must be > 0 s, got tau1 = {}", tau1);
  PNEUMID_CHECK(std::isfinite(tau2) && tau2 > 0.0,
                "SOPDT: time constant tau2 must be > 0 s, got tau2 = {}", tau2);
  PNEUMID_CHECK(std::isfinite(theta) && theta >= 0.0,
                "SOPDT: dead time theta must be >= 0 s, got theta = {}", theta);
  return Continuous({K}, {tau1 * tau2, tau1 + tau2, 1.0}, theta);
}

int TransferFunction::DelaySamples() const {
  PNEUMID_CHECK(IsDiscrete(),
                "DelaySamples() needs a discrete model; this one is continuous (delay = {} s)",
                delay_);
  return DelayInSamples(delay_, Ts_);
}

int DelayInSamples(double delay, double Ts) {
  const double samples = delay / Ts;
  PNEUMID_CHECK(std::isfinite(samples) && samples >= 0.0 && samples <= kMaxDelaySamples,
                "a delay of {} s at a sample time of {} s is {} samples; pneumid holds delays of "
                "0 to {:g} samples (choose a longer sample time or check the delay's unit)",
                delay, Ts, samples, kMaxDelaySamples);
  return static_cast<int>(std::lround(samples));
}

TransferFunction TransferFunction::WithDelay(double delay) const {
  return TransferFunction(num_, den_, Ts_, delay);
}

int TransferFunction::Order() const { return static_cast<int>(poly::TrimLeading(den_).size()) - 1; }

Eigen::VectorXcd TransferFunction::Poles() const { return poly::Roots(den_); }

Eigen::VectorXcd TransferFunction::Zeros() const { return poly::Roots(num_); }

double TransferFunction::DcGain() const {
  const double n = IsDiscrete() ? num_.sum() : num_[num_.size() - 1];
  const double d = IsDiscrete() ? den_.sum() : den_[den_.size() - 1];
  if (d == 0.0) {
    if (n == 0.0) return std::numeric_limits<double>::quiet_NaN();
    return n > 0 ? std::numeric_limits<double>::infinity()
                 : -std::numeric_limits<double>::infinity();
  }
  return n / d;
}

bool TransferFunction::IsStable() const {
  const Eigen::VectorXcd p = Poles();
  for (Eigen::Index i = 0; i < p.size(); ++i) {
    if (IsDiscrete() ? std::abs(p[i]) >= 1.0 : p[i].real() >= 0.0) return false;
  }
  return true;
}

std::complex<double> TransferFunction::Evaluate(std::complex<double> point) const {
  return poly::Evaluate(num_, point) / poly::Evaluate(den_, point);
}

std::complex<double> TransferFunction::FrequencyResponse(double w) const {
  const std::complex<double> j(0.0, 1.0);
  const std::complex<double> point = IsDiscrete() ? std::exp(j * w * Ts_) : j * w;
  return Evaluate(point) * std::exp(-j * w * delay_);
}

TransferFunction TransferFunction::Normalized() const {
  const Eigen::VectorXd den = poly::TrimLeading(den_);
  const double a0 = den[0];
  if (IsDiscrete()) return TransferFunction(num_ / a0, den_ / a0, Ts_, delay_);
  return TransferFunction(poly::TrimLeading(num_) / a0, den / a0, Ts_, delay_);
}

std::string TransferFunction::ToString(int precision) const {
  std::string num, den, delay;
  if (IsContinuous()) {
    auto term = [](Eigen::Index n) {
      return [n](Eigen::Index i) -> std::string {
        const Eigen::Index p = n - 1 - i;
        if (p == 0) return "";
        if (p == 1) return "s";
        return fmt::format("s^{}", p);
      };
    };
    const Eigen::VectorXd nt = poly::TrimLeading(num_);
    num = FormatPolynomial(nt, precision, term(nt.size()));
    den = FormatPolynomial(den_, precision, term(den_.size()));
    if (delay_ > 0) delay = fmt::format(" * exp(-{} s)", FormatCoefficient(delay_, precision));
  } else {
    auto term = [](Eigen::Index i) -> std::string {
      if (i == 0) return "";
      if (i == 1) return "z^-1";
      return fmt::format("z^-{}", i);
    };
    num = FormatPolynomial(num_, precision, term);
    den = FormatPolynomial(den_, precision, term);
    const int d = DelaySamples();
    if (d > 0) delay = fmt::format(" * z^-{}", d);
  }
  std::string out = fmt::format("({}) / ({}){}", num, den, delay);
  if (IsDiscrete()) out += fmt::format(", Ts = {}", FormatCoefficient(Ts_, precision));
  return out;
}

namespace poly {

Eigen::VectorXd TrimLeading(const Eigen::VectorXd& p, double tol) {
  if (p.size() == 0) return Eigen::VectorXd::Zero(1);
  const double threshold = tol * p.cwiseAbs().maxCoeff();
  Eigen::Index first = 0;
  while (first < p.size() - 1 && std::abs(p[first]) <= threshold) ++first;
  return p.tail(p.size() - first);
}

Eigen::VectorXcd Roots(const Eigen::VectorXd& p_in) {
  Eigen::VectorXd p = TrimLeading(p_in);
  const Eigen::Index n = p.size() - 1;
  if (n <= 0) return Eigen::VectorXcd(0);
  PNEUMID_CHECK(p[0] != 0.0, "poly::Roots: the zero polynomial has no roots");
  // Roots at the origin exactly (trailing zeros), then the companion matrix.
  Eigen::Index zeros_at_origin = 0;
  while (zeros_at_origin < n && p[n - zeros_at_origin] == 0.0) ++zeros_at_origin;
  const Eigen::Index m = n - zeros_at_origin;
  Eigen::VectorXcd roots = Eigen::VectorXcd::Zero(n);
  if (m > 0) {
    Eigen::MatrixXd companion = Eigen::MatrixXd::Zero(m, m);
    for (Eigen::Index j = 0; j < m; ++j) companion(0, j) = -p[j + 1] / p[0];
    for (Eigen::Index i = 1; i < m; ++i) companion(i, i - 1) = 1.0;
    Eigen::EigenSolver<Eigen::MatrixXd> es(companion, false);
    roots.head(m) = es.eigenvalues();
  }
  return roots;
}

Eigen::VectorXd FromRoots(const Eigen::VectorXcd& roots) {
  Eigen::VectorXcd c = Eigen::VectorXcd::Zero(roots.size() + 1);
  c[0] = 1.0;
  for (Eigen::Index k = 0; k < roots.size(); ++k) {
    for (Eigen::Index i = k + 1; i >= 1; --i) c[i] -= roots[k] * c[i - 1];
  }
  return c.real();
}

Eigen::VectorXd Multiply(const Eigen::VectorXd& a, const Eigen::VectorXd& b) {
  if (a.size() == 0 || b.size() == 0) return Eigen::VectorXd::Zero(1);
  Eigen::VectorXd c = Eigen::VectorXd::Zero(a.size() + b.size() - 1);
  for (Eigen::Index i = 0; i < a.size(); ++i) c.segment(i, b.size()) += a[i] * b;
  return c;
}

Eigen::VectorXd Add(const Eigen::VectorXd& a, const Eigen::VectorXd& b) {
  const Eigen::Index n = std::max(a.size(), b.size());
  Eigen::VectorXd c = Eigen::VectorXd::Zero(n);
  c.tail(a.size()) += a;
  c.tail(b.size()) += b;
  return c;
}

std::complex<double> Evaluate(const Eigen::VectorXd& p, std::complex<double> x) {
  std::complex<double> acc = 0.0;
  for (Eigen::Index i = 0; i < p.size(); ++i) acc = acc * x + p[i];
  return acc;
}

}  // namespace poly

}  // namespace pneumid
