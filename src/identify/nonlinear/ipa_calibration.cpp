// Grey-box calibration of the IPA simulator (see include/pneumid/identify/nonlinear/ipa_calibration.hpp).
#include "pneumid/identify/nonlinear/ipa_calibration.hpp"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <thread>

#include <ceres/ceres.h>
#include <fmt/format.h>
#include <Eigen/SVD>

#include "../ceres_logging.hpp"
#include "pneumid/common/check.hpp"
#include "pneumid/common/enum_names.hpp"
#include "pneumid/identify/evaluation/fit_metrics.hpp"

namespace pneumid {

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

constexpr EnumName<CalibrationInitialState> kInitialStateNames[] = {
    {CalibrationInitialState::kMeasured, "measured"},
    {CalibrationInitialState::kSteady, "steady"},
};

}  // namespace

std::string ToString(CalibrationInitialState s) {
  return std::string(EnumToString(kInitialStateNames, s));
}

CalibrationInitialState CalibrationInitialStateFromString(const std::string& name) {
  return EnumFromString(kInitialStateNames, name, "initial state");
}

bool IpaCalibrationOptions::IsValid(std::string* error) const {
  auto fail = [&](const std::string& m) {
    if (error) *error = m;
    return false;
  };
  std::string e;
  if (!start.IsValid(&e)) return fail("start parameters: " + e);
  if (!(std::isfinite(warmup) && warmup >= 0.0 && warmup <= 1e4))
    return fail(fmt::format("warmup must be in 0..1e4 s, got {}", warmup));
  if (!(integration_tolerance >= 1e-14 && integration_tolerance <= 1e-3))
    return fail(
        fmt::format("integration_tolerance must be in 1e-14..1e-3, got {}", integration_tolerance));
  if (!(relative_step > 0.0 && relative_step <= 0.1))
    return fail(fmt::format("relative_step must be in (0, 0.1], got {}", relative_step));
  if (max_iterations < 0 || max_iterations > 100000)
    return fail(fmt::format("max_iterations must be in 0..100000, got {}", max_iterations));
  if (!(function_tolerance >= 0.0) || !(parameter_tolerance >= 0.0))
    return fail("function_tolerance and parameter_tolerance must be >= 0");
  if (num_threads < 1 || num_threads > 256)
    return fail(fmt::format("num_threads must be in 1..256, got {}", num_threads));
  if (!(correlation_threshold > 0.0 && correlation_threshold <= 1.0))
    return fail(
        fmt::format("correlation_threshold must be in (0, 1], got {}", correlation_threshold));
  if (!(fit_warning_percent <= 100.0))
    return fail(
        fmt::format("fit_warning_percent must be at most 100, got {}", fit_warning_percent));
  return true;
}

std::vector<std::string> DefaultCalibrationParameters(IpaMode mode) {
  std::vector<std::string> names = {"valves.inlet_conductance",
                                    "valves.exhaust_conductance",
                                    "valves.inlet_critical_ratio",
                                    "valves.exhaust_critical_ratio",
                                    "cylinder.bore",
                                    "valves.open_delay"};
  if (mode == IpaMode::kPosition) {
    names.push_back("mechanics.mass");
    names.push_back("mechanics.viscous_friction");
    names.push_back("mechanics.coulomb_friction");
  }
  return names;
}

std::vector<std::string> DefaultCalibrationParameters(const IpaParameters& start) {
  std::vector<std::string> names = DefaultCalibrationParameters(start.mode);
  if (start.mode == IpaMode::kForce && start.pressure_filter_time_constant > 0.0)
    names.push_back("sensors.pressure_filter_time_constant");
  return names;
}

