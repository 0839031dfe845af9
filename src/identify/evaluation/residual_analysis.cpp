#include "pneumid/identify/evaluation/residual_analysis.hpp"

#include <cmath>

#include <boost/math/distributions/chi_squared.hpp>
#include <boost/math/distributions/normal.hpp>

#include "pneumid/common/check.hpp"

namespace pneumid {

bool ResidualAnalysisOptions::IsValid(std::string* error) const {
  auto fail = [&](const std::string& m) {
    if (error) *error = m;
    return false;
  };
  if (max_lag < 1) return fail(fmt::format("max_lag must be >= 1, got {}", max_lag));
  if (!(confidence > 0.0 && confidence < 1.0))
    return fail(fmt::format("confidence must be in (0, 1), got {}", confidence));
  return true;
}

Eigen::VectorXd NormalizedCrossCorrelation(const Eigen::VectorXd& x, const Eigen::VectorXd& y,
                                           int max_lag) {
  PNEUMID_CHECK(x.size() == y.size(), "signal lengths differ: {} vs {}", x.size(), y.size());
  const Eigen::Index n = x.size();
  PNEUMID_CHECK(max_lag >= 0 && max_lag < n, "max_lag = {} must be in [0, N = {})", max_lag, n);
  const Eigen::VectorXd xc = x.array() - x.mean();
  const Eigen::VectorXd yc = y.array() - y.mean();
  const double sx = xc.squaredNorm(), sy = yc.squaredNorm();
  PNEUMID_CHECK(sx > 0.0 && sy > 0.0, "a constant signal has no correlation");
  const double norm = std::sqrt(sx * sy);
  Eigen::VectorXd r(2 * max_lag + 1);
  for (int tau = -max_lag; tau <= max_lag; ++tau) {
    // sum_t x(t + tau) y(t)
    const Eigen::Index len = n - std::abs(tau);
    const double s =
        tau >= 0 ? xc.segment(tau, len).dot(yc.head(len)) : xc.head(len).dot(yc.segment(-tau, len));
    r[tau + max_lag] = s / norm;
  }
  return r;
}

ResidualAnalysis AnalyzeResiduals(const Eigen::VectorXd& residuals, const Eigen::VectorXd& u,
                                  const ResidualAnalysisOptions& options) {
  std::string error;
  PNEUMID_CHECK(options.IsValid(&error), "invalid residual-analysis options: {}", error);
  const Eigen::Index n = residuals.size();
  PNEUMID_CHECK(u.size() == n, "residual and input lengths differ: {} vs {}", n, u.size());
  PNEUMID_CHECK(2 * options.max_lag < n, "max_lag = {} needs at least {} samples, got {}",
                options.max_lag, 2 * options.max_lag + 1, n);
  PNEUMID_CHECK(residuals.allFinite(), "the residuals contain a non-finite value");
  const int M = options.max_lag;
  ResidualAnalysis r;
  r.residuals = residuals;
  const Eigen::VectorXd ree = NormalizedCrossCorrelation(residuals, residuals, M);
  r.autocorr = ree.tail(M + 1);
  r.lags_auto = Eigen::VectorXd::LinSpaced(M + 1, 0, M);
  r.crosscorr = NormalizedCrossCorrelation(residuals, u, M);
  r.lags_cross = Eigen::VectorXd::LinSpaced(2 * M + 1, -M, M);
  const double N = static_cast<double>(n);
  const boost::math::normal_distribution<double> normal;
  const double z = boost::math::quantile(normal, 0.5 + options.confidence / 2.0);
  r.bound = z / std::sqrt(N);
  for (int k = 1; k <= M; ++k)
    if (std::abs(r.autocorr[k]) > r.bound) ++r.auto_outside;
  for (Eigen::Index k = 0; k < r.crosscorr.size(); ++k)
    if (std::abs(r.crosscorr[k]) > r.bound) ++r.cross_outside;
  r.whiteness_statistic = N * r.autocorr.tail(M).squaredNorm();
  r.independence_statistic = N * r.crosscorr.squaredNorm();
  r.whiteness_threshold =
      boost::math::quantile(boost::math::chi_squared_distribution<double>(M), options.confidence);
  r.independence_threshold = boost::math::quantile(
      boost::math::chi_squared_distribution<double>(2 * M + 1), options.confidence);
  r.whiteness_passed = r.whiteness_statistic < r.whiteness_threshold;
  r.independence_passed = r.independence_statistic < r.independence_threshold;
  return r;
}

ResidualAnalysis AnalyzeWhiteness(const Eigen::VectorXd& residuals,
                                  const ResidualAnalysisOptions& options) {
  std::string error;
  PNEUMID_CHECK(options.IsValid(&error), "invalid residual-analysis options: {}", error);
  const Eigen::Index n = residuals.size();
  PNEUMID_CHECK(2 * options.max_lag < n, "max_lag = {} needs at least {} samples, got {}",
                options.max_lag, 2 * options.max_lag + 1, n);
  PNEUMID_CHECK(residuals.allFinite(), "the residuals contain a non-finite value");
  const int M = options.max_lag;
  const Eigen::VectorXd e = residuals.array() - residuals.mean();
  const double s0 = e.squaredNorm();
  PNEUMID_CHECK(s0 > 0.0, "a constant signal has no correlation");
  ResidualAnalysis r;
  r.autocorr.resize(M + 1);
  for (int tau = 0; tau <= M; ++tau) {
    const Eigen::Index len = n - tau;
    r.autocorr[tau] = e.segment(tau, len).dot(e.head(len)) / s0;
  }
  r.lags_auto = Eigen::VectorXd::LinSpaced(M + 1, 0, M);
  const double N = static_cast<double>(n);
  const boost::math::normal_distribution<double> normal;
  r.bound = boost::math::quantile(normal, 0.5 + options.confidence / 2.0) / std::sqrt(N);
  for (int k = 1; k <= M; ++k)
    if (std::abs(r.autocorr[k]) > r.bound) ++r.auto_outside;
  r.whiteness_statistic = N * r.autocorr.tail(M).squaredNorm();
  r.whiteness_threshold =
      boost::math::quantile(boost::math::chi_squared_distribution<double>(M), options.confidence);
  r.whiteness_passed = r.whiteness_statistic < r.whiteness_threshold;
  return r;
}

ResidualAnalysis AnalyzeResiduals(const PolynomialModel& model, const Dataset& data,
                                  const ResidualAnalysisOptions& options, int input, int output) {
  model.Validate();
  PNEUMID_CHECK(input >= 0 && input < data.num_inputs(), "input column {} out of range [0, {})",
                input, data.num_inputs());
  PNEUMID_CHECK(output >= 0 && output < data.num_outputs(), "output column {} out of range [0, {})",
                output, data.num_outputs());
  Eigen::MatrixXd u;
  if (model.num_inputs() == 1)
    u = data.u(input);
  else
    u = data.inputs();
  const Eigen::VectorXd eps = PredictionErrors(model, data.y(output), u);
  return AnalyzeResiduals(eps, data.u(input), options);
}

std::string ResidualAnalysis::BriefReport() const {
  return fmt::format(
      "residuals white: {} (Q = {:.4g} vs {:.4g}, {} of {} lags outside +-{:.3g}); independent "
      "of input: {} (Q = {:.4g} vs {:.4g}, {} of {} lags outside)",
      whiteness_passed ? "pass" : "FAIL", whiteness_statistic, whiteness_threshold, auto_outside,
      autocorr.size() - 1, bound, independence_passed ? "pass" : "FAIL", independence_statistic,
      independence_threshold, cross_outside, crosscorr.size());
}

nlohmann::json ResidualAnalysis::ToJson() const {
  auto vec = [](const Eigen::VectorXd& v) {
    return std::vector<double>(v.data(), v.data() + v.size());
  };
  nlohmann::json j;
  j["bound"] = bound;
  j["autocorrelation"] = {
      {"lags", vec(lags_auto)}, {"values", vec(autocorr)}, {"outside", auto_outside}};
  j["crosscorrelation"] = {
      {"lags", vec(lags_cross)}, {"values", vec(crosscorr)}, {"outside", cross_outside}};
  j["whiteness"] = {{"statistic", whiteness_statistic},
                    {"threshold", whiteness_threshold},
                    {"passed", whiteness_passed}};
  j["independence"] = {{"statistic", independence_statistic},
                       {"threshold", independence_threshold},
                       {"passed", independence_passed}};
  j["passed"] = passed();
  return j;
}

}  // namespace pneumid
