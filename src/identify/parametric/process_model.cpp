#include "pneumid/identify/parametric/process_model.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <limits>
#include <memory>
#include <optional>
#include <tuple>

#include <ceres/ceres.h>
#include <fmt/format.h>

#include "../ceres_logging.hpp"
#include "pneumid/common/check.hpp"
#include "pneumid/common/enum_names.hpp"
#include "pneumid/identify/step/reaction_curve.hpp"
#include "pneumid/identify/step/sopdt.hpp"
#include "pneumid/identify/step/step_analysis.hpp"
#include "pneumid/lti/response.hpp"

namespace pneumid {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

enum Slot { kK, kT1, kT2, kT3, kTw, kZeta, kTz, kTheta, kY0 };

double ProcessParams::*Member(Slot s) {
  switch (s) {
    case kK:
      return &ProcessParams::K;
    case kT1:
      return &ProcessParams::T1;
    case kT2:
      return &ProcessParams::T2;
    case kT3:
      return &ProcessParams::T3;
    case kTw:
      return &ProcessParams::Tw;
    case kZeta:
      return &ProcessParams::zeta;
    case kTz:
      return &ProcessParams::Tz;
    case kTheta:
      return &ProcessParams::theta;
    case kY0:
      return &ProcessParams::y0;
  }
  return &ProcessParams::K;
}

std::vector<Slot> Slots(ProcessStructure s, bool zero, bool offset) {
  std::vector<Slot> v{kK};
  switch (s) {
    case ProcessStructure::kP1D:
    case ProcessStructure::kP1DI:
      v.push_back(kT1);
      break;
    case ProcessStructure::kP2D:
      v.insert(v.end(), {kT1, kT2});
      break;
    case ProcessStructure::kP2DU:
      v.insert(v.end(), {kTw, kZeta});
      break;
    case ProcessStructure::kP3D:
      v.insert(v.end(), {kT1, kT2, kT3});
      break;
  }
  if (zero) v.push_back(kTz);
  v.push_back(kTheta);
  if (offset) v.push_back(kY0);
  return v;
}

std::string SlotName(ProcessStructure s, Slot slot) {
  const bool one = s == ProcessStructure::kP1D || s == ProcessStructure::kP1DI;
  switch (slot) {
    case kK:
      return "K";
    case kT1:
      return one ? "tau" : "tau1";
    case kT2:
      return "tau2";
    case kT3:
      return "tau3";
    case kTw:
      return "Tw";
    case kZeta:
      return "zeta";
    case kTz:
      return "Tz";
    case kTheta:
      return "theta";
    case kY0:
      return "y0";
  }
  return "?";
}

// Input before its first change, and the index of that change (n if none).
std::pair<double, Eigen::Index> InitialInput(const Eigen::VectorXd& u) {
  const double tol = 1e-12 * std::max(1.0, u.cwiseAbs().maxCoeff());
  Eigen::Index k = 0;
  while (k < u.size() && std::abs(u[k] - u[0]) <= tol) ++k;
  return {u[0], k};
}

// Robust noise standard deviation from first differences (MAD).
double RobustNoise(const Eigen::VectorXd& y) {
  if (y.size() < 3) return 0.0;
  std::vector<double> d(static_cast<std::size_t>(y.size() - 1));
  for (Eigen::Index k = 1; k < y.size(); ++k) d[k - 1] = y[k] - y[k - 1];
  auto median = [](std::vector<double> v) {
    std::nth_element(v.begin(), v.begin() + static_cast<long>(v.size() / 2), v.end());
    return v[v.size() / 2];
  };
  const double m = median(d);
  for (double& x : d) x = std::abs(x - m);
  return 1.4826 * median(d) / std::sqrt(2.0);
}

// Simulates the model for a parameter vector (physical units); shared by the
// residual blocks through a cache keyed on the parameter values.
class Simulator {
 public:
  Simulator(ProcessStructure structure, bool zero, std::vector<Slot> slots, ProcessParams fixed,
            Eigen::VectorXd du, Eigen::VectorXd y, double Ts, Eigen::VectorXd scale,
            Eigen::VectorXd lower, Eigen::VectorXd upper)
      : structure_(structure),
        zero_(zero),
        slots_(std::move(slots)),
        fixed_(fixed),
        du_(std::move(du)),
        y_(std::move(y)),
        Ts_(Ts),
        scale_(std::move(scale)),
        lower_(std::move(lower)),
        upper_(std::move(upper)) {}

  int num_params() const { return static_cast<int>(slots_.size()); }
  Eigen::Index num_samples() const { return y_.size(); }

  ProcessParams ToParams(const double* x) const {
    ProcessParams p = fixed_;
    for (std::size_t i = 0; i < slots_.size(); ++i) p.*Member(slots_[i]) = x[i] * scale_[i];
    return p;
  }

  // Response of the model with unit gain and no offset to the input steps du
  // (the output is linear in K and y0: yhat = K h + y0); false when invalid.
  bool UnitResponse(const double* x, Eigen::VectorXd* h) const {
    ProcessParams p = ToParams(x);
    p.K = 1.0;
    try {
      *h = Lsim(ProcessTransferFunction(structure_, zero_, p), du_, Ts_);
      return h->allFinite();
    } catch (const std::exception&) {
      return false;
    }
  }

  // Residuals y - yhat for scaled parameters x; false when the model is invalid.
  bool Residuals(const double* x, Eigen::VectorXd* r) const {
    Eigen::VectorXd h;
    if (!UnitResponse(x, &h)) return false;
    const ProcessParams p = ToParams(x);
    *r = y_ - (p.K * h.array() + p.y0).matrix();
    return r->allFinite();
  }

