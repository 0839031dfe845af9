// Grey-box calibration of the IPA simulator (see
// include/pneumid/identify/nonlinear/ipa_calibration.hpp).
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
                "{}: the IPA model needs an input, an output and at least 2 samples, got {} "
                "input(s), {} output(s), {} sample(s)",
                data.source().empty() ? std::string("the data") : data.source(),
                data.num_inputs(), data.num_outputs(), data.size());
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

namespace {

// The free parameters in their order: TOML keys and units, the scales that
// make them of order one, the search ranges and values in scaled units, and
// the physical start values.
struct FreeParameters {
  std::vector<std::string> keys, units;
  Eigen::VectorXd scale;         // physical value of one scaled unit
  Eigen::VectorXd lower, upper;  // search range, scaled
  Eigen::VectorXd values;        // scaled: the start, then the solution
  Eigen::VectorXd start;         // physical start values
  int size() const { return static_cast<int>(keys.size()); }
};

// Keys of the free parameters (the options' or the defaults), each a
// calibratable parameter named once; bounds may be given only for them.
std::vector<std::string> FreeParameterKeys(const IpaCalibrationOptions& options) {
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
  return keys;
}

// Free parameters, their ranges (physical or given bounds) and scales.
FreeParameters ScaleFreeParameters(const IpaCalibrationOptions& options) {
  FreeParameters free;
  free.keys = FreeParameterKeys(options);
  const int np = free.size();
  free.scale.resize(np);
  free.lower.resize(np);
  free.upper.resize(np);
  free.values.resize(np);
  free.start.resize(np);
  free.units.resize(np);
  for (int i = 0; i < np; ++i) {
    const std::string& key = free.keys[i];
    const IpaParameterInfo& info = FindIpaParameter(key);
    double lo = info.lower, hi = info.upper;
    for (const auto& [name, range] : options.bounds)
      if (FindIpaParameter(name).key == key) std::tie(lo, hi) = range;
    const double value = GetIpaParameter(options.start, key);
    PNEUMID_CHECK(std::isfinite(lo) && std::isfinite(hi) && lo < hi,
                  "bounds of '{}' must be finite with lower < upper, got {} .. {}", key, lo, hi);
    PNEUMID_CHECK(value >= lo && value <= hi,
                  "the start value of '{}', {} {}, is outside its bounds {} .. {}", key, value,
                  info.unit, lo, hi);
    free.scale[i] = value != 0.0 ? std::abs(value) : (hi - lo);
    free.lower[i] = lo / free.scale[i];
    free.upper[i] = hi / free.scale[i];
    free.values[i] = value / free.scale[i];
    free.start[i] = value;
    free.units[i] = info.unit;
  }
  return free;
}

// The experiments checked and prepared for the output-error cost.
std::vector<PreparedExperiment> PrepareExperiments(
    const std::vector<CalibrationExperiment>& experiments) {
  std::vector<PreparedExperiment> prepared;
  for (std::size_t e = 0; e < experiments.size(); ++e) {
    const Dataset& data = experiments[e].data;
    const std::string name = !experiments[e].name.empty() ? experiments[e].name
                             : !data.source().empty()     ? data.source()
                                                          : fmt::format("experiment {}", e + 1);
    PNEUMID_CHECK(data.num_inputs() >= 1 && data.num_outputs() >= 1,
                  "{}: needs an input (PWM duty, %) and an output column", name);
    PNEUMID_CHECK(data.size() >= 3, "{}: needs at least 3 samples, has {}", name, data.size());
    data.RequireUniform();
    PreparedExperiment experiment;
    experiment.name = name;
    experiment.u = data.u(0);
    experiment.y = data.y(0);
    experiment.Ts = data.SampleTime();
    PNEUMID_CHECK(experiment.u.maxCoeff() > experiment.u.minCoeff(),
                  "{}: no excitation: the input is constant ({} %) over all {} samples, so "
                  "the data say nothing about the dynamics; use a step, staircase or PRBS",
                  name, experiment.u[0], data.size());
    const double weight = experiments[e].weight;
    PNEUMID_CHECK(std::isfinite(weight) && weight > 0.0, "{}: the weight must be positive, got {}",
                  name, weight);
    experiment.norm = (experiment.y.array() - experiment.y.mean()).matrix().norm();
    PNEUMID_CHECK(experiment.norm > 0.0, "{}: the output is constant ({}), nothing to fit", name,
                  experiment.y[0]);
    experiment.norm /= std::sqrt(weight);
    experiment.weight = weight;
    prepared.push_back(std::move(experiment));
  }
  return prepared;
}

Eigen::Index TotalSamples(const std::vector<PreparedExperiment>& prepared) {
  Eigen::Index total = 0;
  for (const auto& e : prepared) total += e.y.size();
  return total;
}

// Why the simulation with the start parameters fails.
std::string StartFailureReason(const std::vector<PreparedExperiment>& prepared,
                               const IpaCalibrationOptions& options) {
  try {
    for (const auto& e : prepared)
      Simulate(ModelParameters(options.start, options.integration_tolerance), e.u, e.y, e.Ts,
               options.initial_state, options.warmup);
    return "the simulated output is not finite";
  } catch (const std::exception& ex) {
    return ex.what();
  }
}

// Fit of each experiment with the start parameters, from the weighted
// residuals of all experiments.
std::vector<CalibrationExperimentFit> InitialFits(const std::vector<PreparedExperiment>& prepared,
                                                  const Eigen::VectorXd& residuals) {
  std::vector<CalibrationExperimentFit> fits;
  Eigen::Index offset = 0;
  for (const auto& experiment : prepared) {
    const Eigen::Index n = experiment.y.size();
    CalibrationExperimentFit fit;
    fit.name = experiment.name;
    fit.samples = n;
    fit.initial_fit_percent = FitOf(residuals.segment(offset, n) / std::sqrt(experiment.weight));
    fits.push_back(fit);
    offset += n;
  }
  return fits;
}

// Fit and simulated output of each experiment with the calibrated parameters.
void StoreCalibratedFits(const std::vector<PreparedExperiment>& prepared,
                         const Eigen::VectorXd& residuals,
                         std::vector<CalibrationExperimentFit>* fits) {
  Eigen::Index offset = 0;
  for (std::size_t e = 0; e < prepared.size(); ++e) {
    const Eigen::Index n = prepared[e].y.size();
    (*fits)[e].fit_percent = FitOf(residuals.segment(offset, n) / std::sqrt(prepared[e].weight));
    (*fits)[e].simulated = prepared[e].y + residuals.segment(offset, n) * prepared[e].norm;
    offset += n;
  }
}

// Levenberg-Marquardt on the output error within the bounds; the solution
// replaces free->values.
ceres::Solver::Summary SolveCalibration(const Problem& problem,
                                        const IpaCalibrationOptions& options,
                                        FreeParameters* free) {
  double* values = free->values.data();
  ceres::Problem::Options problem_options;
  problem_options.cost_function_ownership = ceres::TAKE_OWNERSHIP;
  ceres::Problem ceres_problem(problem_options);
  ceres_problem.AddResidualBlock(new OutputErrorCost(&problem), nullptr, values);
  for (int i = 0; i < free->size(); ++i) {
    ceres_problem.SetParameterLowerBound(values, i, free->lower[i]);
    ceres_problem.SetParameterUpperBound(values, i, free->upper[i]);
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
  return summary;
}

void RecordSolverSummary(const ceres::Solver::Summary& summary, IpaCalibrationSummary* out) {
  out->iterations = static_cast<int>(summary.iterations.size()) - 1;
  out->initial_cost = summary.initial_cost;
  out->final_cost = summary.final_cost;
  out->termination = summary.termination_type == ceres::CONVERGENCE ? Termination::kConvergence
                     : summary.termination_type == ceres::NO_CONVERGENCE
                         ? Termination::kNoConvergence
                         : Termination::kFailure;
  out->message = summary.message;
}

void AddPoorFitWarnings(double fit_warning_percent, IpaCalibrationSummary* out) {
  for (const auto& e : out->experiments)
    if (e.fit_percent < fit_warning_percent)
      out->warnings.push_back(fmt::format(
          "{}: the calibrated twin fits it by only {:.2f} % (start {:.2f} %): it does not "
          "reproduce these data; check their units (u: PWM duty in %, y: force in N or "
          "position in m), the initial state and the free parameters",
          e.name, e.fit_percent, e.initial_fit_percent));
}

// Ceres stops with "convergence" on a zero gradient, which a flat region
// also gives: a step that makes the twin stop responding to every free
// parameter (e.g. a valve delay longer than the PWM pulses: no valve opens,
// the force is constant). Such an end point is not a minimum: a failure.
void RejectFlatRegion(const Eigen::MatrixXd& J, const Eigen::VectorXd& residuals,
                      const std::vector<std::string>& keys, const std::string& ceres_message,
                      IpaCalibrationSummary* out) {
  const double flat = 1e-9 * std::max(residuals.norm(), 1e-300);
  std::vector<std::string> responding;
  for (Eigen::Index i = 0; i < J.cols(); ++i)
    if (J.col(i).norm() > flat) responding.push_back(keys[i]);
  if (!responding.empty()) return;
  out->termination = Termination::kFailure;
  out->message = fmt::format(
      "the calibration stopped where the simulated output no longer responds to any free "
      "parameter ({}): a flat region, not a minimum (Ceres: {}); free fewer parameters or "
      "start closer to the actuator",
      fmt::join(keys, ", "), ceres_message);
}

// Standard deviations (physical units, NaN when unknown) and whether the
// data determine each free parameter.
struct ParameterUncertainty {
  Eigen::VectorXd std_dev;
  std::vector<bool> determined;
};

// Uncertainty and identifiability from the Jacobian J of the weighted
// residuals at the solution (header comment); strong correlations go to
// *correlations.
ParameterUncertainty UncertaintyFromJacobian(const Eigen::MatrixXd& J,
                                             const Eigen::VectorXd& residuals,
                                             const FreeParameters& free,
                                             double correlation_threshold,
                                             std::vector<ParameterCorrelation>* correlations) {
  const int np = free.size();
  ParameterUncertainty out{Eigen::VectorXd::Constant(np, kNaN), std::vector<bool>(np, true)};
  Eigen::JacobiSVD<Eigen::MatrixXd> svd(J, Eigen::ComputeThinV);
  const Eigen::VectorXd singular = svd.singularValues();
  const Eigen::MatrixXd& V = svd.matrixV();
  const double smax = singular.size() > 0 ? singular[0] : 0.0;
  Eigen::VectorXd inv2 = Eigen::VectorXd::Zero(np);
  for (int j = 0; j < np; ++j) {
    if (smax > 0.0 && singular[j] > 1e-10 * smax) inv2[j] = 1.0 / (singular[j] * singular[j]);
    if (!(smax > 0.0) || singular[j] < 1e-4 * smax)
      for (int i = 0; i < np; ++i)
        if (std::abs(V(i, j)) > 0.3) out.determined[i] = false;
  }
  const double dof = static_cast<double>(std::max<Eigen::Index>(residuals.size() - np, 1));
  const double sigma2 = residuals.squaredNorm() / dof;
  const Eigen::MatrixXd C = V * inv2.asDiagonal() * V.transpose() * sigma2;  // scaled units
  for (int i = 0; i < np; ++i) out.std_dev[i] = std::sqrt(std::max(C(i, i), 0.0)) * free.scale[i];
  for (int i = 0; i < np; ++i)
    for (int j = i + 1; j < np; ++j) {
      const double std_product = std::sqrt(C(i, i) * C(j, j));
      if (!(std_product > 0.0)) continue;
      const double rho = C(i, j) / std_product;
      if (std::abs(rho) >= correlation_threshold)
        correlations->push_back({free.keys[i], free.keys[j], rho});
    }
  return out;
}

std::string UndeterminedWarning(const std::vector<std::string>& undetermined) {
  std::string list;
  for (const auto& n : undetermined) list += (list.empty() ? "" : ", ") + n;
  return undetermined.size() == 1
             ? fmt::format(
                   "the data do not determine {}: its effect on the output is too small "
                   "or is taken up by the other free parameters; fix it (leave it out of "
                   "the free parameters) or add an experiment that excites it",
                   list)
             : fmt::format(
                   "the data do not determine {} separately (only a combination of "
                   "them): fix one of them (leave it out of the free parameters) or add "
                   "an experiment that separates them",
                   list);
}

// One estimate per free parameter, with warnings for vague, undetermined
// and bound-limited ones.
void ReportEstimates(const FreeParameters& free, const ParameterUncertainty& uncertainty,
                     IpaCalibrationSummary* out) {
  std::vector<std::string> undetermined;
  for (int i = 0; i < free.size(); ++i) {
    CalibratedParameter c;
    c.name = free.keys[i];
    c.unit = free.units[i];
    c.value = free.values[i] * free.scale[i];
    c.start = free.start[i];
    c.lower = free.lower[i] * free.scale[i];
    c.upper = free.upper[i] * free.scale[i];
    c.std = uncertainty.std_dev[i];
    const double width = c.upper - c.lower;
    c.at_bound = c.value - c.lower <= 1e-6 * width || c.upper - c.value <= 1e-6 * width;
    const bool vague = std::isfinite(c.std) && c.value != 0.0 && c.std > 0.1 * std::abs(c.value);
    c.determined = uncertainty.determined[i] && !vague && std::isfinite(c.std);
    if (!uncertainty.determined[i])
      undetermined.push_back(c.name);
    else if (vague)
      out->warnings.push_back(
          fmt::format("{} is poorly determined by the data: {:.4g} +- {:.2g} {} ({:.0f} %)", c.name,
                      c.value, c.std, c.unit, 100.0 * c.std / std::abs(c.value)));
    if (c.at_bound)
      out->warnings.push_back(
          fmt::format("{} ended at its bound ({:.4g} {}, range {:.4g} .. {:.4g})", c.name, c.value,
                      c.unit, c.lower, c.upper));
    out->estimates.push_back(c);
  }
  if (!undetermined.empty()) out->warnings.push_back(UndeterminedWarning(undetermined));
}

}  // namespace

IpaCalibrationSummary CalibrateIpa(const std::vector<CalibrationExperiment>& experiments,
                                   const IpaCalibrationOptions& options) {
  std::string error;
  PNEUMID_CHECK(options.IsValid(&error), "invalid calibration options: {}", error);
  PNEUMID_CHECK(!experiments.empty(), "calibration needs at least one experiment");
  FreeParameters free = ScaleFreeParameters(options);
  const int np = free.size();
  const std::vector<PreparedExperiment> prepared = PrepareExperiments(experiments);
  const Eigen::Index total = TotalSamples(prepared);
  PNEUMID_CHECK(total > np, "{} samples in all cannot determine {} free parameters", total, np);

  const auto t_begin = std::chrono::steady_clock::now();
  IpaCalibrationSummary out;
  out.parameters = options.start;
  Problem problem(prepared, options, free.keys, free.scale, free.lower, free.upper);
  Eigen::VectorXd r0(total);
  if (!problem.Residuals(free.values.data(), r0.data())) {
    out.termination = Termination::kFailure;
    out.message =
        "the simulation with the start parameters fails: " + StartFailureReason(prepared, options);
    return out;
  }
  out.experiments = InitialFits(prepared, r0);

  const ceres::Solver::Summary summary = SolveCalibration(problem, options, &free);
  RecordSolverSummary(summary, &out);
  out.parameters = options.start;
  for (int i = 0; i < np; ++i)
    SetIpaParameter(out.parameters, free.keys[i], free.values[i] * free.scale[i]);

  Eigen::VectorXd r(total);
  if (!problem.Residuals(free.values.data(), r.data())) {
    out.termination = Termination::kFailure;
    out.message = "the simulation with the calibrated parameters fails";
    out.parameters = options.start;
    return out;
  }
  StoreCalibratedFits(prepared, r, &out.experiments);
  AddPoorFitWarnings(options.fit_warning_percent, &out);
  Eigen::MatrixXd J(total, np);
  const bool have_j = problem.Jacobian(free.values.data(), r.data(), J.data());
  if (have_j && out.termination == Termination::kConvergence && J.allFinite())
    RejectFlatRegion(J, r, free.keys, summary.message, &out);

  // Uncertainty and identifiability (header comment).
  ParameterUncertainty uncertainty{Eigen::VectorXd::Constant(np, kNaN),
                                   std::vector<bool>(np, true)};
  if (have_j && J.allFinite()) {
    uncertainty =
        UncertaintyFromJacobian(J, r, free, options.correlation_threshold, &out.correlations);
  } else {
    out.warnings.push_back(
        "the Jacobian at the solution could not be formed: no standard "
        "deviations");
  }
  ReportEstimates(free, uncertainty, &out);
  out.simulations = problem.simulations();
  out.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t_begin).count();
  return out;
}

}  // namespace pneumid