namespace {

/// The simulator parameters of the calibration's model: noise-free, no ADC
/// quantization, tighter integration tolerances.
IpaParameters ModelParameters(IpaParameters p, double tolerance) {
  p.pressure_noise = 0.0;
  p.position_noise = 0.0;
  p.adc_bits = 0;
  p.relative_tolerance = tolerance;
  p.absolute_tolerance = tolerance;
  return p;
}

/// The output level the record starts from: the mean of the leading outputs
/// (at most 5) recorded with the first input, stopping at the first one that
/// has moved by more than 1 % of the record's range from y(0) (a record that
/// starts in a transient keeps y(0)).
double LeadingOutput(const Eigen::VectorXd& u, const Eigen::VectorXd& y) {
  const double band = 0.01 * (y.maxCoeff() - y.minCoeff());
  double sum = 0.0;
  int n = 0;
  for (Eigen::Index k = 0; k < y.size() && k < 5 && u[k] == u[0]; ++k, ++n) {
    if (std::abs(y[k] - y[0]) > band) break;
    sum += y[k];
  }
  return n > 0 ? sum / n : y[0];
}

Eigen::VectorXd Simulate(const IpaParameters& model, const Eigen::VectorXd& u,
                         const Eigen::VectorXd& y, double Ts, CalibrationInitialState initial,
                         double warmup) {
  IpaSimulator sim(model, Ts);
  const Eigen::Index n = u.size();
  if (initial == CalibrationInitialState::kSteady) {
    const auto steps = static_cast<long long>(std::ceil(warmup / Ts));
    for (long long k = 0; k < steps; ++k) sim.Advance(u[0]);
  } else {
    const double y0 = LeadingOutput(u, y);
    const double patm = model.atmospheric_pressure;
    if (model.mode == IpaMode::kForce) {
      const double pa = (y0 - model.force_offset) / model.AreaA() + patm;
      sim.SetState(std::max(pa, 0.01 * patm), sim.pressure_b(), sim.position());
    } else {
      sim.SetState(sim.pressure_a(), sim.pressure_b(), std::clamp(y0, 0.0, model.stroke));
    }
  }
  Eigen::VectorXd out(n);
  for (Eigen::Index k = 0; k < n; ++k) {
    out[k] = sim.Measure();
    if (k + 1 < n) sim.Advance(u[k]);
  }
  return out;
}

struct PreparedExperiment {
  std::string name;
  Eigen::VectorXd u, y;
  double Ts = 0.0;
  double norm = 1.0;  // ||y - mean(y)|| / sqrt(weight)
  double weight = 1.0;
};

/// Output error of every experiment for given scaled variables, and its
/// finite-difference Jacobian, the simulations spread over worker threads.
class Problem {
 public:
  Problem(const std::vector<PreparedExperiment>& experiments, const IpaCalibrationOptions& options,
          std::vector<std::string> keys, Eigen::VectorXd scale, Eigen::VectorXd lower,
          Eigen::VectorXd upper)
      : experiments_(experiments),
        options_(options),
        keys_(std::move(keys)),
        scale_(std::move(scale)),
        lower_(std::move(lower)),
        upper_(std::move(upper)),
        base_(ModelParameters(options.start, options.integration_tolerance)) {
    for (const auto& e : experiments_) total_ += e.y.size();
  }

  Eigen::Index num_residuals() const { return total_; }
  int num_parameters() const { return static_cast<int>(keys_.size()); }
  long long simulations() const { return simulations_.load(); }

  IpaParameters Parameters(const double* z) const {
    IpaParameters p = base_;
    for (int i = 0; i < num_parameters(); ++i) SetIpaParameter(p, keys_[i], z[i] * scale_[i]);
    return p;
  }

  /// Weighted residuals of all experiments into r; false when the parameters
  /// are invalid or the simulation fails.
  bool Residuals(const double* z, double* r) const {
    const IpaParameters p = Parameters(z);
    if (!p.IsValid(nullptr)) return false;
    Eigen::Index offset = 0;
    for (const auto& e : experiments_) {
      Eigen::VectorXd ys;
      try {
        ys = Simulate(p, e.u, e.y, e.Ts, options_.initial_state, options_.warmup);
      } catch (const std::exception&) {
        return false;
      }
      ++simulations_;
      for (Eigen::Index k = 0; k < e.y.size(); ++k) {
        const double v = (ys[k] - e.y[k]) / e.norm;
        if (!std::isfinite(v)) return false;
        r[offset + k] = v;
      }
      offset += e.y.size();
    }
    return true;
  }