  // Evaluates residuals (and the Jacobian when wanted) at x, caching the result.
  // K and y0 enter linearly and have exact columns (-h scale_K, -scale_y0); the
  // lags, zero and delay have forward differences of K h (step 1e-7 relative,
  // backward at an upper bound): one simulation per parameter.
  bool Evaluate(const double* x, bool want_jacobian) {
    const int np = num_params();
    const bool same = valid_ && std::equal(x, x + np, x_.data());
    if (same && (!want_jacobian || jacobian_valid_)) return ok_;
    x_ = Eigen::Map<const Eigen::VectorXd>(x, np);
    valid_ = true;
    jacobian_valid_ = false;
    ok_ = UnitResponse(x, &h_);
    if (!ok_) return ok_;
    const ProcessParams p = ToParams(x);
    r_ = y_ - (p.K * h_.array() + p.y0).matrix();
    ok_ = r_.allFinite();
    if (!ok_ || !want_jacobian) return ok_;
    J_.resize(r_.size(), np);
    Eigen::VectorXd xp = x_, hp, hm;
    for (int j = 0; j < np; ++j) {
      if (slots_[j] == kK) {
        J_.col(j) = -scale_[j] * h_;
        continue;
      }
      if (slots_[j] == kY0) {
        J_.col(j).setConstant(-scale_[j]);
        continue;
      }
      const double step = 1e-7 * std::max(1.0, std::abs(x_[j]));
      const bool can_up = x_[j] + step <= upper_[j];
      const bool can_down = x_[j] - step >= lower_[j];
      double hu = can_up ? step : 0.0, hd = can_down && !can_up ? step : 0.0;
      if (!can_up && !can_down) hu = step;  // degenerate bounds: step outside anyway
      xp = x_;
      xp[j] = x_[j] + hu;
      if (hu > 0.0) {
        if (!UnitResponse(xp.data(), &hp)) return ok_ = false;
      } else {
        hp = h_;
      }
      xp[j] = x_[j] - hd;
      if (hd > 0.0) {
        if (!UnitResponse(xp.data(), &hm)) return ok_ = false;
      } else {
        hm = h_;
      }
      J_.col(j) = (-p.K / (hu + hd)) * (hp - hm);
    }
    jacobian_valid_ = true;
    return ok_;
  }

  const Eigen::VectorXd& residuals() const { return r_; }
  const Eigen::MatrixXd& jacobian() const { return J_; }

 private:
  ProcessStructure structure_;
  bool zero_;
  std::vector<Slot> slots_;
  ProcessParams fixed_;
  Eigen::VectorXd du_, y_;
  double Ts_;
  Eigen::VectorXd scale_, lower_, upper_;
  Eigen::VectorXd x_, r_, h_;
  Eigen::MatrixXd J_;
  bool valid_ = false, jacobian_valid_ = false, ok_ = false;
};

// One sample's residual; all blocks share the Simulator (single-threaded solve).
class SampleResidual : public ceres::CostFunction {
 public:
  SampleResidual(Simulator* sim, Eigen::Index k) : sim_(sim), k_(k) {
    set_num_residuals(1);
    mutable_parameter_block_sizes()->push_back(sim->num_params());
  }
  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override {
    const bool want_j = jacobians != nullptr && jacobians[0] != nullptr;
    if (!sim_->Evaluate(parameters[0], want_j)) return false;
    residuals[0] = sim_->residuals()[k_];
    if (want_j) {
      for (int j = 0; j < sim_->num_params(); ++j) jacobians[0][j] = sim_->jacobian()(k_, j);
    }
    return true;
  }

 private:
  Simulator* sim_;
  Eigen::Index k_;
};

// All samples' residuals in one block (least squares without a robust loss):
// one simulation per evaluation and a dense N x np Jacobian, without the
// per-block overhead of N one-sample blocks.
class RecordResidual : public ceres::CostFunction {
 public:
  explicit RecordResidual(Simulator* sim) : sim_(sim) {
    set_num_residuals(static_cast<int>(sim->num_samples()));
    mutable_parameter_block_sizes()->push_back(sim->num_params());
  }
  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override {
    const bool want_j = jacobians != nullptr && jacobians[0] != nullptr;
    if (!sim_->Evaluate(parameters[0], want_j)) return false;
    const Eigen::Index n = sim_->num_samples();
    Eigen::Map<Eigen::VectorXd>(residuals, n) = sim_->residuals();
    if (want_j) {
      using RowMajor = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;
      Eigen::Map<RowMajor>(jacobians[0], n, sim_->num_params()) = sim_->jacobian();
    }
    return true;
  }

 private:
  Simulator* sim_;
};

}  // namespace

namespace {
constexpr EnumName<ProcessStructure> kProcessStructureNames[] = {
    {ProcessStructure::kP1D, "P1D"},   {ProcessStructure::kP2D, "P2D"},
    {ProcessStructure::kP2DU, "P2DU"}, {ProcessStructure::kP3D, "P3D"},
    {ProcessStructure::kP1DI, "P1DI"},
};
constexpr EnumName<RobustLoss> kRobustLossNames[] = {
    {RobustLoss::kNone, "none"}, {RobustLoss::kHuber, "huber"}, {RobustLoss::kCauchy, "cauchy"}};
}  // namespace

std::string ToString(ProcessStructure structure) {
  return std::string(EnumToString(kProcessStructureNames, structure));
}

ProcessStructure ProcessStructureFromString(const std::string& name, bool* zero) {
  // A trailing Z (no structure name ends in Z) adds a zero: P2DZ = P2D with (1 + Tz s).
  const bool z = !name.empty() && (name.back() == 'z' || name.back() == 'Z');
  const auto s = EnumLookup(kProcessStructureNames,
                            std::string_view(name).substr(0, name.size() - (z ? 1 : 0)),
                            /*ignore_case=*/true);
  PNEUMID_CHECK(s.has_value(),
                "unknown process model structure '{}' (valid: {}, each optionally followed by Z "
                "for a zero)",
                name, EnumNameList(kProcessStructureNames));
  if (zero) *zero = z;
  return *s;
}

