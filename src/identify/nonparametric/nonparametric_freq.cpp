#include "pneumid/identify/nonparametric/nonparametric_freq.hpp"

#include <cmath>
#include <vector>

#include <unsupported/Eigen/FFT>

#include "pneumid/common/check.hpp"

namespace pneumid {

namespace {

void CheckSignals(const Eigen::VectorXd& y, const Eigen::VectorXd& u, double Ts) {
  PNEUMID_CHECK(Ts > 0, "sample time must be positive, got Ts = {}", Ts);
  PNEUMID_CHECK(y.size() == u.size(), "output and input lengths differ: {} vs {}", y.size(),
                u.size());
  PNEUMID_CHECK(y.size() >= 8, "at least 8 samples needed, got {}", y.size());
  PNEUMID_CHECK(y.allFinite() && u.allFinite(), "the data contain a non-finite value");
  PNEUMID_CHECK((u.array() - u.mean()).matrix().squaredNorm() > 0,
                "the input is constant: no frequency response can be estimated");
}

void Finish(FrequencyResponseEstimate* r) {
  const Eigen::Index k = r->response.size();
  r->magnitude = r->response.cwiseAbs();
  r->phase_deg.resize(k);
  double prev = 0, offset = 0;
  for (Eigen::Index i = 0; i < k; ++i) {
    double ph = std::arg(r->response[i]);
    if (i > 0) {
      while (ph + offset - prev > M_PI) offset -= 2 * M_PI;
      while (ph + offset - prev < -M_PI) offset += 2 * M_PI;
    }
    prev = ph + offset;
    r->phase_deg[i] = prev * 180.0 / M_PI;
  }
}

// 1/N sum_t x(t + tau) y(t), tau >= 0.
double Cov(const Eigen::VectorXd& x, const Eigen::VectorXd& y, Eigen::Index tau) {
  const Eigen::Index n = x.size();
  return x.tail(n - tau).dot(y.head(n - tau)) / static_cast<double>(n);
}

}  // namespace

bool SpaOptions::IsValid(std::string* error) const {
  auto fail = [&](const std::string& m) {
    if (error) *error = m;
    return false;
  };
  if (lag_window < 0) return fail(fmt::format("lag_window must be >= 0, got {}", lag_window));
  if (num_frequencies < 1)
    return fail(fmt::format("num_frequencies must be >= 1, got {}", num_frequencies));
  return true;
}

bool EtfeOptions::IsValid(std::string* error) const {
  if (num_frequencies < 0) {
    if (error) *error = fmt::format("num_frequencies must be >= 0, got {}", num_frequencies);
    return false;
  }
  return true;
}

FrequencyResponseEstimate Spa(const Eigen::VectorXd& y, const Eigen::VectorXd& u, double Ts,
                              const SpaOptions& o) {
  std::string error;
  PNEUMID_CHECK(o.IsValid(&error), "invalid spa options: {}", error);
  CheckSignals(y, u, Ts);
  const Eigen::Index n = y.size();
  const int M =
      o.lag_window > 0
          ? o.lag_window
          : static_cast<int>(std::max<Eigen::Index>(1, std::min<Eigen::Index>(30, n / 10)));
  PNEUMID_CHECK(M < n, "lag window M = {} must be below N = {}", M, n);
  const Eigen::VectorXd uc = u.array() - u.mean();
  const Eigen::VectorXd yc = y.array() - y.mean();
  std::vector<double> w(M + 1), ruu(M + 1), ryy(M + 1), ryu_p(M + 1), ryu_n(M + 1);
  for (int tau = 0; tau <= M; ++tau) {
    w[tau] = 0.5 * (1 + std::cos(M_PI * tau / M));
    ruu[tau] = Cov(uc, uc, tau);
    ryy[tau] = Cov(yc, yc, tau);
    ryu_p[tau] = Cov(yc, uc, tau);  // R_yu(tau)
    ryu_n[tau] = Cov(uc, yc, tau);  // R_yu(-tau) = 1/N sum y(t - tau) u(t)
  }
  FrequencyResponseEstimate r;
  r.Ts = Ts;
  const int K = o.num_frequencies;
  r.omega.resize(K);
  r.response.resize(K);
  r.noise_spectrum.resize(K);
  r.magnitude_std.resize(K);
  for (int k = 0; k < K; ++k) {
    const double wk = (k + 1) * M_PI / (K * Ts);
    r.omega[k] = wk;
    double pu = w[0] * ruu[0], py = w[0] * ryy[0];
    std::complex<double> pyu = w[0] * ryu_p[0];
    for (int tau = 1; tau <= M; ++tau) {
      const double c = std::cos(wk * tau * Ts), s = std::sin(wk * tau * Ts);
      pu += 2 * w[tau] * ruu[tau] * c;
      py += 2 * w[tau] * ryy[tau] * c;
      // sum over +tau and -tau of R_yu e^{-i w tau}
      pyu += w[tau] *
             (ryu_p[tau] * std::complex<double>(c, -s) + ryu_n[tau] * std::complex<double>(c, s));
    }
    r.response[k] = pu > 0 ? pyu / pu : std::complex<double>(NAN, NAN);
    r.noise_spectrum[k] = std::max(0.0, py - std::norm(pyu) / pu);
    r.magnitude_std[k] = std::sqrt(0.75 * M / static_cast<double>(n) * r.noise_spectrum[k] / pu);
  }
  Finish(&r);
  return r;
}

FrequencyResponseEstimate Etfe(const Eigen::VectorXd& y, const Eigen::VectorXd& u, double Ts,
                               const EtfeOptions& o) {
  std::string error;
  PNEUMID_CHECK(o.IsValid(&error), "invalid etfe options: {}", error);
  CheckSignals(y, u, Ts);
  const Eigen::Index n = y.size();
  Eigen::FFT<double> fft;
  std::vector<double> ys(y.data(), y.data() + n), us(u.data(), u.data() + n);
  const double ym = y.mean(), um = u.mean();
  for (auto& v : ys) v -= ym;
  for (auto& v : us) v -= um;
  std::vector<std::complex<double>> Y, U;
  fft.fwd(Y, ys);
  fft.fwd(U, us);
  const Eigen::Index half = n / 2;
  FrequencyResponseEstimate r;
  r.Ts = Ts;
  std::vector<double> om;
  std::vector<std::complex<double>> g;
  if (o.num_frequencies == 0) {
    for (Eigen::Index k = 1; k <= half; ++k) {
      if (std::norm(U[k]) == 0.0) continue;
      om.push_back(2 * M_PI * k / (n * Ts));
      g.push_back(Y[k] / U[k]);
    }
  } else {
    const int bands = static_cast<int>(std::min<Eigen::Index>(o.num_frequencies, half));
    for (int b = 0; b < bands; ++b) {
      const Eigen::Index k0 = 1 + b * half / bands, k1 = 1 + (b + 1) * half / bands;
      std::complex<double> num = 0;
      double den = 0, wsum = 0;
      for (Eigen::Index k = k0; k < k1; ++k) {
        num += Y[k] * std::conj(U[k]);
        den += std::norm(U[k]);
        wsum += std::norm(U[k]) * 2 * M_PI * k / (n * Ts);
      }
      if (den == 0.0) continue;
      om.push_back(wsum / den);
      g.push_back(num / den);
    }
  }
  r.omega = Eigen::Map<Eigen::VectorXd>(om.data(), static_cast<Eigen::Index>(om.size()));
  r.response = Eigen::Map<Eigen::VectorXcd>(g.data(), static_cast<Eigen::Index>(g.size()));
  Finish(&r);
  return r;
}

namespace {
void CheckDataColumns(const Dataset& data, int input, int output) {
  data.RequireUniform();
  PNEUMID_CHECK(input >= 0 && input < data.num_inputs(), "input column {} out of range [0, {})",
                input, data.num_inputs());
  PNEUMID_CHECK(output >= 0 && output < data.num_outputs(), "output column {} out of range [0, {})",
                output, data.num_outputs());
}
}  // namespace

FrequencyResponseEstimate Spa(const Dataset& data, const SpaOptions& options, int input,
                              int output) {
  CheckDataColumns(data, input, output);
  return Spa(data.y(output), data.u(input), data.SampleTime(), options);
}

FrequencyResponseEstimate Etfe(const Dataset& data, const EtfeOptions& options, int input,
                               int output) {
  CheckDataColumns(data, input, output);
  return Etfe(data.y(output), data.u(input), data.SampleTime(), options);
}

nlohmann::json FrequencyResponseEstimate::ToJson() const {
  auto vec = [](const Eigen::VectorXd& v) {
    return std::vector<double>(v.data(), v.data() + v.size());
  };
  nlohmann::json j = {{"omega", vec(omega)},
                      {"magnitude", vec(magnitude)},
                      {"phase_deg", vec(phase_deg)},
                      {"Ts", Ts}};
  if (noise_spectrum.size() > 0) j["noise_spectrum"] = vec(noise_spectrum);
  if (magnitude_std.size() > 0) j["magnitude_std"] = vec(magnitude_std);
  return j;
}

}  // namespace pneumid