  /// Column-major N x p Jacobian by central differences (one-sided at a bound).
  bool Jacobian(const double* z, const double* r0, double* J) const {
    const int np = num_parameters();
    const Eigen::Index N = total_;
    std::atomic<bool> ok{true};
    std::atomic<int> next{0};
    auto work = [&]() {
      std::vector<double> zz(z, z + np);
      Eigen::VectorXd rp(N), rm(N);
      for (int i = next++; i < np && ok; i = next++) {
        const double h = options_.relative_step * std::max(1.0, std::abs(z[i]));
        const double up = std::min(z[i] + h, upper_[i]);
        const double dn = std::max(z[i] - h, lower_[i]);
        bool good = true;
        zz[i] = up;
        const bool have_up = up > z[i] && Residuals(zz.data(), rp.data());
        zz[i] = dn;
        const bool have_dn = dn < z[i] && Residuals(zz.data(), rm.data());
        zz[i] = z[i];
        Eigen::Map<Eigen::VectorXd> col(J + static_cast<Eigen::Index>(i) * N, N);
        Eigen::Map<const Eigen::VectorXd> base(r0, N);
        if (have_up && have_dn)
          col = (rp - rm) / (up - dn);
        else if (have_up)
          col = (rp - base) / (up - z[i]);
        else if (have_dn)
          col = (base - rm) / (z[i] - dn);
        else
          good = false;
        if (!good) ok = false;
      }
    };
    const int threads = std::min(options_.num_threads, np);
    std::vector<std::thread> pool;
    for (int t = 1; t < threads; ++t) pool.emplace_back(work);
    work();
    for (auto& t : pool) t.join();
    return ok;
  }

 private:
  const std::vector<PreparedExperiment>& experiments_;
  const IpaCalibrationOptions& options_;
  std::vector<std::string> keys_;
  Eigen::VectorXd scale_, lower_, upper_;
  IpaParameters base_;
  Eigen::Index total_ = 0;
  mutable std::atomic<long long> simulations_{0};
};

class OutputErrorCost : public ceres::CostFunction {
 public:
  explicit OutputErrorCost(const Problem* problem) : problem_(problem) {
    set_num_residuals(static_cast<int>(problem->num_residuals()));
    mutable_parameter_block_sizes()->push_back(problem->num_parameters());
  }
  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override {
    if (!problem_->Residuals(parameters[0], residuals)) return false;
    if (!jacobians || !jacobians[0]) return true;
    // Ceres wants the block row-major (residual i, parameter j at i * p + j).
    const Eigen::Index N = problem_->num_residuals();
    const int np = problem_->num_parameters();
    Eigen::MatrixXd J(N, np);
    if (!problem_->Jacobian(parameters[0], residuals, J.data())) return false;
    Eigen::Map<Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>>(jacobians[0],
                                                                                       N, np) = J;
    return true;
  }

 private:
  const Problem* problem_;
};

class ProgressCallback : public ceres::IterationCallback {
 public:
  explicit ProgressCallback(const std::function<void(int, double)>& f) : f_(f) {}
  ceres::CallbackReturnType operator()(const ceres::IterationSummary& s) override {
    if (f_) f_(s.iteration, s.cost);
    return ceres::SOLVER_CONTINUE;
  }

 private:
  const std::function<void(int, double)>& f_;
};

double FitOf(const Eigen::VectorXd& r_weighted) {
  // The residuals are weighted by 1 / ||y - mean(y)||: fit = 100 (1 - ||r||).
  return 100.0 * (1.0 - r_weighted.norm());
}

}  // namespace

Eigen::VectorXd SimulateIpaOnData(const IpaParameters& parameters, const Dataset& data,
                                  CalibrationInitialState initial_state, double warmup,
                                  double integration_tolerance) {
  std::string error;
  PNEUMID_CHECK(parameters.IsValid(&error), "invalid IPA parameters: {}", error);
  PNEUMID_CHECK(data.num_inputs() >= 1 && data.num_outputs() >= 1 && data.size() >= 2,
                "{}: the IPA model needs an input, an output and at least 2 samples",
                data.source());
  data.RequireUniform();
  return Simulate(ModelParameters(parameters, integration_tolerance), data.u(0), data.y(0),
                  data.SampleTime(), initial_state, warmup);
}

std::string IpaCalibrationSummary::BriefReport() const {
  std::string s = fmt::format(
      "IPA calibration: {}, {} iterations, cost {:.4g} -> {:.4g}, {} "
      "simulations, {:.2f} s",
      ToString(termination), iterations, initial_cost, final_cost, simulations, seconds);
  for (const auto& e : experiments) s += fmt::format("; {} fit {:.2f} %", e.name, e.fit_percent);
  return s;
}