std::string ToString(RobustLoss loss) { return std::string(EnumToString(kRobustLossNames, loss)); }

RobustLoss RobustLossFromString(const std::string& name) {
  return EnumFromString(kRobustLossNames, name, "robust loss", /*ignore_case=*/true);
}

bool ProcessFitOptions::IsValid(std::string* error) const {
  auto fail = [&](const std::string& m) {
    if (error) *error = m;
    return false;
  };
  if (!(loss_scale >= 0.0 && std::isfinite(loss_scale)))
    return fail(fmt::format("loss_scale must be >= 0, got {}", loss_scale));
  if (!(max_delay >= 0.0 && std::isfinite(max_delay)))
    return fail(fmt::format("max_delay must be >= 0 s, got {}", max_delay));
  if (max_iterations < 1)
    return fail(fmt::format("max_iterations must be >= 1, got {}", max_iterations));
  if (!(function_tolerance > 0.0))
    return fail(fmt::format("function_tolerance must be > 0, got {}", function_tolerance));
  if (!(parameter_tolerance > 0.0))
    return fail(fmt::format("parameter_tolerance must be > 0, got {}", parameter_tolerance));
  return true;
}

std::string ProcessFitSummary::BriefReport() const {
  return fmt::format(
      "process fit: {} after {} iterations, cost {:.6g} -> {:.6g}, residual std "
      "{:.4g}, initial guess from {}{}",
      ToString(termination), iterations, initial_cost, final_cost, sigma, initial_guess,
      message.empty() ? "" : " (" + message + ")");
}

TransferFunction ProcessTransferFunction(ProcessStructure structure, bool zero,
                                         const ProcessParams& p) {
  PNEUMID_CHECK(std::isfinite(p.K), "process model: K must be finite, got {}", p.K);
  PNEUMID_CHECK(std::isfinite(p.theta) && p.theta >= 0.0,
                "process model: delay theta must be >= 0 s, got {}", p.theta);
  auto lag = [](double T, const char* name) {
    PNEUMID_CHECK(std::isfinite(T) && T > 0.0, "process model: {} must be > 0 s, got {}", name, T);
    Eigen::VectorXd v(2);
    v << T, 1.0;
    return v;
  };
  Eigen::VectorXd den(1);
  den << 1.0;
  switch (structure) {
    case ProcessStructure::kP1D:
      den = lag(p.T1, "tau");
      break;
    case ProcessStructure::kP2D:
      den = poly::Multiply(lag(p.T1, "tau1"), lag(p.T2, "tau2"));
      break;
    case ProcessStructure::kP3D:
      den = poly::Multiply(poly::Multiply(lag(p.T1, "tau1"), lag(p.T2, "tau2")), lag(p.T3, "tau3"));
      break;
    case ProcessStructure::kP2DU:
      PNEUMID_CHECK(std::isfinite(p.Tw) && p.Tw > 0.0, "process model: Tw must be > 0 s, got {}",
                    p.Tw);
      PNEUMID_CHECK(std::isfinite(p.zeta) && p.zeta >= 0.0,
                    "process model: zeta must be >= 0, got {}", p.zeta);
      den.resize(3);
      den << p.Tw * p.Tw, 2.0 * p.zeta * p.Tw, 1.0;
      break;
    case ProcessStructure::kP1DI: {
      Eigen::VectorXd s(2);
      s << 1.0, 0.0;
      den = poly::Multiply(s, lag(p.T1, "tau"));
      break;
    }
  }
  Eigen::VectorXd num(1);
  num << p.K;
  if (zero) {
    PNEUMID_CHECK(std::isfinite(p.Tz), "process model: Tz must be finite, got {}", p.Tz);
    num.resize(2);
    num << p.K * p.Tz, p.K;
    if (p.Tz == 0.0) {
      num.resize(1);
      num << p.K;
    }
  }
  return TransferFunction(num, den, 0.0, p.theta);
}

std::vector<std::pair<std::string, double>> NamedParams(ProcessStructure structure, bool zero,
                                                        const ProcessParams& p) {
  std::vector<std::pair<std::string, double>> v;
  for (Slot s : Slots(structure, zero, true)) v.emplace_back(SlotName(structure, s), p.*Member(s));
  return v;
}

