#include "pneumid/identify/step/step_analysis.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include <fmt/format.h>

#include "pneumid/common/check.hpp"
#include "pneumid/lti/response.hpp"

namespace pneumid {
namespace {

std::string SourceName(const Dataset& data) {
  return data.source().empty() ? std::string("data") : data.source();
}

double Mean(const Eigen::VectorXd& x, Eigen::Index begin, Eigen::Index end) {
  return x.segment(begin, end - begin).mean();
}

double StdDev(const Eigen::VectorXd& x, Eigen::Index begin, Eigen::Index end) {
  const Eigen::Index n = end - begin;
  if (n < 2) return 0.0;
  const double m = Mean(x, begin, end);
  return std::sqrt((x.segment(begin, n).array() - m).square().sum() / static_cast<double>(n - 1));
}

// Least-squares line x = a + c t over [begin, end); returns {a, c, residual std}.
struct Line {
  double a = 0.0, c = 0.0, residual_std = 0.0;
};
Line FitLine(const Eigen::VectorXd& t, const Eigen::VectorXd& x, Eigen::Index begin,
             Eigen::Index end) {
  const Eigen::Index n = end - begin;
  Line line;
  const double tm = t.segment(begin, n).mean();
  const double xm = x.segment(begin, n).mean();
  const Eigen::ArrayXd dt = t.segment(begin, n).array() - tm;
  const Eigen::ArrayXd dx = x.segment(begin, n).array() - xm;
  const double stt = dt.square().sum();
  line.c = stt > 0.0 ? (dt * dx).sum() / stt : 0.0;
  line.a = xm - line.c * tm;
  if (n > 2) {
    line.residual_std = std::sqrt((dx - line.c * dt).square().sum() / static_cast<double>(n - 2));
  }
  return line;
}

}  // namespace

bool StepAnalysisOptions::IsValid(std::string* error) const {
  auto fail = [&](const std::string& m) {
    if (error) *error = m;
    return false;
  };
  if (!(tail_fraction > 0.0 && tail_fraction < 0.5))
    return fail(fmt::format("tail_fraction must be in (0, 0.5), got {}", tail_fraction));
  if (min_tail_samples < 3)
    return fail(fmt::format("min_tail_samples must be >= 3, got {}", min_tail_samples));
  if (!(settle_tolerance > 0.0))
    return fail(fmt::format("settle_tolerance must be positive, got {}", settle_tolerance));
  if (!(min_snr >= 0.0)) return fail(fmt::format("min_snr must be >= 0, got {}", min_snr));
  if (!(input_tolerance > 0.0 && input_tolerance < 0.5))
    return fail(fmt::format("input_tolerance must be in (0, 0.5), got {}", input_tolerance));
  if (!(band_sigmas >= 0.0))
    return fail(fmt::format("band_sigmas must be >= 0, got {}", band_sigmas));
  if (!(band_min_fraction > 0.0 && band_min_fraction < 0.5))
    return fail(fmt::format("band_min_fraction must be in (0, 0.5), got {}", band_min_fraction));
  if (band_hold_samples < 1)
    return fail(fmt::format("band_hold_samples must be >= 1, got {}", band_hold_samples));
  if (!(departure_fit_upper > band_min_fraction && departure_fit_upper < 1.0))
    return fail(fmt::format("departure_fit_upper must be in (band_min_fraction, 1), got {}",
                            departure_fit_upper));
  return true;
}

double StepAnalysis::CrossingTime(double level) const {
  PNEUMID_CHECK(level > 0.0 && level < 1.5, "crossing level must be in (0, 1.5), got {}", level);
  const double first = FirstCrossing(t, r, level, step_index);
  if (std::isnan(first)) {
    throw DataError(
        fmt::format("the normalized step response never reaches {:.1f} % (largest value {:.1f} %)",
                    100.0 * level, 100.0 * r.maxCoeff()));
  }
  // Last upward crossing before the response is clearly (one band) above the level.
  Eigen::Index k_hi = r.size() - 1;
  for (Eigen::Index k = step_index; k < r.size(); ++k) {
    if (r[k] >= level + band) {
      k_hi = k;
      break;
    }
  }
  double last = first;
  for (Eigen::Index k = step_index + 1; k <= k_hi; ++k) {
    if (r[k - 1] < level && r[k] >= level) {
      last = FirstCrossing(t, r, level, k - 1);
    }
  }
  return 0.5 * (first + last);
}

std::string StepAnalysis::BriefReport() const {
  return fmt::format(
      "step at t = {:g} s: u {:g} -> {:g}, y {:.6g} -> {:.6g} (+- {:.2g}), gain {:.6g}, "
      "noise std {:.3g}, departure {:.4g} s after the step",
      step_time, u0, u1, y0, y_final, y_final_std, gain, noise_std, departure_time);
}

StepAnalysis AnalyzeStep(const Dataset& data, int input, int output,
                         const StepAnalysisOptions& options) {
  std::string why;
  PNEUMID_CHECK(options.IsValid(&why), "invalid StepAnalysisOptions: {}", why);
  PNEUMID_CHECK(input >= 0 && input < data.num_inputs(),
                "input column {} out of range (the data has {} inputs)", input, data.num_inputs());
  PNEUMID_CHECK(output >= 0 && output < data.num_outputs(),
                "output column {} out of range (the data has {} outputs)", output,
                data.num_outputs());
  data.RequireNumericScale();
  const std::string src = SourceName(data);
  const Eigen::Index n = data.size();
  if (n < 2 * options.min_tail_samples + 2) {
    throw DataError(
        fmt::format("{}: {} samples are too few for a step-response analysis "
                    "(need at least {})",
                    src, n, 2 * options.min_tail_samples + 2));
  }
  const Eigen::VectorXd& time = data.time();
  const Eigen::VectorXd u = data.u(input);
  const Eigen::VectorXd y = data.y(output);
  for (Eigen::Index k = 0; k < n; ++k) {
    if (!std::isfinite(u[k]) || !std::isfinite(y[k]) || !std::isfinite(time[k])) {
      throw DataError(fmt::format("{}: sample {} is not a number (t = {}, u = {}, y = {})", src, k,
                                  time[k], u[k], y[k]));
    }
  }
  data.RequireUniform();

  StepAnalysis s;
  s.Ts = data.SampleTime();

  // 1. The step in the input.
  const double dev_max = (u.array() - u[0]).abs().maxCoeff();
  const double scale = std::max(1.0, u.cwiseAbs().maxCoeff());
  if (!(dev_max > 1e-12 * scale)) {
    throw DataError(
        fmt::format("{}: no step in the input: it stays at {} over all {} samples", src, u[0], n));
  }
  Eigen::Index ks = 0;
  while (std::abs(u[ks] - u[0]) <= 0.5 * dev_max) ++ks;
  s.step_index = ks;
  s.step_time = time[ks];
  s.u0 = Mean(u, 0, ks);
  s.u1 = Mean(u, ks, n);
  s.du = s.u1 - s.u0;
  const double utol = options.input_tolerance * std::abs(s.du);
  for (Eigen::Index k = 0; k < n; ++k) {
    const double ref = k < ks ? s.u0 : s.u1;
    if (std::abs(u[k] - ref) > utol) {
      throw DataError(fmt::format(
          "{}: the input is not a single step: sample {} (t = {}) has u = {}, but the step goes "
          "from {} to {} at t = {}; use a fit-* method for general inputs",
          src, k, time[k], u[k], s.u0, s.u1, s.step_time));
    }
  }

  // 2. Baseline, tail, noise.
  s.y0 = Mean(y, 0, ks);
  const Eigen::Index n_after = n - ks;
  const Eigen::Index n_tail = std::max<Eigen::Index>(
      options.min_tail_samples,
      static_cast<Eigen::Index>(std::lround(options.tail_fraction * static_cast<double>(n))));
  if (2 * n_tail > n_after) {
    throw DataError(
        fmt::format("{}: only {} samples after the step at t = {} s; the response "
                    "cannot have settled (need at least {})",
                    src, n_after, s.step_time, 2 * n_tail));
  }
  const Eigen::Index tail_begin = n - n_tail;
  const Line tail = FitLine(time, y, tail_begin, n);
  s.y_final = Mean(y, tail_begin, n);
  s.noise_std = ks >= 5 ? StdDev(y, 0, ks) : tail.residual_std;
  s.y_final_std = tail.residual_std / std::sqrt(static_cast<double>(n_tail));
  s.dy = s.y_final - s.y0;
  if (!(std::abs(s.dy) > options.min_snr * s.noise_std) || s.dy == 0.0) {
    throw DataError(
        fmt::format("{}: the step response is too small against the noise: output change {:.4g} "
                    "(from {:.6g} to {:.6g}) vs noise std {:.3g} (need a ratio of at least {})",
                    src, s.dy, s.y0, s.y_final, s.noise_std, options.min_snr));
  }
  const double drift = tail.c * (time[n - 1] - time[tail_begin]);
  const double sigma_for_drift = std::max(s.noise_std, tail.residual_std);
  const double drift_limit =
      std::max(options.settle_tolerance * std::abs(s.dy),
               3.0 * sigma_for_drift * std::sqrt(12.0 / static_cast<double>(n_tail)));
  if (std::abs(drift) > drift_limit) {
    throw DataError(fmt::format(
        "{}: the response has not settled: the output still changes by {:.4g} ({:.1f} % of the "
        "step) over the last {:.4g} s; record longer or use a fit-* method",
        src, drift, 100.0 * drift / s.dy, time[n - 1] - time[tail_begin]));
  }
  s.gain = s.dy / s.du;

  // 3. Normalized response after the step.
  s.t = time.array() - s.step_time;
  s.r = (y.array() - s.y0) / s.dy;
  s.band = std::max(options.band_sigmas * s.noise_std / std::abs(s.dy), options.band_min_fraction);

  // 4. Departure from the baseline.
  Eigen::Index kb = -1;
  for (Eigen::Index k = ks; k + options.band_hold_samples <= n; ++k) {
    bool out = true;
    for (int j = 0; j < options.band_hold_samples; ++j) out = out && s.r[k + j] > s.band;
    if (out) {
      kb = k;
      break;
    }
  }
  if (kb < 0) {
    throw DataError(
        fmt::format("{}: the response never leaves the noise band ({:.2g} % of the "
                    "step) for {} samples",
                    src, 100.0 * s.band, options.band_hold_samples));
  }
  const double t_band = kb == 0 ? 0.0
                                : s.t[kb - 1] + (s.band - s.r[kb - 1]) / (s.r[kb] - s.r[kb - 1]) *
                                                    (s.t[kb] - s.t[kb - 1]);
  const double upper = std::max(options.departure_fit_upper, s.band + 0.1);
  Eigen::Index ke = kb;
  while (ke < n && s.r[ke] <= upper) ++ke;
  Eigen::Index kf = kb;
  if (ke - kf < 2) kf = std::max<Eigen::Index>(ks, ke - 2);
  if (ke - kf < 2) ke = std::min<Eigen::Index>(n, kf + 2);
  const Line rise = FitLine(s.t, s.r, kf, ke);
  double departure = t_band;
  if (rise.c > 0.0) departure = std::clamp(-rise.a / rise.c, 0.0, t_band);
  s.departure_time = departure;
  return s;
}

}  // namespace pneumid
