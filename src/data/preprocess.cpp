#include "pneumid/data/preprocess.hpp"

#include <algorithm>
#include <cmath>
#include <complex>
#include <limits>
#include <optional>
#include <vector>

#include <fmt/format.h>

#include "pneumid/common/check.hpp"
#include "pneumid/common/enum_names.hpp"
#include "pneumid/common/strings.hpp"

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

Dataset SubtractOperatingPoint(const Dataset& data, const OperatingPoint& op) {
  PNEUMID_CHECK(op.u0.size() == data.num_inputs() && op.y0.size() == data.num_outputs(),
                "SubtractOperatingPoint: {} input and {} output levels for data with {} inputs "
                "and {} outputs",
                op.u0.size(), op.y0.size(), data.num_inputs(), data.num_outputs());
  return SubtractOffsets(data, op.u0.transpose(), op.y0.transpose(), nullptr);
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

Dataset Detrend(const Dataset& data, ChannelSet which, LinearTrend* removed) {
  data.RequireSamples(2, "Detrend");
  // Least squares fit of a + b (t - tm) on centred time: the two regressors are
  // orthogonal, so a = mean(x), b = sum((t - tm) x) / sum((t - tm)^2).
  const double tm = data.time().mean();
  const Eigen::VectorXd tc = data.time().array() - tm;
  const double stt = tc.squaredNorm();
  auto detrend = [&](const Eigen::MatrixXd& m, bool active, Eigen::VectorXd* level,
                     Eigen::VectorXd* slope) {
    *level = Eigen::VectorXd::Zero(m.cols());
    *slope = Eigen::VectorXd::Zero(m.cols());
    if (!active) return m;
    Eigen::MatrixXd out(m.rows(), m.cols());
    for (Eigen::Index c = 0; c < m.cols(); ++c) {
      const double a = m.col(c).mean();
      const double b = tc.dot(m.col(c)) / stt;
      out.col(c) = m.col(c).array() - a - b * tc.array();
      (*level)[c] = a;
      (*slope)[c] = b;
    }
    return out;
  };
  LinearTrend trend;
  trend.time = tm;
  Eigen::MatrixXd u = detrend(data.inputs(), DoInputs(which), &trend.level.u0, &trend.slope.u0);
  Eigen::MatrixXd y = detrend(data.outputs(), DoOutputs(which), &trend.level.y0, &trend.slope.y0);
  if (removed != nullptr) *removed = std::move(trend);
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

/// One second-order section b0 + b1 z^-1 + b2 z^-2 over 1 + a1 z^-1 + a2 z^-2
/// (a first-order section has b2 = a2 = 0).
struct Biquad {
  double b0, b1, b2, a1, a2;
};

constexpr double kPi = 3.14159265358979323846;

/// Bilinear transform with fs = 2 (frequencies as fractions of Nyquist):
/// z = (4 + s) / (4 - s); the analog frequency of the digital fraction w is
/// the prewarped 4 tan(pi w / 2).
std::complex<double> Bilinear(std::complex<double> s) { return (4.0 + s) / (4.0 - s); }
double Prewarp(double w) { return 4.0 * std::tan(kPi * w / 2.0); }

/// Pole k of the analog Butterworth prototype of `order` with unit cutoff:
/// exp(j pi (2k + n + 1) / (2n)); k < order / 2 lie in the upper half plane,
/// k = (order - 1) / 2 of an odd order is the real pole -1.
std::complex<double> PrototypePole(int order, int k) {
  return std::polar(1.0, kPi * (2.0 * k + order + 1.0) / (2.0 * order));
}

/// Denominator 1 + a1 z^-1 + a2 z^-2 with digital roots za, zb (a conjugate
/// pair or two real roots).
std::pair<double, double> Denominator(std::complex<double> za, std::complex<double> zb) {
  return {-(za + zb).real(), (za * zb).real()};
}

/// Digital Butterworth filter as second-order sections [2], the design of
/// scipy.signal.butter(order, wn, btype, output='sos'): analog prototype poles
/// scaled (low-pass) or transformed s -> (s^2 + w0^2) / (s bw) (band-pass)
/// at prewarped frequencies, then mapped by the bilinear transform.
/// Low-pass: `high` is the cutoff (fraction of Nyquist), zeros at z = -1, each
/// section of unit DC gain. Band-pass [low, high]: `order` sections, each with
/// zeros at z = +1 and z = -1, total gain 1 at the centre frequency.
std::vector<Biquad> ButterworthSections(FilterKind kind, int order, double low, double high) {
  std::vector<Biquad> sections;
  if (kind == FilterKind::kLowpass) {
    const double warped = Prewarp(high);
    for (int k = 0; k < order / 2; ++k) {
      const std::complex<double> z = Bilinear(warped * PrototypePole(order, k));
      const auto [a1, a2] = Denominator(z, std::conj(z));
      const double g = (1.0 + a1 + a2) / 4.0;  // unit DC gain: b = g [1 2 1]
      sections.push_back({g, 2.0 * g, g, a1, a2});
    }
    if (order % 2 == 1) {
      const double z = Bilinear(-warped).real();
      const double g = (1.0 - z) / 2.0;  // b = g [1 1]
      sections.push_back({g, g, 0.0, -z, 0.0});
    }
    return sections;
  }
  const double w1 = Prewarp(low);
  const double w2 = Prewarp(high);
  const double bw = w2 - w1;
  const double w0sq = w1 * w2;
  // Roots of s^2 - p bw s + w0^2 = 0, the two band-pass poles of prototype pole p.
  auto band_poles = [&](std::complex<double> p) {
    const std::complex<double> h = p * bw / 2.0;
    const std::complex<double> r = std::sqrt(h * h - w0sq);
    return std::pair{Bilinear(h + r), Bilinear(h - r)};
  };
  auto add = [&](std::complex<double> za, std::complex<double> zb) {
    const auto [a1, a2] = Denominator(za, zb);
    sections.push_back({1.0, 0.0, -1.0, a1, a2});
  };
  for (int k = 0; k < order / 2; ++k) {
    const auto [za, zb] = band_poles(PrototypePole(order, k));
    add(za, std::conj(za));
    add(zb, std::conj(zb));
  }
  if (order % 2 == 1) {
    const auto [za, zb] = band_poles(-1.0);
    add(za, zb);
  }
  // Gain: the analog band-pass has gain exactly 1 at w0, which the bilinear
  // transform maps to the digital frequency 2 atan(w0 / 4).
  const std::complex<double> z = std::polar(1.0, 2.0 * std::atan(std::sqrt(w0sq) / 4.0));
  std::complex<double> h = 1.0;
  for (const Biquad& s : sections) {
    h *= (s.b0 + s.b1 / z + s.b2 / (z * z)) / (1.0 + s.a1 / z + s.a2 / (z * z));
  }
  const double gain = 1.0 / h.real();
  const double per_section = std::pow(std::abs(gain), 1.0 / static_cast<double>(sections.size()));
  for (std::size_t i = 0; i < sections.size(); ++i) {
    const double g = i == 0 && gain < 0 ? -per_section : per_section;
    sections[i].b0 *= g;
    sections[i].b1 *= g;
    sections[i].b2 *= g;
  }
  return sections;
}

/// Edge padding of scipy.signal.sosfiltfilt for these sections:
/// 3 * (2 * sections + 1 - min(#(b2 == 0), #(a2 == 0))).
Eigen::Index EdgePadding(const std::vector<Biquad>& sections) {
  Eigen::Index b2_zero = 0, a2_zero = 0;
  for (const Biquad& s : sections) {
    b2_zero += s.b2 == 0.0;
    a2_zero += s.a2 == 0.0;
  }
  return 3 * (2 * static_cast<Eigen::Index>(sections.size()) + 1 - std::min(b2_zero, a2_zero));
}

/// Runs the cascade over x in place (direct form II transposed), starting from
/// the steady state of a constant input x[0]: a section of DC gain
/// G = (b0 + b1 + b2) / (1 + a1 + a2) fed with the constant c has the states
/// z2 = (b2 - a2 G) c, z1 = (b1 - a1 G) c + z2 and passes G c on
/// (scipy.signal.sosfilt_zi).
void FilterInPlace(const std::vector<Biquad>& sections, std::vector<double>& x) {
  double level = x.front();
  for (const Biquad& s : sections) {
    const double gain = (s.b0 + s.b1 + s.b2) / (1.0 + s.a1 + s.a2);
    double z2 = (s.b2 - s.a2 * gain) * level;
    double z1 = (s.b1 - s.a1 * gain) * level + z2;
    level *= gain;
    for (double& v : x) {
      const double in = v;
      const double out = s.b0 * in + z1;
      z1 = s.b1 * in - s.a1 * out + z2;
      z2 = s.b2 * in - s.a2 * out;
      v = out;
    }
  }
}

/// Zero-phase filtering as scipy.signal.sosfiltfilt with odd extension of
/// `pad` samples [3]: on return ext[pad + i] is the filtered x[i]. Needs
/// x.size() > pad.
void FiltFilt(const std::vector<Biquad>& sections, Eigen::Index pad,
              const Eigen::Ref<const Eigen::VectorXd>& x, std::vector<double>& ext) {
  const Eigen::Index n = x.size();
  ext.resize(static_cast<std::size_t>(n + 2 * pad));
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
  const auto sections =
      ButterworthSections(FilterKind::kLowpass, options.order, 0.0, options.cutoff / factor);
  const Eigen::Index pad = EdgePadding(sections);
  if (n <= pad) {
    throw DataError(fmt::format(
        "{}: decimation with an order-{} anti-alias filter needs more than {} samples, the data "
        "has {}",
        Source(data), options.order, pad, n));
  }
  const Eigen::Index m = (n + factor - 1) / factor;
  std::vector<double> ext;
  auto decimate = [&](const Eigen::MatrixXd& x, Eigen::MatrixXd& out) {
    out.resize(m, x.cols());
    for (Eigen::Index c = 0; c < x.cols(); ++c) {
      FiltFilt(sections, pad, x.col(c), ext);
      for (Eigen::Index k = 0; k < m; ++k) {
        out(k, c) = ext[static_cast<std::size_t>(pad + k * factor)];
      }
    }
  };
  Eigen::MatrixXd u, y;
  decimate(data.inputs(), u);
  decimate(data.outputs(), y);
  Eigen::VectorXd t(m);
  for (Eigen::Index k = 0; k < m; ++k) t[k] = data.time()[k * factor];
  return Rebuild(data, std::move(t), std::move(u), std::move(y), -1);
}

namespace {
constexpr EnumName<FilterKind> kFilterKindNames[] = {
    {FilterKind::kLowpass, "lowpass"},
    {FilterKind::kBandpass, "bandpass"},
};
constexpr int kMaxFilterOrder = 10;
}  // namespace

std::string ToString(FilterKind v) { return std::string(EnumToString(kFilterKindNames, v)); }

FilterKind FilterKindFromString(const std::string& name) {
  return EnumFromString(kFilterKindNames, name, "filter kind");
}

bool FilterSpec::IsValid(std::string* error) const {
  auto fail = [&](std::string m) {
    if (error != nullptr) *error = std::move(m);
    return false;
  };
  if (order < 1 || order > kMaxFilterOrder) {
    return fail(fmt::format("filter order must be in [1, {}], got {}", kMaxFilterOrder, order));
  }
  if (kind == FilterKind::kLowpass) {
    if (!(std::isfinite(high_hz) && high_hz > 0)) {
      return fail(fmt::format("filter cutoff must be > 0 Hz, got {} Hz", high_hz));
    }
    return true;
  }
  if (!(std::isfinite(low_hz) && low_hz > 0) || !std::isfinite(high_hz)) {
    return fail(fmt::format("band-pass edges must be finite and > 0 Hz, got F1 = {} Hz, F2 = {} Hz",
                            low_hz, high_hz));
  }
  if (!(low_hz < high_hz)) {
    return fail(fmt::format("need F1 < F2, got F1 = {} Hz, F2 = {} Hz", low_hz, high_hz));
  }
  return true;
}

std::string FilterSpec::ToString() const {
  std::string s = kind == FilterKind::kLowpass ? fmt::format("lowpass:{}", high_hz)
                                               : fmt::format("bandpass:{},{}", low_hz, high_hz);
  if (order != kDefaultOrder) s += fmt::format(",order={}", order);
  return s;
}

FilterSpec FilterSpec::Parse(const std::string& text) {
  const std::string context = fmt::format("filter '{}'", Excerpt(text));
  const std::string_view trimmed = Trim(text);
  const auto colon = trimmed.find(':');
  PNEUMID_CHECK(colon != std::string_view::npos,
                "{}: expected lowpass:F or bandpass:F1,F2 (frequencies in Hz, optionally "
                "followed by ,order=N)",
                context);
  FilterSpec spec;
  const std::string kind = ToLower(Trim(trimmed.substr(0, colon)));
  PNEUMID_CHECK(kind == "lowpass" || kind == "bandpass",
                "{}: unknown filter kind '{}' (valid: lowpass, bandpass)", context, Excerpt(kind));
  spec.kind = FilterKindFromString(kind);
  std::vector<double> freqs;
  bool order_given = false;
  for (const std::string& item : Split(trimmed.substr(colon + 1), ',')) {
    const auto eq = item.find('=');
    if (eq == std::string::npos) {
      const std::optional<double> v = ParseDouble(item);
      PNEUMID_CHECK(v && std::isfinite(*v), "{}: '{}' is not a frequency in Hz", context,
                    Excerpt(item));
      freqs.push_back(*v);
      continue;
    }
    const std::string key = ToLower(Trim(std::string_view(item).substr(0, eq)));
    const std::string value(Trim(std::string_view(item).substr(eq + 1)));
    PNEUMID_CHECK(key == "order", "{}: unknown key '{}' (valid: order)", context, Excerpt(key));
    PNEUMID_CHECK(!order_given, "{}: order given twice", context);
    const std::optional<double> v = ParseDouble(value);
    PNEUMID_CHECK(v && std::isfinite(*v) && *v == std::floor(*v) && std::abs(*v) < 1e6,
                  "{}: order must be an integer, got '{}'", context, Excerpt(value));
    spec.order = static_cast<int>(*v);
    order_given = true;
  }
  const std::size_t expected = spec.kind == FilterKind::kLowpass ? 1 : 2;
  PNEUMID_CHECK(freqs.size() == expected, "{}: {} takes {} (in Hz), got {} value(s)", context, kind,
                expected == 1 ? "one cutoff frequency F" : "two band edges F1,F2", freqs.size());
  if (spec.kind == FilterKind::kLowpass) {
    spec.high_hz = freqs[0];
  } else {
    spec.low_hz = freqs[0];
    spec.high_hz = freqs[1];
  }
  std::string error;
  PNEUMID_CHECK(spec.IsValid(&error), "{}: {}", context, error);
  return spec;
}

Dataset Filter(const Dataset& data, const FilterSpec& spec, ChannelSet which) {
  std::string error;
  PNEUMID_CHECK(spec.IsValid(&error), "Filter: {}", error);
  data.RequireSamples(2, fmt::format("filter {}", spec.ToString()));
  data.RequireUniform();
  const double Ts = data.SampleTime();
  const double nyquist = 0.5 / Ts;
  auto check = [&](double f, const char* what) {
    if (f >= nyquist) {
      throw DataError(fmt::format(
          "filter {} {:g} Hz is {} the Nyquist frequency {:g} Hz of {} (sample time {:g} s): "
          "choose a frequency below {:g} Hz",
          what, f, f > nyquist ? "above" : "at", nyquist, Source(data), Ts, nyquist));
    }
  };
  if (spec.kind == FilterKind::kLowpass) {
    check(spec.high_hz, "cutoff");
  } else {
    check(spec.low_hz, "lower edge F1 =");
    check(spec.high_hz, "upper edge F2 =");
  }
  const auto sections =
      ButterworthSections(spec.kind, spec.order, spec.low_hz / nyquist, spec.high_hz / nyquist);
  const Eigen::Index pad = EdgePadding(sections);
  const Eigen::Index n = data.size();
  if (n <= pad) {
    throw DataError(
        fmt::format("{}: filter {} needs more than {} samples (its edge padding), the data has {}",
                    Source(data), spec.ToString(), pad, n));
  }
  std::vector<double> ext;
  auto filter = [&](const Eigen::MatrixXd& x, bool active) {
    if (!active) return Eigen::MatrixXd(x);
    Eigen::MatrixXd out(x.rows(), x.cols());
    for (Eigen::Index c = 0; c < x.cols(); ++c) {
      FiltFilt(sections, pad, x.col(c), ext);
      out.col(c) = Eigen::Map<const Eigen::VectorXd>(ext.data() + pad, n);
    }
    return out;
  };
  return Rebuild(data, data.time(), filter(data.inputs(), DoInputs(which)),
                 filter(data.outputs(), DoOutputs(which)), 0);
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

namespace pneumid {

bool TimeWindow::IsSet() const { return std::isfinite(start) || std::isfinite(end); }

bool TimeWindow::IsValid(std::string* error) const {
  if (std::isnan(start) || std::isnan(end) || start == std::numeric_limits<double>::infinity() ||
      end == -std::numeric_limits<double>::infinity() || start > end) {
    if (error != nullptr) {
      *error = fmt::format("window {}: need T0 <= T1 (seconds), got T0 = {} s, T1 = {} s",
                           ToString(), start, end);
    }
    return false;
  }
  return true;
}

std::string TimeWindow::ToString() const {
  auto side = [](double v) { return std::isfinite(v) ? fmt::format("{}", v) : std::string(); };
  return side(start) + ":" + side(end);
}

TimeWindow TimeWindow::Parse(const std::string& text) {
  const std::string context = fmt::format("window '{}'", Excerpt(text));
  const std::string_view trimmed = Trim(text);
  const auto colon = trimmed.find(':');
  PNEUMID_CHECK(colon != std::string_view::npos && trimmed.find(':', colon + 1) == trimmed.npos,
                "{}: expected T0:T1 in seconds (e.g. 5:9, or 5: from 5 s on, or :9 up to 9 s)",
                context);
  TimeWindow w;
  auto side = [&](std::string_view part, const char* name, double* value) {
    part = Trim(part);
    if (part.empty()) return;
    const std::optional<double> v = ParseDouble(part);
    PNEUMID_CHECK(v && std::isfinite(*v), "{}: {} '{}' is not a time in seconds", context, name,
                  Excerpt(part));
    *value = *v;
  };
  side(trimmed.substr(0, colon), "start", &w.start);
  side(trimmed.substr(colon + 1), "end", &w.end);
  PNEUMID_CHECK(w.start <= w.end, "{}: start {} s is after end {} s", context, w.start, w.end);
  return w;
}

namespace {
constexpr EnumName<DetrendKind> kDetrendKindNames[] = {
    {DetrendKind::kNone, "none"},
    {DetrendKind::kConstant, "constant"},
    {DetrendKind::kLinear, "linear"},
    {DetrendKind::kConstant, "mean"},
};
}  // namespace

std::string ToString(DetrendKind v) { return std::string(EnumToString(kDetrendKindNames, v)); }

DetrendKind DetrendKindFromString(const std::string& name) {
  return EnumFromString(kDetrendKindNames, name, "detrend kind");
}

bool PreprocessOptions::IsValid(std::string* error) const {
  auto fail = [&](std::string m) {
    if (error != nullptr) *error = std::move(m);
    return false;
  };
  std::string why;
  if (!window.IsValid(&why)) return fail(why);
  if (!(std::isfinite(resample_ts) && resample_ts >= 0)) {
    return fail(fmt::format("resample sample time must be > 0 s, got {}", resample_ts));
  }
  if (initial_samples < 0) {
    return fail(fmt::format("initial samples must be >= 0, got {}", initial_samples));
  }
  if (remove_initial && detrend != DetrendKind::kNone) {
    return fail(fmt::format(
        "remove-initial and detrend {} are alternatives: remove either the initial level or "
        "the {}, not both",
        pneumid::ToString(detrend), detrend == DetrendKind::kLinear ? "straight line" : "mean"));
  }
  if (remove_initial && initial_samples == 0 && !step.IsValid(&why)) return fail(why);
  if (filter && !filter->IsValid(&why)) return fail(fmt::format("filter: {}", why));
  if (decimate < 1) return fail(fmt::format("decimation factor must be >= 1, got {}", decimate));
  if (decimate > 1 && !decimate_options.IsValid(&why)) return fail(why);
  return true;
}

bool PreprocessOptions::IsIdentity() const {
  return !window.IsSet() && resample_ts == 0 && !remove_initial && detrend == DetrendKind::kNone &&
         !filter && decimate == 1;
}

namespace {

Eigen::VectorXd OffsetAt(const Eigen::VectorXd& level, const Eigen::VectorXd& slope, double dt) {
  if (slope.size() != level.size()) return level;
  return level + slope * dt;
}

std::string Values(const Eigen::VectorXd& v) {
  return fmt::format("[{:g}]", fmt::join(v.data(), v.data() + v.size(), ", "));
}

/// Subtracts level + slope (t - t0) from every channel.
Dataset SubtractLines(const Dataset& data, const OperatingPoint& level, const OperatingPoint& slope,
                      double t0) {
  const Eigen::ArrayXd dt = data.time().array() - t0;
  auto apply = [&](const Eigen::MatrixXd& m, const Eigen::VectorXd& a, const Eigen::VectorXd& b) {
    Eigen::MatrixXd out = m;
    if (a.size() != m.cols()) return out;
    const bool sloped = b.size() == m.cols() && (b.array() != 0.0).any();
    for (Eigen::Index c = 0; c < m.cols(); ++c) {
      out.col(c).array() -= a[c];
      if (sloped) out.col(c).array() -= b[c] * dt;
    }
    return out;
  };
  return Rebuild(data, data.time(), apply(data.inputs(), level.u0, slope.u0),
                 apply(data.outputs(), level.y0, slope.y0), 0);
}

}  // namespace

Eigen::VectorXd PreprocessRecord::InputOffsetAt(double t) const {
  return OffsetAt(level.u0, slope.u0, t - trend_time);
}

Eigen::VectorXd PreprocessRecord::OutputOffsetAt(double t) const {
  return OffsetAt(level.y0, slope.y0, t - trend_time);
}

bool PreprocessRecord::IsIdentity() const {
  return !window.IsSet() && resample_ts == 0 && offsets == "none" && !filter && decimate == 1;
}

Dataset Preprocess(const Dataset& data, const PreprocessOptions& options,
                   PreprocessRecord* record) {
  std::string error;
  PNEUMID_CHECK(options.IsValid(&error), "preprocessing: {}", error);
  PreprocessRecord r;
  r.channels = options.channels;
  r.level.u0 = r.slope.u0 = Eigen::VectorXd::Zero(data.num_inputs());
  r.level.y0 = r.slope.y0 = Eigen::VectorXd::Zero(data.num_outputs());
  // `d` points at the data of the latest step; no copy while nothing changes.
  const Dataset* d = &data;
  Dataset current;
  auto set = [&](Dataset next) {
    current = std::move(next);
    d = &current;
  };

  if (options.window.IsSet()) {
    data.RequireSamples(1, "a time window");
    const double t0 = data.time()[0];
    const double t1 = data.time()[data.size() - 1];
    if (options.window.start > t1 || options.window.end < t0) {
      throw DataError(fmt::format("window {} s lies outside the data {:g}..{:g} s of {}",
                                  options.window.ToString(), t0, t1, Source(data)));
    }
    set(SelectWindow(*d, options.window.start, options.window.end));
    r.window = options.window;
    r.steps.push_back(fmt::format("window {} s: {} samples from t = {:g} s to {:g} s",
                                  options.window.ToString(), d->size(), d->time()[0],
                                  d->time()[d->size() - 1]));
  }
  if (options.resample_ts > 0) {
    set(Resample(*d, options.resample_ts));
    r.resample_ts = options.resample_ts;
    r.steps.push_back(fmt::format("resample to Ts = {:g} s (linear interpolation): {} samples",
                                  options.resample_ts, d->size()));
  }
  if (options.remove_initial) {
    OperatingPoint removed;
    if (options.initial_samples > 0) {
      set(RemoveInitialOffset(*d, options.initial_samples, options.channels, &removed));
      r.steps.push_back(fmt::format("remove initial offset: mean of the first {} samples",
                                    options.initial_samples));
    } else {
      StepEvent step = DetectStep(*d, options.step);
      // The rest ends where the input first leaves its initial level (by
      // more than 6 times its spread over the first samples, and 1e-6 of
      // the step): on a rest followed by a PRBS the largest jump lies inside
      // the PRBS, and the mean before it took in PRBS samples (54 samples
      // averaged where the rest held 40).
      const Eigen::VectorXd u = d->inputs().col(step.input);
      const Eigen::Index m = std::max<Eigen::Index>(1, std::min<Eigen::Index>(step.index, 10));
      const double u_rest = u.head(m).mean();
      const double spread =
          m > 1 ? std::sqrt((u.head(m).array() - u_rest).square().sum() / (m - 1)) : 0.0;
      const double tolerance = std::max(6.0 * spread, 1e-6 * std::abs(step.size));
      for (Eigen::Index k = 1; k < step.index; ++k) {
        if (std::abs(u[k] - u_rest) > tolerance) {
          step.index = k;
          step.time = d->time()[k];
          break;
        }
      }
      set(RemoveInitialOffset(*d, step, options.channels, &removed));
      r.steps.push_back(
          fmt::format("remove initial offset: mean of the {} samples before the step at t = {:g} s",
                      step.index, step.time));
    }
    r.offsets = "initial";
    r.level = std::move(removed);
  } else if (options.detrend == DetrendKind::kConstant) {
    OperatingPoint removed;
    set(RemoveMeans(*d, options.channels, &removed));
    r.offsets = ToString(DetrendKind::kConstant);
    r.level = std::move(removed);
    r.steps.push_back("detrend constant: remove the mean of each channel");
  } else if (options.detrend == DetrendKind::kLinear) {
    LinearTrend removed;
    set(Detrend(*d, options.channels, &removed));
    r.offsets = ToString(DetrendKind::kLinear);
    r.level = std::move(removed.level);
    r.slope = std::move(removed.slope);
    r.trend_time = removed.time;
    r.steps.push_back(fmt::format(
        "detrend linear: remove the least-squares line of each channel, slopes u {} y {} per "
        "second about t = {:g} s",
        Values(r.slope.u0), Values(r.slope.y0), r.trend_time));
  }
  if (r.offsets != "none") {
    r.steps.back() += fmt::format(" (u0 = {}, y0 = {})", Values(r.level.u0), Values(r.level.y0));
  }
  if (options.filter) {
    set(Filter(*d, *options.filter, options.channels));
    r.filter = options.filter;
    r.steps.push_back(fmt::format("filter {} (zero-phase Butterworth of order {}, {})",
                                  options.filter->ToString(), options.filter->order,
                                  ToString(options.channels)));
  }
  if (options.decimate > 1) {
    set(Decimate(*d, options.decimate, options.decimate_options));
    r.decimate = options.decimate;
    r.decimate_options = options.decimate_options;
    r.steps.push_back(fmt::format("decimate by {} (order-{} anti-alias filter): Ts = {:g} s",
                                  options.decimate, options.decimate_options.order,
                                  d->size() >= 2 ? d->SampleTime() : 0.0));
  }
  if (record != nullptr) *record = std::move(r);
  if (d == &data) return data;
  return current;
}

Dataset ApplyRecorded(const Dataset& data, const PreprocessRecord& record) {
  auto check_size = [&](const Eigen::VectorXd& v, int n, const char* what) {
    if (v.size() != 0 && v.size() != n) {
      throw DataError(
          fmt::format("{} has {} {}, the recorded preprocessing (operating point) is for {}",
                      Source(data), n, what, v.size()));
    }
  };
  check_size(record.level.u0, data.num_inputs(), "inputs");
  check_size(record.level.y0, data.num_outputs(), "outputs");
  const Dataset* d = &data;
  Dataset current;
  auto set = [&](Dataset next) {
    current = std::move(next);
    d = &current;
  };
  if (record.resample_ts > 0) set(Resample(*d, record.resample_ts));
  if (record.offsets != "none") {
    set(SubtractLines(*d, record.level, record.slope, record.trend_time));
  }
  if (record.filter) set(Filter(*d, *record.filter, record.channels));
  if (record.decimate > 1) set(Decimate(*d, record.decimate, record.decimate_options));
  if (d == &data) return data;
  return current;
}

}  // namespace pneumid