namespace {

// The input rests a record may start from (GridGuess): u0, the input before
// its first change at index k0, and when the record does not start with a
// rest (k0 < max(3, n/100)) also zero and the input's mean.
std::vector<double> InputRests(const Eigen::VectorXd& u, double u0, Eigen::Index k0) {
  std::vector<double> rests = {u0};
  if (k0 < std::max<Eigen::Index>(3, u.size() / 100)) {
    for (double c : {0.0, u.mean()})
      if (std::abs(c - u0) > 1e-9 * std::max(1.0, u.cwiseAbs().maxCoeff())) rests.push_back(c);
  }
  return rests;
}

// Grid search for an initial guess: lags T (geometric, 2 Ts .. a quarter of
// the record) and delays theta in {0, 0.1, 0.3, 1} T and in whole samples
// (0, 1, 2, 3, then 1.4 times apart up to a quarter of the record), plus the
// (T, theta) pairs of `extra`; K and y0 by linear least squares each. The
// sample delays matter on records without a clean step (white noise, a
// PRBS, a chirp), where the cost has a minimum for each delay: from delays
// tied to T alone a SOPDT (K 1.5, tau 0.8 s and 0.3 s, theta 0.4 s) under
// white noise was fitted as K 0.95, tau 0.385 s twice, theta 0.44 s (50 %).
// The input's steady state before the record, `rest` (the input before its
// first change when the record starts with a rest; else, white noise, a
// chirp, it changes at once, also zero and the input's mean: a SOPDT at rest
// at zero under white noise simulated from rest at u(0) = 1.45 carried a
// transient no lag fits).
// The best grid point for one input rest, and its cost (sum of squares).
std::pair<ProcessParams, double> GridGuessAt(ProcessStructure structure, const Eigen::VectorXd& u,
                                             const Eigen::VectorXd& y, double rest, double Ts,
                                             double duration,
                                             const std::vector<std::pair<double, double>>& extra) {
  const Eigen::Index n = u.size();
  std::vector<double> sample_delays;
  for (double d = 0.0; d * Ts <= 0.25 * duration; d = d < 3.0 ? d + 1.0 : std::round(d * 1.4))
    sample_delays.push_back(d * Ts);
  std::vector<std::pair<double, double>> candidates = extra;
  const int nT = 16;
  for (int i = 0; i < nT; ++i) {
    const double T = 2.0 * Ts * std::pow(0.25 * duration / Ts, static_cast<double>(i) / (nT - 1));
    for (double delay : {0.0, 0.1 * T, 0.3 * T, T}) candidates.emplace_back(T, delay);
    for (double delay : sample_delays) candidates.emplace_back(T, delay);
  }
  ProcessParams p;
  p.K = 1.0;
  p.u0 = rest;
  double best = std::numeric_limits<double>::infinity();
  const Eigen::VectorXd du = (u.array() - rest).matrix();
  for (const auto& [T, delay] : candidates) {
    ProcessParams q;
    q.K = 1.0;
    q.T1 = T;
    q.T2 = 0.5 * T;
    q.T3 = 0.25 * T;
    q.Tw = 0.5 * T;
    q.zeta = 0.7;
    q.theta = std::min(delay, 0.5 * duration);
    Eigen::VectorXd h;
    try {
      h = Lsim(ProcessTransferFunction(structure, false, q), du, Ts);
    } catch (const std::exception&) {
      continue;
    }
    Eigen::MatrixXd A(n, 2);
    A.col(0) = h;
    A.col(1).setOnes();
    const Eigen::Vector2d c = A.colPivHouseholderQr().solve(y);
    const double cost = (A * c - y).squaredNorm();
    if (std::isfinite(cost) && cost < best && c[0] != 0.0) {
      best = cost;
      q.K = c[0];
      q.y0 = c[1];
      q.u0 = rest;
      p = q;
    }
  }
  return {p, best};
}

// The best grid point of each input rest of InputRests, in its order.
std::vector<std::pair<ProcessParams, double>> GridGuesses(
    ProcessStructure structure, const Eigen::VectorXd& u, const Eigen::VectorXd& y, double u0,
    Eigen::Index k0, double Ts, double duration,
    const std::vector<std::pair<double, double>>& extra) {
  std::vector<std::pair<ProcessParams, double>> points;
  for (double rest : InputRests(u, u0, k0))
    points.push_back(GridGuessAt(structure, u, y, rest, Ts, duration, extra));
  return points;
}

// The lowest-cost point of GridGuesses (the first on a tie).
ProcessParams BestGridPoint(const std::vector<std::pair<ProcessParams, double>>& points) {
  ProcessParams best;
  best.K = 1.0;
  double cost = std::numeric_limits<double>::infinity();
  for (const auto& [p, c] : points) {
    if (c < cost) {
      best = p;
      cost = c;
    }
  }
  return best;
}

// InitialProcessGuess, and the best grid point of each input rest when the
// guess came from the grid search (empty otherwise), for FitProcessModel's
// multi-start.
struct ProcessGuess {
  ProcessParams params;
  std::string source;
  std::vector<std::pair<ProcessParams, double>> rest_points;
};

ProcessGuess GuessProcess(const Dataset& data, int input, int output, ProcessStructure structure,
                          bool zero) {
  ProcessGuess guess;
  const Eigen::VectorXd u = data.u(input), y = data.y(output), t = data.time();
  const Eigen::Index n = data.size();
  const double duration = t[n - 1] - t[0];
  const auto [u0, k0] = InitialInput(u);
  ProcessParams p;
  p.y0 = k0 > 0 ? y.head(k0).mean() : y[0];
  std::string from;
  if (structure == ProcessStructure::kP1DI) {
    // Final ramp: y ~ y0 + K du (t - t_s - theta - T1) over the last 30 %.
    const Eigen::Index m = std::max<Eigen::Index>(3, n * 3 / 10);
    const Eigen::VectorXd tt = t.tail(m), yy = y.tail(m);
    const double tm = tt.mean(), ym = yy.mean();
    const double slope =
        ((tt.array() - tm) * (yy.array() - ym)).sum() / (tt.array() - tm).square().sum();
    const double du = u.tail(m).mean() - u0;
    const double ts = k0 < n ? t[k0] : t[0];
    p.K = du != 0.0 ? slope / du : 1.0;
    const double tx = slope != 0.0 ? tm - (ym - p.y0) / slope : ts + 0.1 * duration;
    const double lag = std::clamp(tx - ts, 0.01 * duration, 0.5 * duration);
    p.T1 = 0.7 * lag;
    p.theta = 0.3 * lag;
    from = "the final ramp";
    // A ramp the record ends with is a guess only after a step; under a
    // PRBS or white noise the output of an integrator wanders (a K = 1/s
    // plant got K = -0.008 from it): the grid search, with the ramp's lag
    // and delay among its candidates, takes the better of them.
    if (k0 < std::max<Eigen::Index>(3, n / 100) || !std::isfinite(p.K)) {
      guess.rest_points =
          GridGuesses(structure, u, y, u0, k0, data.SampleTime(), duration, {{p.T1, p.theta}});
      p = BestGridPoint(guess.rest_points);
      from = "a grid search over lag and delay (with the final ramp's)";
    }
  } else {
    // The first step of the record (up to the next input change), when it is
    // a clean settled step, gives the graphical initial guess.
    Eigen::Index k1 = k0;
    const double utol = 0.05 * std::abs(k0 < n ? u[k0] - u0 : 0.0);
    while (k1 < n && std::abs(u[k1] - u[k0]) <= utol) ++k1;
    Dataset first = data;
    if (k1 < n && k1 >= 10) {
      first = Dataset(t.head(k1), data.inputs().topRows(k1), data.outputs().topRows(k1),
                      data.input_channels(), data.output_channels());
      first.set_source(data.source());
    }
    bool have_step = false;
    try {
      const StepAnalysis s = AnalyzeStep(first, input, output);
      p.y0 = s.y0;
      if (structure == ProcessStructure::kP1D) {
        const FopdtParams f = ReactionCurve(s);
        p.K = f.K;
        p.T1 = f.tau;
        p.theta = f.theta;
        from = k1 < n ? "the reaction curve of the first step" : "the reaction curve";
      } else {
        const ThreePointSopdtResult so = ThreePointSopdt(s);
        p.K = so.params.K;
        p.T1 = so.params.tau1;
        p.T2 = std::max(so.params.tau2, 0.05 * so.params.tau1);
        p.theta = so.params.theta;
        from = k1 < n ? "the three-point SOPDT of the first step" : "the three-point SOPDT";
        if (structure == ProcessStructure::kP3D) {
          p.T3 = 0.5 * p.T2;
          p.theta = std::max(0.0, p.theta - p.T3);
        } else if (structure == ProcessStructure::kP2DU) {
          p.Tw = std::sqrt(p.T1 * p.T2);
          p.zeta = std::min(1.0, (p.T1 + p.T2) / (2.0 * p.Tw));
          const double peak = s.r.maxCoeff();
          if (peak > 1.0 + s.band) {
            const double lo = std::log(peak - 1.0);
            p.zeta = -lo / std::sqrt(M_PI * M_PI + lo * lo);
            Eigen::Index kp;
            s.r.maxCoeff(&kp);
            const double tp = std::max(s.t[kp] - s.departure_time, 2.0 * s.Ts);
            p.Tw = tp * std::sqrt(1.0 - p.zeta * p.zeta) / M_PI;
            p.theta = s.departure_time;
          }
          p.zeta = std::clamp(p.zeta, 0.05, 0.99);
        }
      }
      have_step = true;
    } catch (const std::exception&) {  // not a clean step: fall back to the grid
      have_step = false;
    }
    if (!have_step) {
      guess.rest_points = GridGuesses(structure, u, y, u0, k0, data.SampleTime(), duration, {});
      p = BestGridPoint(guess.rest_points);
      from = "a grid search over lag and delay";
    }
  }
  if (p.K == 0.0) p.K = 1.0;
  if (zero) p.Tz = 0.0;
  guess.params = p;
  guess.source = from;
  return guess;
}

}  // namespace

