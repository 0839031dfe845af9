#include "pneumid/identify/nonparametric/cra.hpp"

#include <cmath>

#include <boost/math/distributions/normal.hpp>

#include "../parametric_filter.hpp"
#include "pneumid/common/check.hpp"
#include "pneumid/identify/parametric/arx.hpp"

namespace pneumid {

bool CraOptions::IsValid(std::string* error) const {
  auto fail = [&](const std::string& m) {
    if (error) *error = m;
    return false;
  };
  if (num_lags < 1) return fail(fmt::format("num_lags must be >= 1, got {}", num_lags));
  if (prewhitening_order < 0)
    return fail(fmt::format("prewhitening_order must be >= 0, got {}", prewhitening_order));
  if (!(confidence > 0 && confidence < 1))
    return fail(fmt::format("confidence must be in (0, 1), got {}", confidence));
  return true;
}

CraResult Cra(const Eigen::VectorXd& y, const Eigen::VectorXd& u, double Ts, const CraOptions& o) {
  std::string error;
  PNEUMID_CHECK(o.IsValid(&error), "invalid correlation-analysis options: {}", error);
  PNEUMID_CHECK(Ts > 0, "sample time must be positive, got Ts = {}", Ts);
  PNEUMID_CHECK(y.size() == u.size(), "output and input lengths differ: {} vs {}", y.size(),
                u.size());
  PNEUMID_CHECK(y.allFinite() && u.allFinite(), "the data contain a non-finite value");
  const Eigen::Index n = y.size();
  PNEUMID_CHECK(4 * (o.num_lags + o.prewhitening_order) < n,
                "{} samples are too few for {} lags and prewhitening order {}", n, o.num_lags,
                o.prewhitening_order);
  const Eigen::VectorXd uc = u.array() - u.mean();
  const Eigen::VectorXd yc = y.array() - y.mean();
  PNEUMID_CHECK(uc.squaredNorm() > 0, "the input is constant: no correlation analysis possible");
  Eigen::VectorXd L = Eigen::VectorXd::Ones(1);
  if (o.prewhitening_order > 0) {
    ArxOptions ao;
    ao.na = o.prewhitening_order;
    ao.nb = {0};
    ao.nk = {0};
    const Eigen::MatrixXd zero = Eigen::MatrixXd::Zero(n, 1);
    const ArxResult ar = EstimateArx(uc, zero, Ts, ao);
    if (ar.summary.termination == Termination::kConvergence) L = ar.model.a;
  }
  const Eigen::VectorXd one = Eigen::VectorXd::Ones(1);
  const Eigen::Index skip = L.size() - 1;
  const Eigen::VectorXd uf = internal::Filter(L, one, uc).tail(n - skip);
  const Eigen::VectorXd yf = internal::Filter(L, one, yc).tail(n - skip);
  const Eigen::Index nf = uf.size();
  const double ruu0 = uf.squaredNorm() / static_cast<double>(nf);
  const double ryy0 = yf.squaredNorm() / static_cast<double>(nf);
  CraResult r;
  r.Ts = Ts;
  const int M = o.num_lags;
  r.lags = Eigen::VectorXd::LinSpaced(M + 1, 0, M);
  r.t = r.lags * Ts;
  r.impulse.resize(M + 1);
  for (int k = 0; k <= M; ++k) {
    const double ryu = yf.tail(nf - k).dot(uf.head(nf - k)) / static_cast<double>(nf);
    r.impulse[k] = ryu / ruu0;
  }
  r.step.resize(M + 1);
  double acc = 0;
  for (int k = 0; k <= M; ++k) r.step[k] = (acc += r.impulse[k]);
  const double z =
      boost::math::quantile(boost::math::normal_distribution<double>(), 0.5 + o.confidence / 2);
  r.bound = z * std::sqrt(ryy0 / (static_cast<double>(nf) * ruu0));
  return r;
}

CraResult Cra(const Dataset& data, const CraOptions& options, int input, int output) {
  data.RequireUniform();
  PNEUMID_CHECK(input >= 0 && input < data.num_inputs(), "input column {} out of range [0, {})",
                input, data.num_inputs());
  PNEUMID_CHECK(output >= 0 && output < data.num_outputs(), "output column {} out of range [0, {})",
                output, data.num_outputs());
  data.RequireSamples(4 * (options.num_lags + options.prewhitening_order) + 1, "cra");
  return Cra(data.y(output), data.u(input), data.SampleTime(), options);
}

nlohmann::json CraResult::ToJson() const {
  auto vec = [](const Eigen::VectorXd& v) {
    return std::vector<double>(v.data(), v.data() + v.size());
  };
  return {
      {"t", vec(t)}, {"impulse", vec(impulse)}, {"step", vec(step)}, {"bound", bound}, {"Ts", Ts}};
}

}  // namespace pneumid
