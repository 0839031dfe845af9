#include "pneumid/identify/nonlinear/narx_simulation_fit.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include <ceres/ceres.h>
#include <fmt/format.h>

#include "../ceres_logging.hpp"
#include "pneumid/common/check.hpp"

namespace pneumid {

namespace {

// The free run of a NARX model in normalised signals, optionally clipped to
// [lo, hi], with its sensitivities ds(t)/dtheta (row t of *sens, rows-major
// N x K) when sens is not null.
class NarxRun {
 public:
  NarxRun(const NarxModel& m, const Eigen::VectorXd& u, const Eigen::VectorXd& y)
      : m_(m), un_((u.array() - m.u_offset) / m.u_scale), yn_(y / m.y_scale) {}

  // Returns the run s (length N); samples outside [lo, hi] are clipped and
  // counted in *clipped (when not null).
  Eigen::VectorXd Run(const double* theta, double lo, double hi, Eigen::MatrixXd* sens,
                      Eigen::Index* clipped) const {
    const Eigen::Index N = yn_.size(), n0 = m_.FirstSample();
    const auto K = static_cast<Eigen::Index>(m_.terms.size());
    const int ny = m_.ny, nr = m_.ny + m_.nu;
    Eigen::VectorXd s = yn_;
    if (sens) sens->setZero(N, K);
    if (clipped) *clipped = 0;
    std::vector<double> reg(static_cast<std::size_t>(nr)), g(static_cast<std::size_t>(ny));
    Eigen::VectorXd p(K);
    for (Eigen::Index t = n0; t < N; ++t) {
      for (int r = 0; r < ny; ++r) reg[static_cast<std::size_t>(r)] = s[t - 1 - r];
      for (int r = ny; r < nr; ++r) reg[static_cast<std::size_t>(r)] = un_[t - m_.nk - (r - ny)];
      std::fill(g.begin(), g.end(), 0.0);
      double v = 0.0;
      for (Eigen::Index i = 0; i < K; ++i) {
        const NarxTerm& term = m_.terms[static_cast<std::size_t>(i)];
        double prod = 1.0;
        for (int r : term) prod *= reg[static_cast<std::size_t>(r)];
        p[i] = prod;
        v += theta[i] * prod;
        if (!sens) continue;
        // d p_i / d reg_r for the output regressors: the product of the other factors.
        for (std::size_t k = 0; k < term.size(); ++k) {
          if (term[k] >= ny) continue;
          double other = theta[i];
          for (std::size_t l = 0; l < term.size(); ++l)
            if (l != k) other *= reg[static_cast<std::size_t>(term[l])];
          g[static_cast<std::size_t>(term[k])] += other;
        }
      }
      const bool out = !(v >= lo && v <= hi);  // NaN counts as outside
      if (out) {
        v = std::isnan(v) ? hi : std::clamp(v, lo, hi);
        if (clipped) ++*clipped;
      }
      s[t] = v;
      if (!sens || out) continue;  // a clipped sample does not depend on theta
      auto row = sens->row(t);
      row = p.transpose();
      for (int r = 0; r < ny; ++r)
        if (t - 1 - r >= n0) row += g[static_cast<std::size_t>(r)] * sens->row(t - 1 - r);
    }
    return s;
  }

  const Eigen::VectorXd& target() const { return yn_; }

 private:
  const NarxModel& m_;
  Eigen::VectorXd un_, yn_;
};

class SimulationCost : public ceres::CostFunction {
 public:
  SimulationCost(const NarxRun& run, Eigen::Index n0, Eigen::Index N, int K, double lo, double hi)
      : run_(run), n0_(n0), N_(N), K_(K), lo_(lo), hi_(hi) {
    set_num_residuals(static_cast<int>(N - n0));
    mutable_parameter_block_sizes()->push_back(K);
  }

  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override {
    const bool jac = jacobians != nullptr && jacobians[0] != nullptr;
    Eigen::MatrixXd sens;
    const Eigen::VectorXd s = run_.Run(parameters[0], lo_, hi_, jac ? &sens : nullptr, nullptr);
    for (Eigen::Index t = n0_; t < N_; ++t) residuals[t - n0_] = s[t] - run_.target()[t];
    if (jac)
      for (Eigen::Index t = n0_; t < N_; ++t)
        for (int j = 0; j < K_; ++j) jacobians[0][(t - n0_) * K_ + j] = sens(t, j);
    return true;
  }

