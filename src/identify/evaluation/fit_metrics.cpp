#include "pneumid/identify/evaluation/fit_metrics.hpp"

#include <cmath>

#include "pneumid/common/check.hpp"

namespace pneumid {
namespace {

void CheckPair(const Eigen::VectorXd& y, const Eigen::VectorXd& yhat, Eigen::Index min_size,
               const char* what) {
  PNEUMID_CHECK(y.size() == yhat.size(), "{}: y has {} samples but yhat has {}", what, y.size(),
                yhat.size());
  PNEUMID_CHECK(y.size() >= min_size, "{}: needs at least {} samples, got {}", what, min_size,
                y.size());
  for (Eigen::Index k = 0; k < y.size(); ++k) {
    PNEUMID_CHECK(std::isfinite(y[k]), "{}: y[{}] = {} is not finite", what, k, y[k]);
    PNEUMID_CHECK(std::isfinite(yhat[k]), "{}: yhat[{}] = {} is not finite", what, k, yhat[k]);
  }
}

}  // namespace

double NrmseFit(const Eigen::VectorXd& y, const Eigen::VectorXd& yhat) {
  CheckPair(y, yhat, 2, "NrmseFit");
  const double spread = (y.array() - y.mean()).matrix().norm();
  PNEUMID_CHECK(spread > 0.0, "NrmseFit: the measured output is constant (y = {}), fit undefined",
                y[0]);
  return 100.0 * (1.0 - (y - yhat).norm() / spread);
}

double Iae(const Eigen::VectorXd& t, const Eigen::VectorXd& y, const Eigen::VectorXd& yhat) {
  CheckPair(y, yhat, 2, "Iae");
  PNEUMID_CHECK(t.size() == y.size(), "Iae: t has {} samples but y has {}", t.size(), y.size());
  double sum = 0.0;
  for (Eigen::Index k = 1; k < t.size(); ++k) {
    const double dt = t[k] - t[k - 1];
    PNEUMID_CHECK(dt > 0.0 && std::isfinite(dt),
                  "Iae: time must be strictly increasing, t[{}] = {} after t[{}] = {}", k, t[k],
                  k - 1, t[k - 1]);
    sum += 0.5 * dt * (std::abs(y[k] - yhat[k]) + std::abs(y[k - 1] - yhat[k - 1]));
  }
  return sum;
}

double Iae(const Eigen::VectorXd& y, const Eigen::VectorXd& yhat, double dt) {
  CheckPair(y, yhat, 2, "Iae");
  PNEUMID_CHECK(dt > 0.0 && std::isfinite(dt), "Iae: sample interval must be positive, got dt = {}",
                dt);
  const Eigen::ArrayXd e = (y - yhat).array().abs();
  return dt * (e.sum() - 0.5 * (e[0] + e[e.size() - 1]));
}

double Rmse(const Eigen::VectorXd& y, const Eigen::VectorXd& yhat) {
  CheckPair(y, yhat, 1, "Rmse");
  return std::sqrt((y - yhat).squaredNorm() / static_cast<double>(y.size()));
}

FitMetrics ComputeFitMetrics(const Eigen::VectorXd& t, const Eigen::VectorXd& y,
                             const Eigen::VectorXd& yhat) {
  FitMetrics m;
  m.fit_percent = NrmseFit(y, yhat);
  m.iae = Iae(t, y, yhat);
  m.rmse = Rmse(y, yhat);
  m.max_abs_error = (y - yhat).cwiseAbs().maxCoeff();
  return m;
}

}  // namespace pneumid