ProcessParams InitialProcessGuess(const Dataset& data, int input, int output,
                                  ProcessStructure structure, bool zero, std::string* source) {
  ProcessGuess guess = GuessProcess(data, input, output, structure, zero);
  if (source) *source = guess.source;
  return guess.params;
}

namespace {

// The checked columns of a process-model fit and what the fit needs of the record.
struct ProcessFitRecord {
  std::string source;  // name of the data in messages
  Eigen::VectorXd u, y;
  double u0 = 0.0;      // input before its first change
  Eigen::Index k0 = 0;  // index of the first input change
  double Ts = 0.0;
  double duration = 0.0;  // time span of the record
};

ProcessFitRecord CheckedProcessFitRecord(const Dataset& data, int input, int output,
                                         const ProcessFitOptions& options) {
  std::string why;
  PNEUMID_CHECK(options.IsValid(&why), "invalid ProcessFitOptions: {}", why);
  PNEUMID_CHECK(input >= 0 && input < data.num_inputs(),
                "input column {} out of range (the data has {} inputs)", input, data.num_inputs());
  PNEUMID_CHECK(output >= 0 && output < data.num_outputs(),
                "output column {} out of range (the data has {} outputs)", output,
                data.num_outputs());
  ProcessFitRecord record;
  record.source = data.source().empty() ? "data" : data.source();
  data.RequireSamples(10, "process-model fit");
  data.RequireUniform();
  record.u = data.u(input);
  record.y = data.y(output);
  if (!record.u.allFinite() || !record.y.allFinite()) {
    throw DataError(fmt::format("{}: the data contain NaN or Inf", record.source));
  }
  std::tie(record.u0, record.k0) = InitialInput(record.u);
  if (record.k0 >= data.size()) {
    throw DataError(fmt::format("{}: the input never changes (u = {}); nothing to fit",
                                record.source, record.u0));
  }
  record.Ts = data.SampleTime();
  record.duration = data.time()[data.size() - 1] - data.time()[0];
  return record;
}

// A zero is fitted from the converged model without it, started with
// Tz = 0 and with Tz = +-Tm (Tm = the second lag, at least T1 / 5, the
// faster lags raised to Tm); the lowest cost wins. Without any fit that
// does not fail: nullopt, with the model without zero (Tz = 0) in *start.
std::optional<ProcessFitResult> FitZeroFromModelWithoutZero(const Dataset& data, int input,
                                                            int output,
                                                            const ProcessFitOptions& options,
                                                            ProcessParams* start,
                                                            std::string* source) {
  ProcessFitOptions no_zero = options;
  no_zero.zero = false;
  const ProcessFitResult first = FitProcessModel(data, input, output, no_zero);
  const double T1 =
      options.structure == ProcessStructure::kP2DU ? first.params.Tw : first.params.T1;
  const double Tm = std::max(first.params.T2, 0.2 * T1);
  ProcessFitResult best;
  bool have = false;
  for (double sign : {0.0, 1.0, -1.0}) {
    ProcessParams zero_start = first.params;
    zero_start.Tz = sign * Tm;
    if (sign != 0.0) {
      zero_start.T2 = std::max(zero_start.T2, Tm);
      zero_start.T3 = std::max(zero_start.T3, 0.5 * Tm);
    }
    ProcessFitResult fit = FitProcessModel(data, input, output, options, &zero_start);
    if (fit.summary.termination != Termination::kFailure &&
        (!have || fit.summary.final_cost < best.summary.final_cost)) {
      best = std::move(fit);
      have = true;
    }
  }
  if (have) {
    best.summary.initial_guess = "the fitted " + ToString(options.structure) +
                                 " without zero, Tz started at 0 and +-" +
                                 fmt::format("{:.4g}", Tm) + " s";
    return best;
  }
  *start = first.params;
  start->Tz = 0.0;
  *source = "the fitted " + ToString(options.structure) + " without zero";
  return std::nullopt;
}

// The estimated parameters in scaled units (of order one) and their bounds.
struct ScaledParameters {
  Eigen::VectorXd scale;         // physical value of one scaled unit
  Eigen::VectorXd lower, upper;  // bounds, scaled
  Eigen::VectorXd values;        // scaled: the start (clamped to the bounds), then the solution
};

// Scales and bounds (physical), then the scaled start.
ScaledParameters ScaleAndBound(const std::vector<Slot>& slots, const ProcessParams& start,
                               const ProcessFitOptions& options, const ProcessFitRecord& record,
                               double y_scale) {
  const double Ts = record.Ts, duration = record.duration;
  const double max_delay = options.max_delay > 0.0 ? options.max_delay : 0.5 * duration;
  const double t_scale = std::max({start.T1, start.Tw, 10.0 * Ts});
  const auto np = static_cast<Eigen::Index>(slots.size());
  ScaledParameters scaled;
  scaled.scale.resize(np);
  scaled.lower.resize(np);
  scaled.upper.resize(np);
  scaled.values.resize(np);
  const double inf = std::numeric_limits<double>::infinity();
  for (Eigen::Index i = 0; i < np; ++i) {
    const Slot slot = slots[static_cast<std::size_t>(i)];
    double scale = 1.0, lower = -inf, upper = inf;
    switch (slot) {
      case kK:
        scale = std::abs(start.K) > 0.0 ? std::abs(start.K) : 1.0;
        break;
      case kT1:
      case kT2:
      case kT3:
      case kTw:
        scale = t_scale;
        lower = 1e-3 * Ts;
        upper = 100.0 * duration;
        break;
      case kZeta:
        scale = 1.0;
        lower = 1e-3;
        upper = 1.0;
        break;
      case kTz:
        scale = t_scale;
        lower = -10.0 * duration;
        upper = 10.0 * duration;
        break;
      case kTheta:
        scale = t_scale;
        lower = 0.0;
        upper = max_delay;
        break;
      case kY0:
        scale = y_scale;
        break;
    }
    scaled.scale[i] = scale;
    scaled.lower[i] = lower / scale;
    scaled.upper[i] = upper / scale;
    scaled.values[i] = std::clamp(start.*Member(slot) / scale, scaled.lower[i], scaled.upper[i]);
  }
  return scaled;
}

// Scale of the robust loss: the option, or 1.345 (Huber) or 2.385 (Cauchy)
// times the robust noise estimate.
double RobustLossScale(const ProcessFitOptions& options, const Eigen::VectorXd& y, double y_scale) {
  const double noise = RobustNoise(y);
  return options.loss_scale > 0.0 ? options.loss_scale
                                  : std::max(noise, 1e-12 * y_scale) *
                                        (options.loss == RobustLoss::kHuber ? 1.345 : 2.385);
}

// The residual blocks (one for least squares, one per sample with a robust
// loss) and the bounds of the scaled parameters.
void AddProcessResiduals(ceres::Problem* problem, Simulator* sim, ScaledParameters* scaled,
                         const ProcessFitOptions& options, double loss_scale) {
  double* values = scaled->values.data();
  if (options.loss == RobustLoss::kNone) {
    problem->AddResidualBlock(new RecordResidual(sim), nullptr, values);
  }
  for (Eigen::Index k = 0; options.loss != RobustLoss::kNone && k < sim->num_samples(); ++k) {
    ceres::LossFunction* loss = nullptr;
    if (options.loss == RobustLoss::kHuber) loss = new ceres::HuberLoss(loss_scale);
    if (options.loss == RobustLoss::kCauchy) loss = new ceres::CauchyLoss(loss_scale);
    problem->AddResidualBlock(new SampleResidual(sim, k), loss, values);
  }
  for (int i = 0; i < sim->num_params(); ++i) {
    if (std::isfinite(scaled->lower[i]))
      problem->SetParameterLowerBound(values, i, scaled->lower[i]);
    if (std::isfinite(scaled->upper[i]))
      problem->SetParameterUpperBound(values, i, scaled->upper[i]);
  }
}

ceres::Solver::Summary SolveProcessProblem(ceres::Problem* problem,
                                           const ProcessFitOptions& options) {
  ceres::Solver::Options solver_options;
  solver_options.linear_solver_type = ceres::DENSE_NORMAL_CHOLESKY;  // J^T J: O(N np^2), N >> np
  solver_options.max_num_iterations = options.max_iterations;
  solver_options.function_tolerance = options.function_tolerance;
  solver_options.parameter_tolerance = options.parameter_tolerance;
  solver_options.gradient_tolerance = 1e-14;
  solver_options.num_threads = 1;
  // Trust-region steps are clamped to the bounds by Ceres; its projected line
  // search on top of that evaluates the full Jacobian (2 simulations per lag
  // or delay parameter) at every trial point, doubling the cost on long
  // records for no gain in the fitted values.
  solver_options.max_num_line_search_step_size_iterations = 0;
  solver_options.logging_type = ceres::SILENT;
  ceres::Solver::Summary summary;
  internal::SilenceCeresLogging();
  ceres::Solve(solver_options, problem, &summary);
  return summary;
}

void RecordSolverSummary(const ceres::Solver::Summary& summary, ProcessFitSummary* out) {
  out->iterations = static_cast<int>(summary.iterations.size());
  out->initial_cost = summary.initial_cost;
  out->final_cost = summary.final_cost;
  out->message = summary.message;
  if (summary.termination_type == ceres::CONVERGENCE) {
    out->termination = Termination::kConvergence;
  } else if (summary.termination_type == ceres::NO_CONVERGENCE) {
    out->termination = Termination::kNoConvergence;
  } else {
    out->termination = Termination::kFailure;
  }
}

// (J^T J)^+ of the scaled parameters (the covariance up to sigma^2) into *C;
// false when not available.
bool ScaledCovariance(ceres::Problem* problem, Simulator* sim, double* values, RobustLoss loss,
                      Eigen::MatrixXd* C) {
  const int np = sim->num_params();
  ceres::Covariance::Options cov_options;
  cov_options.algorithm_type = ceres::DENSE_SVD;
  cov_options.null_space_rank = -1;
  cov_options.min_reciprocal_condition_number = 1e-14;
  ceres::Covariance covariance(cov_options);
  std::vector<std::pair<const double*, const double*>> blocks{{values, values}};
  if (loss != RobustLoss::kNone) {
    if (!covariance.Compute(blocks, problem)) return false;
    covariance.GetCovarianceBlock(values, values, C->data());
    return true;
  }
  // The same pseudo-inverse as Ceres' DENSE_SVD covariance (eigenvalues of
  // J^T J below 1e-14 of the largest dropped), from the np x np normal
  // matrix instead of an SVD of the N x np Jacobian.
  if (!sim->Evaluate(values, true)) return false;
  const Eigen::MatrixXd JtJ = sim->jacobian().transpose() * sim->jacobian();
  Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(JtJ);
  const Eigen::VectorXd lambda = eig.eigenvalues();
  const double lmax = lambda.maxCoeff();
  Eigen::VectorXd inv = Eigen::VectorXd::Zero(np);
  for (int i = 0; i < np; ++i)
    if (lmax > 0.0 && lambda[i] / lmax >= cov_options.min_reciprocal_condition_number)
      inv[i] = 1.0 / lambda[i];
  *C = eig.eigenvectors() * inv.asDiagonal() * eig.eigenvectors().transpose();
  return true;
}

// Standard deviations sqrt(sigma^2 C_ii) in physical units into *param_std;
// with all of them finite, the covariance sigma^2 C in physical units and
// its names into *result.
void StoreCovariance(const Eigen::MatrixXd& C, double sigma2, const std::vector<Slot>& slots,
                     const Eigen::VectorXd& scale, ProcessParams* param_std,
                     ProcessFitResult* result) {
  bool ok = true;
  for (std::size_t i = 0; i < slots.size(); ++i) {
    const auto index = static_cast<Eigen::Index>(i);
    const double variance = C(index, index) * sigma2;
    ok = ok && std::isfinite(variance) && variance >= 0.0;
    param_std->*Member(slots[i]) = std::sqrt(std::max(variance, 0.0)) * scale[index];
  }
  result->summary.covariance_ok = ok;
  if (ok) {
    result->covariance = (scale.asDiagonal() * C * scale.asDiagonal()) * sigma2;
    for (Slot slot : slots) result->covariance_names.push_back(SlotName(result->structure, slot));
  }
}

// Lags in decreasing order (with their standard deviations) for P2D and P3D.
void SortLagsDecreasing(const std::vector<Slot>& slots, ProcessParams* param_std,
                        ProcessFitResult* result) {
  const ProcessStructure structure = result->structure;
  if (structure != ProcessStructure::kP2D && structure != ProcessStructure::kP3D) return;
  ProcessParams& params = result->params;
  std::vector<std::pair<double, double>> lags{{params.T1, param_std->T1},
                                              {params.T2, param_std->T2}};
  if (structure == ProcessStructure::kP3D) lags.emplace_back(params.T3, param_std->T3);
  // The covariance follows the lags: the row of the lag that becomes tau_k
  // moves to tau_k's position.
  if (result->covariance.size() > 0) {
    const int np = static_cast<int>(slots.size());
    std::vector<int> order(lags.size());
    for (std::size_t i = 0; i < order.size(); ++i) order[i] = static_cast<int>(i);
    std::stable_sort(order.begin(), order.end(),
                     [&lags](int a, int b) { return lags[a].first > lags[b].first; });
    const std::vector<Slot> lag_slots{kT1, kT2, kT3};
    std::vector<int> pos(lags.size());  // index of each lag slot in the covariance
    for (std::size_t i = 0; i < lags.size(); ++i)
      pos[i] =
          static_cast<int>(std::find(slots.begin(), slots.end(), lag_slots[i]) - slots.begin());
    Eigen::VectorXi perm = Eigen::VectorXi::LinSpaced(np, 0, np - 1);
    for (std::size_t k = 0; k < lags.size(); ++k) perm[pos[k]] = pos[order[k]];
    Eigen::MatrixXd permuted(np, np);
    for (int i = 0; i < np; ++i)
      for (int j = 0; j < np; ++j) permuted(i, j) = result->covariance(perm[i], perm[j]);
    result->covariance = permuted;
  }
  std::sort(lags.begin(), lags.end(), [](auto a, auto b) { return a.first > b.first; });
  params.T1 = lags[0].first;
  param_std->T1 = lags[0].second;
  params.T2 = lags[1].first;
  param_std->T2 = lags[1].second;
  if (lags.size() > 2) {
    params.T3 = lags[2].first;
    param_std->T3 = lags[2].second;
  }
  result->tf = ProcessTransferFunction(structure, result->zero, params);
}

}  // namespace