 private:
  const NarxRun& run_;
  Eigen::Index n0_, N_;
  int K_;
  double lo_, hi_;
};

}  // namespace

bool NarxSimulationFitOptions::IsValid(std::string* error) const {
  if (max_iterations < 1 || !(band > 0.0 && std::isfinite(band))) {
    if (error)
      *error = fmt::format(
          "NarxSimulationFitOptions: max_iterations must be >= 1 and band > 0, got {} and {}",
          max_iterations, band);
    return false;
  }
  return true;
}

std::pair<double, double> NarxDataBand(const Eigen::VectorXd& y, double band) {
  const double ymin = y.minCoeff(), ymax = y.maxCoeff();
  const double range = std::max(ymax - ymin, 1e-12 * std::max(1.0, std::abs(ymax)));
  return {ymin - band * range, ymax + band * range};
}

NarxSimulationFitResult FitNarxSimulation(NarxModel* m, const Eigen::VectorXd& u,
                                          const Eigen::VectorXd& y,
                                          const NarxSimulationFitOptions& o) {
  std::string why;
  PNEUMID_CHECK(o.IsValid(&why), "{}", why);
  PNEUMID_CHECK(m != nullptr && !m->terms.empty() && m->terms.size() == m->theta.size(),
                "NARX simulation fit: the model needs terms, one theta each");
  PNEUMID_CHECK(u.size() == y.size(),
                "NARX simulation fit: the input has {} samples, the output {}", u.size(), y.size());
  PNEUMID_CHECK(u.allFinite() && y.allFinite(),
                "NARX simulation fit: the data hold non-finite values");
  const Eigen::Index N = y.size(), n0 = m->FirstSample();
  PNEUMID_CHECK(N > n0, "NARX simulation fit: {} samples, the free run starts at sample {}", N, n0);
  const auto K = static_cast<int>(m->terms.size());
  const auto [band_lo, band_hi] = NarxDataBand(y, o.band);
  const double lo = band_lo / m->y_scale, hi = band_hi / m->y_scale;
  const double inf = std::numeric_limits<double>::infinity();
  const NarxRun run(*m, u, y);
  const double scale2 = m->y_scale * m->y_scale / static_cast<double>(N - n0);
  // Mean squared error of the run of theta (output units), clipped or not.
  auto mse = [&](const std::vector<double>& theta, bool clip, Eigen::Index* clipped) {
    const Eigen::VectorXd s =
        run.Run(theta.data(), clip ? lo : -inf, clip ? hi : inf, nullptr, clipped);
    const Eigen::VectorXd e = (s - run.target()).tail(N - n0);
    return e.allFinite() ? scale2 * e.squaredNorm() : inf;
  };
  NarxSimulationFitResult result;
  EstimationSummary& s = result.summary;
  s.num_rows = N - n0;
  s.num_parameters = K;
  const std::vector<double> start = m->theta;
  s.initial_loss = mse(start, true, nullptr);
  std::vector<double> theta = start;
  ceres::Problem problem;
  problem.AddResidualBlock(new SimulationCost(run, n0, N, K, lo, hi), nullptr, theta.data());
  ceres::Solver::Options so;
  so.linear_solver_type = ceres::DENSE_QR;
  so.max_num_iterations = o.max_iterations;
  so.num_threads = 1;
  so.logging_type = ceres::SILENT;
  ceres::Solver::Summary cs;
  internal::SilenceCeresLogging();
  ceres::Solve(so, &problem, &cs);
  s.iterations = std::max(0, static_cast<int>(cs.iterations.size()) - 1);
  s.termination = cs.termination_type == ceres::CONVERGENCE      ? Termination::kConvergence
                  : cs.termination_type == ceres::NO_CONVERGENCE ? Termination::kNoConvergence
                                                                 : Termination::kFailure;
  s.message = "simulation-error Levenberg-Marquardt (Ceres): " + cs.message;
  if (s.termination == Termination::kNoConvergence)
    s.warnings.push_back(
        fmt::format("simulation fit: not converged after {} iterations", o.max_iterations));
  // The unclipped runs of the result and of the start decide what is kept.
  if (!std::isfinite(mse(theta, false, nullptr)) && std::isfinite(mse(start, false, nullptr))) {
    theta = start;
    s.termination = Termination::kNoConvergence;
    s.warnings.push_back(
        "simulation fit: the refined model's free run diverges without the clip band; the "
        "least-squares start is kept");
  }
  m->theta = theta;
  const Eigen::VectorXd free_run = run.Run(theta.data(), -inf, inf, nullptr, nullptr).tail(N - n0);
  const Eigen::Index clipped = (free_run.array() < lo || free_run.array() > hi).count();
  result.clipped = clipped;
  const double final_free = mse(theta, false, nullptr);
  result.diverges = !std::isfinite(final_free);
  s.loss = result.diverges ? mse(theta, true, nullptr) : final_free;
  if (result.diverges) {
    s.termination = Termination::kFailure;
    s.warnings.push_back(fmt::format(
        "simulation fit: the free run diverges on the estimation data (finite only when clipped "
        "to [{:.4g}, {:.4g}])",
        lo * m->y_scale, hi * m->y_scale));
  } else if (clipped > 0) {
    s.warnings.push_back(fmt::format(
        "simulation fit: the free run leaves the band [{:.4g}, {:.4g}] around the data at {} "
        "of {} samples (clipped there during the fit)",
        lo * m->y_scale, hi * m->y_scale, clipped, N - n0));
  }
  return result;
}

}  // namespace pneumid
