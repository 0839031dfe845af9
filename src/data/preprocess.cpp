#include "pneumid/data/preprocess.hpp"

#include <algorithm>
#include <cmath>
#include <complex>
#include <vector>

#include <fmt/format.h>

#include "pneumid/common/check.hpp"
#include "pneumid/common/enum_names.hpp"

namespace pneumid {
namespace {

std::string Source(const Dataset& d) { return d.source().empty() ? "dataset" : d.source(); }

/// A dataset with new values and the metadata (channels, source, time channel)
/// of `like`; `first` is the row of `like` that becomes sample 0 when the rows
/// keep their file lines (negative: the lines are lost).
Dataset Rebuild(const Dataset& like, Eigen::VectorXd time, Eigen::MatrixXd inputs,
                Eigen::MatrixXd outputs, Eigen::Index first) {
  Dataset out(std::move(time), std::move(inputs), std::move(outputs), like.input_channels(),
              like.output_channels());
  out.set_time_channel(like.time_channel());
  out.set_source(like.source());
  if (first >= 0 && out.size() > 0 && like.SourceLine(first) > 0) {
    std::vector<Eigen::Index> samples;
    std::vector<long> lines;
    for (Eigen::Index i = 0; i < out.size(); ++i) {
      const long line = like.SourceLine(first + i);
      if (i == 0 || line != like.SourceLine(first + i - 1) + 1) {
        samples.push_back(i);
        lines.push_back(line);
      }
    }
    out.set_source_lines(std::move(samples), std::move(lines));
  }
  return out;
}

bool DoInputs(ChannelSet s) { return s != ChannelSet::kOutputs; }
bool DoOutputs(ChannelSet s) { return s != ChannelSet::kInputs; }

Dataset SubtractOffsets(const Dataset& data, const Eigen::RowVectorXd& u0,
                        const Eigen::RowVectorXd& y0, OperatingPoint* removed) {
  Eigen::MatrixXd u = data.inputs().rowwise() - u0;
  Eigen::MatrixXd y = data.outputs().rowwise() - y0;
  if (removed != nullptr) {
    removed->u0 = u0.transpose();
    removed->y0 = y0.transpose();
  }
  return Rebuild(data, data.time(), std::move(u), std::move(y), 0);
}

Dataset OffsetFromFirst(const Dataset& data, Eigen::Index n, ChannelSet which,
                        OperatingPoint* removed) {
  Eigen::RowVectorXd u0 = Eigen::RowVectorXd::Zero(data.num_inputs());
  Eigen::RowVectorXd y0 = Eigen::RowVectorXd::Zero(data.num_outputs());
  if (DoInputs(which) && data.num_inputs() > 0) u0 = data.inputs().topRows(n).colwise().mean();
  if (DoOutputs(which) && data.num_outputs() > 0) {
    y0 = data.outputs().topRows(n).colwise().mean();
  }
  return SubtractOffsets(data, u0, y0, removed);
}

}  // namespace

namespace {
constexpr EnumName<ChannelSet> kChannelSetNames[] = {
    {ChannelSet::kInputs, "inputs"},
    {ChannelSet::kOutputs, "outputs"},
    {ChannelSet::kBoth, "both"},
};
}  // namespace

std::string ToString(ChannelSet v) { return std::string(EnumToString(kChannelSetNames, v)); }

ChannelSet ChannelSetFromString(const std::string& name) {
  return EnumFromString(kChannelSetNames, name, "channel set");
}

Dataset RemoveMeans(const Dataset& data, ChannelSet which, OperatingPoint* removed) {
  data.RequireSamples(1, "RemoveMeans");
  return OffsetFromFirst(data, data.size(), which, removed);
}

Dataset RemoveInitialOffset(const Dataset& data, Eigen::Index n, ChannelSet which,
                            OperatingPoint* removed) {
  PNEUMID_CHECK(n >= 1, "RemoveInitialOffset: the number of samples must be >= 1, got {}", n);
  data.RequireSamples(n, fmt::format("RemoveInitialOffset over {} samples", n));
  return OffsetFromFirst(data, n, which, removed);
}

Dataset RemoveInitialOffset(const Dataset& data, const StepEvent& step, ChannelSet which,
                            OperatingPoint* removed) {
  PNEUMID_CHECK(step.index >= 0 && step.index < data.size(),
                "RemoveInitialOffset: step index {} out of range [0, {})", step.index, data.size());
  if (step.index == 0) {
    throw DataError(fmt::format(
        "{}: the step is at the first sample; no samples before it give an initial offset",
        Source(data)));
  }
  return OffsetFromFirst(data, step.index, which, removed);
}

Dataset Detrend(const Dataset& data, ChannelSet which) {
  data.RequireSamples(2, "Detrend");
  // Least squares fit of a + b (t - tm) on centred time: the two regressors are
  // orthogonal, so a = mean(x), b = sum((t - tm) x) / sum((t - tm)^2).
  const Eigen::VectorXd tc = data.time().array() - data.time().mean();
  const double stt = tc.squaredNorm();
  auto detrend = [&](const Eigen::MatrixXd& m) {
    Eigen::MatrixXd out = m;
    for (Eigen::Index c = 0; c < m.cols(); ++c) {
      const double a = m.col(c).mean();
      const double b = tc.dot(m.col(c)) / stt;
      out.col(c) = m.col(c).array() - a - b * tc.array();
    }
    return out;
  };
  Eigen::MatrixXd u = DoInputs(which) ? detrend(data.inputs()) : data.inputs();
  Eigen::MatrixXd y = DoOutputs(which) ? detrend(data.outputs()) : data.outputs();
  return Rebuild(data, data.time(), std::move(u), std::move(y), 0);
}

bool StepDetectOptions::IsValid(std::string* error) const {
  auto fail = [&](std::string m) {
    if (error != nullptr) *error = std::move(m);
    return false;
  };
  if (input < 0) return fail(fmt::format("StepDetectOptions: input must be >= 0, got {}", input));
  if (window < 0) {
    return fail(fmt::format("StepDetectOptions: window must be >= 0, got {}", window));
  }
  if (!(min_significance >= 0) || !std::isfinite(min_significance)) {
    return fail(
        fmt::format("StepDetectOptions: min_significance must be >= 0, got {}", min_significance));
  }
  if (!(min_size >= 0) || !std::isfinite(min_size)) {
    return fail(fmt::format("StepDetectOptions: min_size must be >= 0, got {}", min_size));
  }
  return true;
}

StepEvent DetectStep(const Dataset& data, const StepDetectOptions& options) {
  std::string error;
  PNEUMID_CHECK(options.IsValid(&error), "DetectStep: {}", error);
  PNEUMID_CHECK(options.input < data.num_inputs(),
                "DetectStep: input {} out of range, the data has {} inputs", options.input,
                data.num_inputs());
  data.RequireSamples(2, "step detection");
  const Eigen::Index n = data.size();
  const Eigen::Index w =
      options.window > 0 ? options.window : std::clamp<Eigen::Index>(n / 20, 1, 25);
  const Eigen::VectorXd u = data.inputs().col(options.input);
  const double mean = u.mean();
  // Prefix sums of the centred input.
  std::vector<double> s1(static_cast<std::size_t>(n + 1), 0.0);
  for (Eigen::Index i = 0; i < n; ++i) {
    s1[static_cast<std::size_t>(i + 1)] = s1[static_cast<std::size_t>(i)] + (u[i] - mean);
  }
  auto sum = [](const std::vector<double>& s, Eigen::Index a, Eigen::Index b) {
    return s[static_cast<std::size_t>(b)] - s[static_cast<std::size_t>(a)];
  };
  Eigen::Index best = -1;
  double best_jump = 0.0;
  for (Eigen::Index k = 1; k < n; ++k) {
    const Eigen::Index b0 = std::max<Eigen::Index>(0, k - w);
    const Eigen::Index a1 = std::min<Eigen::Index>(n, k + w);
    const double jump =
        sum(s1, k, a1) / static_cast<double>(a1 - k) - sum(s1, b0, k) / static_cast<double>(k - b0);
    if (std::abs(jump) > std::abs(best_jump)) {
      best_jump = jump;
      best = k;
    }
  }
  const std::string channel = data.input_channels()[static_cast<std::size_t>(options.input)].name;
  if (best < 0 || best_jump == 0.0) {
    throw DataError(
        fmt::format("{}: input '{}' is constant: no step found", Source(data), channel));
  }
  const Eigen::Index k = best;
  const Eigen::Index b0 = std::max<Eigen::Index>(0, k - w);
  const Eigen::Index a1 = std::min<Eigen::Index>(n, k + w);
  // Spread of the input inside the two windows, each around its own mean
  // (two-pass, so that a clean step has exactly zero spread).
  auto squares = [&](Eigen::Index a, Eigen::Index b) {
    const auto seg = u.segment(a, b - a);
    return (seg.array() - seg.mean()).square().sum();
  };
  const double spread = std::sqrt((squares(b0, k) + squares(k, a1)) / static_cast<double>(a1 - b0));
  const double scale = std::max(u.cwiseAbs().maxCoeff(), std::abs(best_jump));
  const double significance = spread <= 1e-14 * scale ? std::numeric_limits<double>::infinity()
                                                      : std::abs(best_jump) / spread;
  if (significance < options.min_significance || std::abs(best_jump) < options.min_size) {
    throw DataError(fmt::format(
        "{}: no step found in input '{}': the largest jump, {:g} at t = {:g} s ({}), is {:.3g} "
        "times the spread of the input around it (a step needs >= {:g}{}); the input looks "
        "like noise, a ramp or a slow change",
        Source(data), channel, best_jump, data.time()[k], data.Where(k), significance,
        options.min_significance,
        options.min_size > 0 ? fmt::format(" and a size >= {:g}", options.min_size) : ""));
  }
  StepEvent e;
  e.input = options.input;
  e.index = k;
  e.time = data.time()[k];
  e.baseline_before = u.head(k).mean();
  e.level_after = u.segment(k, a1 - k).mean();
  e.size = e.level_after - e.baseline_before;
  e.outputs_before = data.num_outputs() > 0
                         ? Eigen::VectorXd(data.outputs().topRows(k).colwise().mean().transpose())
                         : Eigen::VectorXd();
  e.significance = significance;
  return e;
}

Dataset Resample(const Dataset& data, double Ts, double start) {
  PNEUMID_CHECK(std::isfinite(Ts) && Ts > 0, "Resample: sample time must be > 0, got {}", Ts);
  data.RequireSamples(2, "Resample");
  const Eigen::VectorXd& t = data.time();
  const Eigen::Index n = data.size();
  const double t0 = std::isnan(start) ? t[0] : start;
  PNEUMID_CHECK(t0 >= t[0] && t0 <= t[n - 1], "Resample: start {} outside the data [{}, {}]", start,
                t[0], t[n - 1]);
  const double span = t[n - 1] - t0;
  const double steps = std::floor(span / Ts * (1.0 + 1e-12) + 1e-9);
  PNEUMID_CHECK(steps < 1e9, "Resample: {} samples are too many (Ts = {} s over {} s)", steps, Ts,
                span);
  const Eigen::Index m = static_cast<Eigen::Index>(steps) + 1;
  Eigen::VectorXd tn(m);
  // The last instant may exceed t[n-1] by rounding only; interpolation clamps.
  for (Eigen::Index k = 0; k < m; ++k) tn[k] = t0 + static_cast<double>(k) * Ts;
  Eigen::MatrixXd u(m, data.num_inputs()), y(m, data.num_outputs());
  Eigen::Index j = 0;  // t[j] <= tn[k] < t[j + 1]
  for (Eigen::Index k = 0; k < m; ++k) {
    while (j + 2 < n && t[j + 1] <= tn[k]) ++j;
    const double a = std::clamp((tn[k] - t[j]) / (t[j + 1] - t[j]), 0.0, 1.0);
    u.row(k) = (1.0 - a) * data.inputs().row(j) + a * data.inputs().row(j + 1);
    y.row(k) = (1.0 - a) * data.outputs().row(j) + a * data.outputs().row(j + 1);
  }
  return Rebuild(data, std::move(tn), std::move(u), std::move(y), -1);
}

bool DecimateOptions::IsValid(std::string* error) const {
  auto fail = [&](std::string m) {
    if (error != nullptr) *error = std::move(m);
    return false;
  };
  if (order < 2 || order > 16 || order % 2 != 0) {
    return fail(fmt::format("DecimateOptions: order must be even in [2, 16], got {}", order));
  }
  if (!(cutoff > 0 && cutoff < 1)) {
    return fail(fmt::format("DecimateOptions: cutoff must be in (0, 1), got {}", cutoff));
  }
  if (!(uniform_tolerance >= 0)) {
    return fail(
        fmt::format("DecimateOptions: uniform_tolerance must be >= 0, got {}", uniform_tolerance));
  }
  return true;
}

namespace {

/// One biquad b0 + b1 z^-1 + b2 z^-2 over 1 + a1 z^-1 + a2 z^-2.
struct Biquad {
  double b0, b1, b2, a1, a2;
};

/// Digital Butterworth low-pass of even `order` with cutoff `wn` (fraction of
/// Nyquist) as second-order sections of unit DC gain: analog poles
/// exp(j pi (2k + n + 1) / (2n)) scaled to the prewarped cutoff
/// 4 tan(pi wn / 2), mapped by the bilinear transform z = (4 + s) / (4 - s)
/// (fs = 2), zeros at z = -1.
std::vector<Biquad> ButterworthSections(int order, double wn) {
  const double pi = 3.14159265358979323846;
  const double warped = 4.0 * std::tan(pi * wn / 2.0);
  std::vector<Biquad> sections;
  for (int k = 0; k < order / 2; ++k) {
    const std::complex<double> p =
        warped * std::polar(1.0, pi * (2.0 * k + order + 1.0) / (2.0 * order));
    const std::complex<double> z = (4.0 + p) / (4.0 - p);
    const double a1 = -2.0 * z.real();
    const double a2 = std::norm(z);
    const double g = (1.0 + a1 + a2) / 4.0;  // unit DC gain: b = g [1 2 1]
    sections.push_back({g, 2.0 * g, g, a1, a2});
  }
  return sections;
}

/// Runs the cascade over x in place (direct form II transposed), starting from
/// the steady state of a constant input x[0] (unit DC gain: every state pair
/// is (b1 - a1 + b2 - a2, b2 - a2) * x[0]).
void FilterInPlace(const std::vector<Biquad>& sections, std::vector<double>& x) {
  const double x0 = x.front();
  for (const Biquad& s : sections) {
    double z2 = (s.b2 - s.a2) * x0;
    double z1 = (s.b1 - s.a1) * x0 + z2;
    for (double& v : x) {
      const double in = v;
      const double out = s.b0 * in + z1;
      z1 = s.b1 * in - s.a1 * out + z2;
      z2 = s.b2 * in - s.a2 * out;
      v = out;
    }
  }
}

}  // namespace

Dataset Decimate(const Dataset& data, int factor, const DecimateOptions& options) {
  std::string error;
  PNEUMID_CHECK(options.IsValid(&error), "Decimate: {}", error);
  PNEUMID_CHECK(factor >= 1, "Decimate: factor must be >= 1, got {}", factor);
  if (factor == 1) return Rebuild(data, data.time(), data.inputs(), data.outputs(), 0);
  data.RequireSamples(2, "Decimate");
  data.RequireUniform(options.uniform_tolerance);
  const Eigen::Index n = data.size();
  const Eigen::Index pad = 3 * (options.order + 1);
  if (n <= pad) {
    throw DataError(fmt::format(
        "{}: decimation with an order-{} anti-alias filter needs more than {} samples, the data "
        "has {}",
        Source(data), options.order, pad, n));
  }
  const auto sections = ButterworthSections(options.order, options.cutoff / factor);
  const Eigen::Index m = (n + factor - 1) / factor;
  std::vector<double> ext(static_cast<std::size_t>(n + 2 * pad));
  auto filtfilt = [&](const Eigen::VectorXd& x, Eigen::Ref<Eigen::VectorXd> out) {
    // Odd extension: 2 x[0] - x[pad..1], x, 2 x[n-1] - x[n-2..n-1-pad].
    for (Eigen::Index i = 0; i < pad; ++i) {
      ext[static_cast<std::size_t>(i)] = 2.0 * x[0] - x[pad - i];
      ext[static_cast<std::size_t>(n + pad + i)] = 2.0 * x[n - 1] - x[n - 2 - i];
    }
    for (Eigen::Index i = 0; i < n; ++i) ext[static_cast<std::size_t>(pad + i)] = x[i];
    FilterInPlace(sections, ext);
    std::reverse(ext.begin(), ext.end());
    FilterInPlace(sections, ext);
    std::reverse(ext.begin(), ext.end());
    for (Eigen::Index k = 0; k < m; ++k) out[k] = ext[static_cast<std::size_t>(pad + k * factor)];
  };
  Eigen::MatrixXd u(m, data.num_inputs()), y(m, data.num_outputs());
  for (Eigen::Index c = 0; c < u.cols(); ++c) filtfilt(data.inputs().col(c), u.col(c));
  for (Eigen::Index c = 0; c < y.cols(); ++c) filtfilt(data.outputs().col(c), y.col(c));
  Eigen::VectorXd t(m);
  for (Eigen::Index k = 0; k < m; ++k) t[k] = data.time()[k * factor];
  return Rebuild(data, std::move(t), std::move(u), std::move(y), -1);
}

Dataset SelectWindow(const Dataset& data, double t_start, double t_end) {
  PNEUMID_CHECK(!std::isnan(t_start) && !std::isnan(t_end) && t_start <= t_end,
                "SelectWindow: need t_start <= t_end, got [{}, {}]", t_start, t_end);
  const Eigen::VectorXd& t = data.time();
  const double tol = data.size() >= 2 ? 1e-9 * data.SampleTime() : 0.0;
  Eigen::Index first = 0;
  while (first < data.size() && t[first] < t_start - tol) ++first;
  Eigen::Index last = first;
  while (last < data.size() && t[last] <= t_end + tol) ++last;
  if (last == first) {
    throw DataError(fmt::format(
        "{}: no sample in the time window [{:g}, {:g}] s; the data spans [{:g}, {:g}] s",
        Source(data), t_start, t_end, data.size() ? t[0] : 0.0,
        data.size() ? t[data.size() - 1] : 0.0));
  }
  const Eigen::Index len = last - first;
  return Rebuild(data, t.segment(first, len), data.inputs().middleRows(first, len),
                 data.outputs().middleRows(first, len), first);
}

}  // namespace pneumid
