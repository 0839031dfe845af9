// Private helpers of the parametric estimators: linear filtering of sampled
// signals by rational operators in the delay q^-1, templated on the scalar so
// that the prediction-error cost can be differentiated with ceres::Jet.
#pragma once

#include <cstddef>
#include <vector>

#include <Eigen/Core>

namespace pneumid::internal {

/// y = (num(q^-1) / den(q^-1)) x with zero initial conditions, like
/// scipy.signal.lfilter(num, den, x). den[0] must be non-zero.
template <typename T, typename NumVec, typename DenVec>
std::vector<T> Filter(const NumVec& num, int nnum, const DenVec& den, int nden,
                      const std::vector<T>& x) {
  const std::size_t n = x.size();
  std::vector<T> y(n);
  const T inv_a0 = T(1.0) / den[0];
  for (std::size_t t = 0; t < n; ++t) {
    T acc = T(0.0);
    const int kb = static_cast<int>(std::min<std::size_t>(nnum - 1, t));
    for (int k = 0; k <= kb; ++k) acc += num[k] * x[t - k];
    const int ka = static_cast<int>(std::min<std::size_t>(nden - 1, t));
    for (int k = 1; k <= ka; ++k) acc -= den[k] * y[t - k];
    y[t] = acc * inv_a0;
  }
  return y;
}

/// Double-precision Eigen version.
inline Eigen::VectorXd Filter(const Eigen::VectorXd& num, const Eigen::VectorXd& den,
                              const Eigen::VectorXd& x) {
  const Eigen::Index n = x.size();
  Eigen::VectorXd y(n);
  const double inv_a0 = 1.0 / den[0];
  const Eigen::Index nb = num.size(), na = den.size();
  for (Eigen::Index t = 0; t < n; ++t) {
    double acc = 0.0;
    const Eigen::Index kb = std::min<Eigen::Index>(nb - 1, t);
    for (Eigen::Index k = 0; k <= kb; ++k) acc += num[k] * x[t - k];
    const Eigen::Index ka = std::min<Eigen::Index>(na - 1, t);
    for (Eigen::Index k = 1; k <= ka; ++k) acc -= den[k] * y[t - k];
    y[t] = acc * inv_a0;
  }
  return y;
}

/// Product of two polynomials in q^-1 (coefficient convolution).
inline Eigen::VectorXd Convolve(const Eigen::VectorXd& a, const Eigen::VectorXd& b) {
  Eigen::VectorXd c = Eigen::VectorXd::Zero(a.size() + b.size() - 1);
  for (Eigen::Index i = 0; i < a.size(); ++i)
    for (Eigen::Index j = 0; j < b.size(); ++j) c[i + j] += a[i] * b[j];
  return c;
}

}  // namespace pneumid::internal