IpaCalibrationSummary CalibrateIpa(const std::vector<CalibrationExperiment>& experiments,
                                   const IpaCalibrationOptions& options) {
  std::string error;
  PNEUMID_CHECK(options.IsValid(&error), "invalid calibration options: {}", error);
  PNEUMID_CHECK(!experiments.empty(), "calibration needs at least one experiment");

  // Free parameters, their ranges and scales.
  std::vector<std::string> keys;
  for (const auto& name :
       options.free.empty() ? DefaultCalibrationParameters(options.start) : options.free) {
    const IpaParameterInfo& info = FindIpaParameter(name);
    PNEUMID_CHECK(info.calibratable,
                  "'{}' is a numerical or sensor-scaling setting, not a physical parameter a "
                  "calibration can estimate",
                  info.key);
    PNEUMID_CHECK(std::find(keys.begin(), keys.end(), info.key) == keys.end(),
                  "parameter '{}' is named twice", info.key);
    keys.push_back(info.key);
  }
  for (const auto& [name, range] : options.bounds) {
    const std::string key = FindIpaParameter(name).key;
    PNEUMID_CHECK(std::find(keys.begin(), keys.end(), key) != keys.end(),
                  "bounds given for '{}', which is not a free parameter", key);
  }
  const int np = static_cast<int>(keys.size());
  Eigen::VectorXd scale(np), lower(np), upper(np), z(np), start(np);
  std::vector<std::string> units(np);
  for (int i = 0; i < np; ++i) {
    const IpaParameterInfo& info = FindIpaParameter(keys[i]);
    double lo = info.lower, hi = info.upper;
    for (const auto& [name, range] : options.bounds)
      if (FindIpaParameter(name).key == keys[i]) std::tie(lo, hi) = range;
    const double v = GetIpaParameter(options.start, keys[i]);
    PNEUMID_CHECK(std::isfinite(lo) && std::isfinite(hi) && lo < hi,
                  "bounds of '{}' must be finite with lower < upper, got {} .. {}", keys[i], lo,
                  hi);
    PNEUMID_CHECK(v >= lo && v <= hi,
                  "the start value of '{}', {} {}, is outside its bounds {} .. {}", keys[i], v,
                  info.unit, lo, hi);
    scale[i] = v != 0.0 ? std::abs(v) : (hi - lo);
    lower[i] = lo / scale[i];
    upper[i] = hi / scale[i];
    z[i] = v / scale[i];
    start[i] = v;
    units[i] = info.unit;
  }

  // The experiments.
  std::vector<PreparedExperiment> prepared;
  Eigen::Index total = 0;
  for (std::size_t e = 0; e < experiments.size(); ++e) {
    const Dataset& d = experiments[e].data;
    const std::string name = !experiments[e].name.empty() ? experiments[e].name
                             : !d.source().empty()        ? d.source()
                                                          : fmt::format("experiment {}", e + 1);
    PNEUMID_CHECK(d.num_inputs() >= 1 && d.num_outputs() >= 1,
                  "{}: needs an input (PWM duty, %) and an output column", name);
    PNEUMID_CHECK(d.size() >= 3, "{}: needs at least 3 samples, has {}", name, d.size());
    d.RequireUniform();
    PreparedExperiment p;
    p.name = name;
    p.u = d.u(0);
    p.y = d.y(0);
    p.Ts = d.SampleTime();
    PNEUMID_CHECK(p.u.maxCoeff() > p.u.minCoeff(),
                  "{}: no excitation: the input is constant ({} %) over all {} samples, so "
                  "the data say nothing about the dynamics; use a step, staircase or PRBS",
                  name, p.u[0], d.size());
    const double w = experiments[e].weight;
    PNEUMID_CHECK(std::isfinite(w) && w > 0.0, "{}: the weight must be positive, got {}", name, w);
    p.norm = (p.y.array() - p.y.mean()).matrix().norm();
    PNEUMID_CHECK(p.norm > 0.0, "{}: the output is constant ({}), nothing to fit", name, p.y[0]);
    p.norm /= std::sqrt(w);
    p.weight = w;
    total += d.size();
    prepared.push_back(std::move(p));
  }
  PNEUMID_CHECK(total > np, "{} samples in all cannot determine {} free parameters", total, np);

  const auto t_begin = std::chrono::steady_clock::now();
  IpaCalibrationSummary out;
  out.parameters = options.start;
  Problem problem(prepared, options, keys, scale, lower, upper);
  Eigen::VectorXd r0(total);
  const bool start_ok = problem.Residuals(z.data(), r0.data());
  // Initial fits.
  auto fits = [&](const Eigen::VectorXd& r, bool initial) {
    Eigen::Index offset = 0;
    for (std::size_t e = 0; e < prepared.size(); ++e) {
      const Eigen::Index n = prepared[e].y.size();
      const double f = FitOf(r.segment(offset, n) / std::sqrt(prepared[e].weight));
      if (initial) {
        CalibrationExperimentFit fit;
        fit.name = prepared[e].name;
        fit.samples = n;
        fit.initial_fit_percent = f;
        out.experiments.push_back(fit);
      } else {
        out.experiments[e].fit_percent = f;
        out.experiments[e].simulated = prepared[e].y + r.segment(offset, n) * prepared[e].norm;
      }
      offset += n;
    }
  };
  if (!start_ok) {
    std::string why;
    try {
      for (const auto& e : prepared)
        Simulate(ModelParameters(options.start, options.integration_tolerance), e.u, e.y, e.Ts,
                 options.initial_state, options.warmup);
      why = "the simulated output is not finite";
    } catch (const std::exception& ex) {
      why = ex.what();
    }
    out.termination = Termination::kFailure;
    out.message = "the simulation with the start parameters fails: " + why;
    return out;
  }
  fits(r0, true);

  ceres::Problem::Options problem_options;
  problem_options.cost_function_ownership = ceres::TAKE_OWNERSHIP;
  ceres::Problem ceres_problem(problem_options);
  ceres_problem.AddResidualBlock(new OutputErrorCost(&problem), nullptr, z.data());
  for (int i = 0; i < np; ++i) {
    ceres_problem.SetParameterLowerBound(z.data(), i, lower[i]);
    ceres_problem.SetParameterUpperBound(z.data(), i, upper[i]);
  }
  ceres::Solver::Options solver_options;
  solver_options.linear_solver_type = ceres::DENSE_QR;
  solver_options.max_num_iterations = options.max_iterations;
  solver_options.function_tolerance = options.function_tolerance;
  solver_options.parameter_tolerance = options.parameter_tolerance;
  solver_options.gradient_tolerance = 1e-12;
  solver_options.max_num_line_search_step_size_iterations = 0;
  solver_options.logging_type = ceres::SILENT;
  ProgressCallback callback(options.progress);
  if (options.progress) solver_options.callbacks.push_back(&callback);
  ceres::Solver::Summary summary;
  internal::SilenceCeresLogging();
  ceres::Solve(solver_options, &ceres_problem, &summary);

  out.iterations = static_cast<int>(summary.iterations.size()) - 1;
  out.initial_cost = summary.initial_cost;
  out.final_cost = summary.final_cost;
  out.termination = summary.termination_type == ceres::CONVERGENCE ? Termination::kConvergence
                    : summary.termination_type == ceres::NO_CONVERGENCE
                        ? Termination::kNoConvergence
                        : Termination::kFailure;
  out.message = summary.message;
  out.parameters = options.start;
  for (int i = 0; i < np; ++i) SetIpaParameter(out.parameters, keys[i], z[i] * scale[i]);

  Eigen::VectorXd r(total);
  Eigen::MatrixXd J(total, np);
  const bool have_r = problem.Residuals(z.data(), r.data());
  if (!have_r) {
    out.termination = Termination::kFailure;
    out.message = "the simulation with the calibrated parameters fails";
    out.parameters = options.start;
    return out;
  }
  fits(r, false);
  for (const auto& e : out.experiments)
    if (e.fit_percent < options.fit_warning_percent)
      out.warnings.push_back(fmt::format(
          "{}: the calibrated twin fits it by only {:.2f} % (start {:.2f} %): it does not "
          "reproduce these data; check their units (u: PWM duty in %, y: force in N or "
          "position in m), the initial state and the free parameters",
          e.name, e.fit_percent, e.initial_fit_percent));
  const bool have_j = problem.Jacobian(z.data(), r.data(), J.data());
  // Ceres stops with "convergence" on a zero gradient, which a flat region
  // also gives: a step that makes the twin stop responding to every free
  // parameter (e.g. a valve delay longer than the PWM pulses: no valve opens,
  // the force is constant). Such an end point is not a minimum.
  if (have_j && out.termination == Termination::kConvergence && J.allFinite()) {
    const double flat = 1e-9 * std::max(r.norm(), 1e-300);
    std::vector<std::string> responding;
    for (int i = 0; i < np; ++i)
      if (J.col(i).norm() > flat) responding.push_back(keys[i]);
    if (responding.empty()) {
      out.termination = Termination::kFailure;
      out.message = fmt::format(
          "the calibration stopped where the simulated output no longer responds to any free "
          "parameter ({}): a flat region, not a minimum (Ceres: {}); free fewer parameters or "
          "start closer to the actuator",
          fmt::join(keys, ", "), summary.message);
    }
  }

  // Uncertainty and identifiability (header comment).
  Eigen::VectorXd sd = Eigen::VectorXd::Constant(np, kNaN);
  std::vector<bool> determined(np, true);
  if (have_j && J.allFinite()) {
    Eigen::JacobiSVD<Eigen::MatrixXd> svd(J, Eigen::ComputeThinV);
    const Eigen::VectorXd s = svd.singularValues();
    const Eigen::MatrixXd& V = svd.matrixV();
    const double smax = s.size() > 0 ? s[0] : 0.0;
    Eigen::VectorXd inv2 = Eigen::VectorXd::Zero(np);
    for (int j = 0; j < np; ++j) {
      if (smax > 0.0 && s[j] > 1e-10 * smax) inv2[j] = 1.0 / (s[j] * s[j]);
      if (!(smax > 0.0) || s[j] < 1e-4 * smax)
        for (int i = 0; i < np; ++i)
          if (std::abs(V(i, j)) > 0.3) determined[i] = false;
    }
    const double dof = static_cast<double>(std::max<Eigen::Index>(total - np, 1));
    const double s2 = r.squaredNorm() / dof;
    const Eigen::MatrixXd C = V * inv2.asDiagonal() * V.transpose() * s2;  // scaled units
    for (int i = 0; i < np; ++i) sd[i] = std::sqrt(std::max(C(i, i), 0.0)) * scale[i];
    for (int i = 0; i < np; ++i)
      for (int j = i + 1; j < np; ++j) {
        const double d = std::sqrt(C(i, i) * C(j, j));
        if (!(d > 0.0)) continue;
        const double rho = C(i, j) / d;
        if (std::abs(rho) >= options.correlation_threshold)
          out.correlations.push_back({keys[i], keys[j], rho});
      }
  } else {
    out.warnings.push_back(
        "the Jacobian at the solution could not be formed: no standard "
        "deviations");
  }
  std::vector<std::string> undetermined;
  for (int i = 0; i < np; ++i) {
    CalibratedParameter c;
    c.name = keys[i];
    c.unit = units[i];
    c.value = z[i] * scale[i];
    c.start = start[i];
    c.lower = lower[i] * scale[i];
    c.upper = upper[i] * scale[i];
    c.std = sd[i];
    const double width = c.upper - c.lower;
    c.at_bound = c.value - c.lower <= 1e-6 * width || c.upper - c.value <= 1e-6 * width;
    const bool vague = std::isfinite(c.std) && c.value != 0.0 && c.std > 0.1 * std::abs(c.value);
    c.determined = determined[i] && !vague && std::isfinite(c.std);
    if (!determined[i])
      undetermined.push_back(c.name);
    else if (vague)
      out.warnings.push_back(
          fmt::format("{} is poorly determined by the data: {:.4g} +- {:.2g} {} ({:.0f} %)", c.name,
                      c.value, c.std, c.unit, 100.0 * c.std / std::abs(c.value)));
    if (c.at_bound)
      out.warnings.push_back(
          fmt::format("{} ended at its bound ({:.4g} {}, range {:.4g} .. {:.4g})", c.name, c.value,
                      c.unit, c.lower, c.upper));
    out.estimates.push_back(c);
  }
  if (!undetermined.empty()) {
    std::string list;
    for (const auto& n : undetermined) list += (list.empty() ? "" : ", ") + n;
    out.warnings.push_back(
        undetermined.size() == 1
            ? fmt::format("the data do not determine {}: its effect on the output is too small "
                          "or is taken up by the other free parameters; fix it (leave it out of "
                          "the free parameters) or add an experiment that excites it",
                          list)
            : fmt::format("the data do not determine {} separately (only a combination of "
                          "them): fix one of them (leave it out of the free parameters) or add "
                          "an experiment that separates them",
                          list));
  }
  out.simulations = problem.simulations();
  out.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t_begin).count();
  return out;
}

}  // namespace pneumid