ProcessFitResult FitProcessModel(const Dataset& data, int input, int output,
                                 const ProcessFitOptions& options, const ProcessParams* initial) {
  ProcessFitRecord record = CheckedProcessFitRecord(data, input, output, options);
  const Eigen::VectorXd& y = record.y;
  const Eigen::Index k0 = record.k0;

  ProcessFitResult result;
  result.structure = options.structure;
  result.zero = options.zero;
  ProcessParams start;
  if (initial) {
    start = *initial;
    result.summary.initial_guess = "the caller";
  } else if (options.zero) {
    std::optional<ProcessFitResult> best = FitZeroFromModelWithoutZero(
        data, input, output, options, &start, &result.summary.initial_guess);
    if (best) return std::move(*best);
  } else {
    ProcessGuess guess = GuessProcess(data, input, output, options.structure, false);
    start = guess.params;
    result.summary.initial_guess = guess.source;
    // A record without a rest at its start: one fit from the best grid point
    // of each input rest (InputRests) besides the guess; the lowest final
    // cost wins, the guess's on a tie (the grid's coarse costs do not tell
    // zero from a mean of 0.02 on a chirp, the fits do). The grid points are
    // the guess's own when it came from the grid.
    const std::vector<double> rests = InputRests(record.u, record.u0, k0);
    if (rests.size() > 1) {
      if (guess.rest_points.size() != rests.size())
        guess.rest_points = GridGuesses(options.structure, record.u, y, record.u0, k0, record.Ts,
                                        record.duration, {});
      ProcessFitResult best = FitProcessModel(data, input, output, options, &start);
      best.summary.initial_guess = result.summary.initial_guess;
      for (std::size_t i = 0; i < rests.size(); ++i) {
        const ProcessParams& q = guess.rest_points[i].first;
        if (q == start) continue;  // the guess itself, fitted above
        ProcessFitResult fit = FitProcessModel(data, input, output, options, &q);
        fit.summary.initial_guess =
            fmt::format("a grid search over lag and delay from a rest at u = {:.6g}", rests[i]);
        if (fit.summary.termination != Termination::kFailure &&
            (best.summary.termination == Termination::kFailure ||
             fit.summary.final_cost < (1.0 - 1e-6) * best.summary.final_cost))
          best = std::move(fit);
      }
      return best;
    }
  }
  // The guess's input rest (the grid search's choice), else the input before
  // its first change.
  if (std::isfinite(start.u0)) record.u0 = start.u0;
  if (!options.estimate_offset) start.y0 = k0 > 0 ? y.head(k0).mean() : y[0];

  const std::vector<Slot> slots = Slots(options.structure, options.zero, options.estimate_offset);
  const int np = static_cast<int>(slots.size());
  if (data.size() <= np) {
    throw DataError(fmt::format("{}: {} samples are too few for {} parameters", record.source,
                                data.size(), np));
  }
  const double y_scale = std::max({y.cwiseAbs().maxCoeff(), std::abs(start.y0), 1e-300});
  ScaledParameters scaled = ScaleAndBound(slots, start, options, record, y_scale);
  double* values = scaled.values.data();
  Simulator sim(options.structure, options.zero, slots, start,
                (record.u.array() - record.u0).matrix(), y, record.Ts, scaled.scale, scaled.lower,
                scaled.upper);

  const double loss_scale = RobustLossScale(options, y, y_scale);
  ceres::Problem::Options problem_options;
  problem_options.cost_function_ownership = ceres::TAKE_OWNERSHIP;
  problem_options.loss_function_ownership = ceres::TAKE_OWNERSHIP;
  ceres::Problem problem(problem_options);
  AddProcessResiduals(&problem, &sim, &scaled, options, loss_scale);
  const ceres::Solver::Summary summary = SolveProcessProblem(&problem, options);

  RecordSolverSummary(summary, &result.summary);
  result.params = sim.ToParams(values);
  result.params.u0 = record.u0;
  result.tf = ProcessTransferFunction(options.structure, options.zero, result.params);
  Eigen::VectorXd residuals;
  if (sim.Residuals(values, &residuals)) {
    result.yhat = y - residuals;
    result.summary.sigma =
        std::sqrt(residuals.squaredNorm() / static_cast<double>(data.size() - np));
  } else {
    result.yhat = Eigen::VectorXd::Constant(data.size(), kNaN);
    result.summary.termination = Termination::kFailure;
  }

  // Standard deviations: sigma^2 (J^T J)^-1 (Ceres Covariance), in physical units.
  ProcessParams param_std;
  for (Slot slot : Slots(options.structure, options.zero, true)) param_std.*Member(slot) = kNaN;
  if (!options.estimate_offset) param_std.y0 = 0.0;
  Eigen::MatrixXd C(np, np);
  if (result.summary.termination != Termination::kFailure &&
      ScaledCovariance(&problem, &sim, values, options.loss, &C)) {
    const double sigma2 = 2.0 * summary.final_cost / static_cast<double>(data.size() - np);
    StoreCovariance(C, sigma2, slots, scaled.scale, &param_std, &result);
  }
  SortLagsDecreasing(slots, &param_std, &result);
  result.param_std = param_std;
  return result;
}

}  // namespace pneumid
