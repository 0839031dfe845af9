#include "pneumid/control/closed_loop.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <random>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "pneumid/common/check.hpp"
#include "pneumid/common/spec.hpp"
#include "pneumid/lti/response.hpp"
#include "pneumid/plant/actuator.hpp"

namespace pneumid {

namespace {
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

bool Changed(double a, double b) { return std::abs(a - b) > 1e-12 * (1.0 + std::abs(a)); }

// A metric that does not exist in the run (NaN) is null.
nlohmann::json Number(double v) { return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(); }

// The step-response keys StepMetrics and ClosedLoopMetrics share.
template <typename M>
void PutStepResponse(const M& m, nlohmann::ordered_json& j) {
  j["rise_time"] = Number(m.rise_time);
  j["overshoot_percent"] = Number(m.overshoot_percent);
  j["settling_time"] = Number(m.settling_time);
  j["steady_state_error"] = Number(m.steady_state_error);
  j["first_move"] = Number(m.first_move);
  j["settling_band"] = Number(m.settling_band);
  j["settled"] = m.settled;
}

// Ripple/noise band of y over [begin, end): the largest peak-to-peak range
// max - min of 4 consecutive samples (see closed_loop.hpp); NaN for fewer than 4.
double RippleHalfBand(const Eigen::VectorXd& y, Eigen::Index begin, Eigen::Index end) {
  if (end - begin < 4) return kNaN;
  double worst = 0.0;
  for (Eigen::Index k = begin; k + 4 <= end; ++k) {
    const auto w = y.segment(k, 4);
    worst = std::max(worst, w.maxCoeff() - w.minCoeff());
  }
  return worst;
}
// Index of the step whose finite size(step) is largest (the first of equal
// ones); -1 when no step has one.
template <typename Size>
int LargestStep(const std::vector<StepMetrics>& steps, Size size) {
  int worst = -1;
  for (std::size_t i = 0; i < steps.size(); ++i) {
    const double v = size(steps[i]);
    if (std::isfinite(v) && (worst < 0 || v > size(steps[worst]))) worst = static_cast<int>(i);
  }
  return worst;
}

// The summary's worst-step metrics (closed_loop.hpp): the largest overshoot,
// the longest settling time or the first step that did not settle, the
// steady-state error of largest magnitude.
void SummarizeWorstStep(ClosedLoopMetrics* m) {
  const std::vector<StepMetrics>& steps = m->steps;
  m->worst_overshoot_step =
      LargestStep(steps, [](const StepMetrics& s) { return s.overshoot_percent; });
  if (m->worst_overshoot_step >= 0)
    m->overshoot_percent = steps[m->worst_overshoot_step].overshoot_percent;
  const int beyond =
      LargestStep(steps, [](const StepMetrics& s) { return s.overshoot_beyond_ripple_percent; });
  if (beyond >= 0)
    m->overshoot_beyond_ripple_percent = steps[beyond].overshoot_beyond_ripple_percent;
  m->worst_steady_state_error_step =
      LargestStep(steps, [](const StepMetrics& s) { return std::abs(s.steady_state_error); });
  if (m->worst_steady_state_error_step >= 0)
    m->worst_steady_state_error = steps[m->worst_steady_state_error_step].steady_state_error;
  m->settled = true;
  for (std::size_t i = 0; i < steps.size() && m->settled; ++i) {
    if (!steps[i].settled) {
      m->settled = false;
      m->worst_settling_step = static_cast<int>(i);
    } else if (m->worst_settling_step < 0 ||
               steps[i].settling_time > steps[m->worst_settling_step].settling_time) {
      m->worst_settling_step = static_cast<int>(i);
    }
  }
  const StepMetrics& worst = steps[m->worst_settling_step];
  m->settling_time = m->settled ? worst.settling_time : kNaN;
  m->settling_band = worst.settling_band;
}

}  // namespace

nlohmann::ordered_json StepMetrics::ToJson() const {
  nlohmann::ordered_json j;
  j["time"] = time;
  j["from"] = from;
  j["to"] = to;
  PutStepResponse(*this, j);
  j["ripple"] = Number(ripple);
  j["steady_input"] = Number(steady_input);
  j["overshoot_beyond_ripple_percent"] = Number(overshoot_beyond_ripple_percent);
  return j;
}

nlohmann::ordered_json ClosedLoopMetrics::ToJson() const {
  nlohmann::ordered_json j;
  PutStepResponse(*this, j);
  j["worst_overshoot_step"] = worst_overshoot_step >= 0
                                  ? nlohmann::ordered_json(worst_overshoot_step)
                                  : nlohmann::ordered_json();
  j["overshoot_beyond_ripple_percent"] = Number(overshoot_beyond_ripple_percent);
  j["worst_settling_step"] = worst_settling_step >= 0 ? nlohmann::ordered_json(worst_settling_step)
                                                      : nlohmann::ordered_json();
  j["worst_steady_state_error"] = Number(worst_steady_state_error);
  j["worst_steady_state_error_step"] = worst_steady_state_error_step >= 0
                                           ? nlohmann::ordered_json(worst_steady_state_error_step)
                                           : nlohmann::ordered_json();
  j["iae"] = Number(iae);
  j["ise"] = Number(ise);
  j["itae"] = Number(itae);
  j["tv_u"] = Number(tv_u);
  j["u_min"] = Number(u_min);
  j["u_max"] = Number(u_max);
  j["load_peak_deviation"] = Number(load_peak_deviation);
  j["load_recovery_time"] = Number(load_recovery_time);
  j["steps"] = nlohmann::ordered_json::array();
  for (const StepMetrics& s : steps) j["steps"].push_back(s.ToJson());
  return j;
}

double LoadAt(const std::vector<LoadStep>& steps, double t, double Ts) {
  double d = 0.0;
  for (const LoadStep& l : steps)
    if (t >= l.at - 1e-9 * Ts) d += l.size;
  return d;
}

LoadStep ParseLoadStep(const std::string& what, const std::string& spec) {
  Spec fields(what, spec, {.has_kind = false});
  LoadStep l;
  l.at = fields.Number("at");
  l.size = fields.Number("size");
  fields.Finish();
  PNEUMID_CHECK(std::isfinite(l.at) && l.at >= 0.0 && std::isfinite(l.size),
                "{} '{}': need a finite time at >= 0 and a finite size", what, spec);
  return l;
}

bool ClosedLoopOptions::IsValid(std::string* error) const {
  auto fail = [&](const std::string& message) {
    if (error) *error = message;
    return false;
  };
  if (!(duration > 0.0) || !std::isfinite(duration))
    return fail(fmt::format("duration must be positive, got {}", duration));
  for (const LoadStep& l : load_steps) {
    if (!std::isfinite(l.at) || l.at < 0.0 || !std::isfinite(l.size))
      return fail(
          fmt::format("load step at={} size={}: need a finite time >= 0 and size", l.at, l.size));
  }
  if (!(noise_std >= 0.0) || !std::isfinite(noise_std))
    return fail(fmt::format("noise_std must be >= 0, got {}", noise_std));
  if (!std::isfinite(u0)) return fail(fmt::format("u0 must be finite, got {}", u0));
  if (!(settling_threshold > 0.0 && settling_threshold < 1.0))
    return fail(fmt::format("settling_threshold must be in (0, 1), got {}", settling_threshold));
  std::string e;
  if (!actuator.IsValid(&e)) return fail("actuator: " + e);
  return true;
}

Eigen::Index ClosedLoopOptions::Samples(double Ts) const {
  const double n = duration / Ts;
  PNEUMID_CHECK(n < 9e18, "duration {} s at Ts = {} s is {:.3g} samples, more than a count holds",
                duration, Ts, n);
  return std::max<Eigen::Index>(2, std::llround(n));
}

ClosedLoopMetrics ComputeClosedLoopMetrics(const Eigen::VectorXd& t, const Eigen::VectorXd& r,
                                           const Eigen::VectorXd& y, const Eigen::VectorXd& u,
                                           double r_before, double u_before,
                                           const ClosedLoopOptions& options) {
  const Eigen::Index n = t.size();
  PNEUMID_CHECK(n >= 2 && r.size() == n && y.size() == n && u.size() == n,
                "need t, r, y, u of equal length >= 2, got {}, {}, {}, {}", n, r.size(), y.size(),
                u.size());
  const double Ts = t(1) - t(0);
  PNEUMID_CHECK(Ts > 0.0, "time must increase, got t(0) = {}, t(1) = {}", t(0), t(1));
  ClosedLoopMetrics m;
  // Integral criteria and input statistics.
  double u_prev = u_before;
  m.u_min = u.minCoeff();
  m.u_max = u.maxCoeff();
  for (Eigen::Index k = 0; k < n; ++k) {
    const double e = r(k) - y(k);
    m.iae += std::abs(e) * Ts;
    m.ise += e * e * Ts;
    m.itae += (t(k) - t(0)) * std::abs(e) * Ts;
    m.tv_u += std::abs(u(k) - u_prev);
    u_prev = u(k);
  }
  // Set-point segments.
  std::vector<Eigen::Index> changes;
  double r_prev = r_before;
  for (Eigen::Index k = 0; k < n; ++k) {
    if (Changed(r(k), r_prev)) changes.push_back(k);
    r_prev = r(k);
  }
  auto segment_error = [&](Eigen::Index begin, Eigen::Index end) {
    const Eigen::Index len = end - begin;
    const Eigen::Index w = std::clamp<Eigen::Index>(len / 20, 1, 50);
    double acc = 0.0;
    for (Eigen::Index k = end - w; k < end; ++k) acc += r(k) - y(k);
    return acc / static_cast<double>(w);
  };
  for (std::size_t c = 0; c < changes.size(); ++c) {
    const Eigen::Index k0 = changes[c];
    Eigen::Index k1 = c + 1 < changes.size() ? changes[c + 1] : n;
    // The step's window ends at a load step inside it: what follows is the
    // disturbance response (load_peak_deviation, load_recovery_time), not
    // the set-point response.
    for (const LoadStep& l : options.load_steps) {
      Eigen::Index k = k0 + 1;
      while (k < k1 && t(k) - t(0) < l.at - 1e-9 * Ts) ++k;
      if (k > k0 + 1 && k < k1) k1 = k;
    }
    StepMetrics s;
    s.time = t(k0);
    s.from = k0 > 0 ? r(k0 - 1) : r_before;
    s.to = r(k0);
    s.first_move = u(k0) - (k0 > 0 ? u(k0 - 1) : u_before);
    s.steady_state_error = segment_error(k0, k1);
    const double step = std::abs(s.to - s.from);
    const Eigen::Index tail = std::max<Eigen::Index>((k1 - k0) / 4, 8);
    if (k1 - k0 >= 2 * tail) {
      s.ripple = RippleHalfBand(y, k1 - tail, k1);
      s.steady_input = u.segment(k1 - tail, tail).mean();
    }
    s.settling_band =
        std::max(options.settling_threshold * step, std::isfinite(s.ripple) ? s.ripple : 0.0);
    if (options.settling_band_floor) {
      const double floor = options.settling_band_floor(s.to);
      if (std::isfinite(floor)) s.settling_band = std::max(s.settling_band, floor);
    }
    if (k1 - k0 >= 3) {
      StepInfoOptions o;
      // The band as a fraction of the step (a ripple wider than the step
      // leaves no meaningful settling: the fraction is capped below 1).
      o.settling_threshold = std::min(s.settling_band / step, 0.99);
      o.y_initial = s.from;
      o.y_final = s.to;
      const Eigen::VectorXd ts = t.segment(k0, k1 - k0).array() - t(k0);
      const Eigen::VectorXd ys = y.segment(k0, k1 - k0);
      const StepInfo info = ComputeStepInfo(ts, ys, o);
      s.rise_time = info.rise_time;
      s.overshoot_percent = info.overshoot;
      s.settling_time = info.settling_time;
      // A response still outside the band at the end of the window, or one that
      // entered it only in the last 10 % of the window (at least 5 samples),
      // has not been seen to settle.
      const Eigen::Index hold = std::max<Eigen::Index>(5, (k1 - k0) / 10);
      if (std::abs(ys(ys.size() - 1) - s.to) > o.settling_threshold * step ||
          !(s.settling_time <= ts(std::max<Eigen::Index>(0, ys.size() - 1 - hold))))
        s.settling_time = kNaN;
      s.settled = std::isfinite(s.settling_time);
      s.overshoot_beyond_ripple_percent = s.overshoot_percent;
      if (std::isfinite(s.overshoot_percent) && std::isfinite(s.ripple) && step > 0.0)
        s.overshoot_beyond_ripple_percent =
            std::max(0.0, s.overshoot_percent - 100.0 * 0.5 * s.ripple / step);
    }
    m.steps.push_back(s);
  }
  if (!m.steps.empty()) {
    m.rise_time = m.steps[0].rise_time;
    m.first_move = m.steps[0].first_move;
    SummarizeWorstStep(&m);
  }
  const Eigen::Index last_begin = changes.empty() ? 0 : changes.back();
  m.steady_state_error = segment_error(last_begin, n);
  // First load step.
  if (!options.load_steps.empty()) {
    const LoadStep* first = &options.load_steps[0];
    for (const LoadStep& l : options.load_steps)
      if (l.at < first->at) first = &l;
    Eigen::Index k0 = 0;
    while (k0 < n && t(k0) - t(0) < first->at - 1e-9 * Ts) ++k0;
    if (k0 < n) {
      Eigen::Index k1 = n;
      for (Eigen::Index c : changes)
        if (c > k0) {
          k1 = c;
          break;
        }
      for (const LoadStep& l : options.load_steps) {
        if (l.at > first->at) {
          Eigen::Index k = k0;
          while (k < k1 && t(k) - t(0) < l.at - 1e-9 * Ts) ++k;
          k1 = std::min(k1, k);
        }
      }
      const double band =
          std::max(options.settling_threshold * std::abs(first->size), 3.0 * options.noise_std);
      double peak = 0.0;
      Eigen::Index last_out = -1;
      for (Eigen::Index k = k0; k < k1; ++k) {
        const double dev = y(k) - r(k);
        if (std::abs(dev) > std::abs(peak)) peak = dev;
        if (std::abs(dev) > band) last_out = k;
      }
      m.load_peak_deviation = peak;
      if (last_out < 0) {
        m.load_recovery_time = 0.0;
      } else if (last_out + 1 < k1) {
        m.load_recovery_time = t(last_out + 1) - t(k0);
      }
    }
  }
  return m;
}

ClosedLoopResult SimulateClosedLoop(Controller& controller, Plant& plant, const Signal& setpoint,
                                    const ClosedLoopOptions& options) {
  std::string error;
  PNEUMID_CHECK(options.IsValid(&error), "invalid closed-loop options: {}", error);
  const double Ts = controller.Ts();
  PNEUMID_CHECK(std::abs(plant.Ts() - Ts) <= 1e-9 * Ts,
                "the plant samples at Ts = {} s but the controller at Ts = {} s", plant.Ts(), Ts);
  setpoint.CheckSampleTime(Ts);
  const Eigen::Index n = options.Samples(Ts);
  ClosedLoopResult res;
  res.t = Eigen::VectorXd::LinSpaced(n, 0.0, static_cast<double>(n - 1) * Ts);
  res.r.resize(n);
  res.y.resize(n);
  res.y_meas.resize(n);
  res.u.resize(n);
  res.u_requested.resize(n);
  res.d.resize(n);
  if (options.time_updates) res.update_seconds.resize(n);
  for (Eigen::Index k = 0; k < n; ++k) res.r(k) = setpoint(res.t(k));
  const double r_before = setpoint(-Ts);

  // The actuator: the options' limits, within the plant's physical input range.
  InputLimits actuator = options.actuator;
  if (options.plant_range) {
    const Actuator a = PlantActuator(plant);
    actuator.u_min = std::max(actuator.u_min, a.u_min);
    actuator.u_max = std::min(actuator.u_max, a.u_max);
    PNEUMID_CHECK(actuator.u_min <= actuator.u_max,
                  "the actuator limits {} .. {} do not overlap the plant's input range {} .. {}",
                  options.actuator.u_min, options.actuator.u_max, a.u_min, a.u_max);
    CheckSetpointsInOutputRange(a, res.r.data(), static_cast<std::size_t>(n), Ts);
  }
  plant.Reset();
  plant.SetLoadDisturbance(0.0);
  std::mt19937_64 rng(options.seed);
  std::normal_distribution<double> noise(0.0, 1.0);
  double u_prev = options.u0;
  for (Eigen::Index k = 0; k < n; ++k) {
    if (options.stop != nullptr && options.stop->load(std::memory_order_relaxed))
      throw Cancelled(
          fmt::format("the closed-loop simulation was stopped on request at t = {} s", res.t(k)));
    const double d = LoadAt(options.load_steps, res.t(k), Ts);
    if (k == 0 || d != res.d(k - 1)) plant.SetLoadDisturbance(d);
    res.d(k) = d;
    const double y = plant.Measure();
    const double ym = options.noise_std > 0.0 ? y + options.noise_std * noise(rng) : y;
    if (k == 0) controller.Reset(options.u0, ym);
    double u;
    if (options.time_updates) {
      const auto start = std::chrono::steady_clock::now();
      u = controller.Update(res.r(k), ym);
      const auto stop = std::chrono::steady_clock::now();
      res.update_seconds(k) = std::chrono::duration<double>(stop - start).count();
    } else {
      u = controller.Update(res.r(k), ym);
    }
    res.u_requested(k) = u;
    u = std::clamp(u, actuator.u_min, actuator.u_max);
    if (std::isfinite(actuator.du_max))
      u = std::clamp(u, u_prev - actuator.du_max, u_prev + actuator.du_max);
    if (u != res.u_requested(k)) controller.Applied(u);
    plant.Advance(u);
    res.y(k) = y;
    res.y_meas(k) = ym;
    res.u(k) = u;
    u_prev = u;
  }
  // A loop the controller destabilises overflows: say so, not "stepinfo: y
  // contains NaN or Inf".
  for (Eigen::Index k = 0; k < n; ++k) {
    PNEUMID_CHECK(std::isfinite(res.y(k)),
                  "the closed loop diverged: the plant's output is no longer finite from t = {:g} "
                  "s (last finite {:.4g} at t = {:g} s); the controller '{}' destabilises the "
                  "plant '{}': tune it more softly or check the model",
                  res.t(k), k > 0 ? res.y(k - 1) : 0.0, k > 0 ? res.t(k - 1) : 0.0,
                  controller.Describe(), plant.Describe());
  }
  res.metrics = ComputeClosedLoopMetrics(res.t, res.r, res.y, res.u, r_before, options.u0, options);
  res.controller = controller.Describe();
  res.plant = plant.Describe();
  return res;
}

}  // namespace pneumid
