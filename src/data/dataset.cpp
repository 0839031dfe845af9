#include "pneumid/data/dataset.hpp"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

#include "pneumid/common/check.hpp"

namespace pneumid {
namespace {

std::vector<Channel> DefaultChannels(const std::string& prefix, Eigen::Index n) {
  std::vector<Channel> channels;
  for (Eigen::Index i = 0; i < n; ++i) {
    channels.push_back({n == 1 ? prefix : fmt::format("{}{}", prefix, i + 1), ""});
  }
  return channels;
}

void CheckFinite(const Eigen::Ref<const Eigen::MatrixXd>& m, const char* what) {
  if (m.allFinite()) return;
  for (Eigen::Index c = 0; c < m.cols(); ++c) {
    for (Eigen::Index r = 0; r < m.rows(); ++r) {
      PNEUMID_CHECK(std::isfinite(m(r, c)), "Dataset: {} ({}, {}) is not finite: {}", what, r, c,
                    m(r, c));
    }
  }
}

std::string SourcePrefix(const std::string& source) {
  return source.empty() ? std::string("dataset") : source;
}

/// Median of the sample intervals: the nominal sample time, unaffected by a
/// few gaps or jitter.
double MedianInterval(const Eigen::VectorXd& t) {
  std::vector<double> dt(static_cast<std::size_t>(t.size() - 1));
  for (Eigen::Index i = 1; i < t.size(); ++i) dt[static_cast<std::size_t>(i - 1)] = t[i] - t[i - 1];
  const auto mid = dt.begin() + static_cast<std::ptrdiff_t>(dt.size() / 2);
  std::nth_element(dt.begin(), mid, dt.end());
  return *mid;
}

/// True when max(dt) - min(dt) <= rel_tol * min(dt): then every interval is
/// within rel_tol times the median interval of it (the median lies between
/// min and max), without sorting. One pass; false leaves the decision to the
/// median test.
bool IntervalsWithin(const Eigen::VectorXd& t, double rel_tol) {
  const Eigen::Index n = t.size();
  if (n < 2) return true;
  const auto dt = t.tail(n - 1) - t.head(n - 1);
  return dt.maxCoeff() - dt.minCoeff() <= rel_tol * dt.minCoeff();
}

}  // namespace

Dataset::Dataset(Eigen::VectorXd time, Eigen::MatrixXd inputs, Eigen::MatrixXd outputs,
                 std::vector<Channel> input_channels, std::vector<Channel> output_channels)
    : input_channels_(std::move(input_channels)), output_channels_(std::move(output_channels)) {
  const Eigen::Index n = time.size();
  // A matrix without columns carries no samples; give it the right shape.
  if (inputs.cols() == 0) inputs.resize(n, 0);
  if (outputs.cols() == 0) outputs.resize(n, 0);
  PNEUMID_CHECK(inputs.rows() == n,
                "Dataset: inputs have {} rows but time has {} samples (length mismatch)",
                inputs.rows(), n);
  PNEUMID_CHECK(outputs.rows() == n,
                "Dataset: outputs have {} rows but time has {} samples (length mismatch)",
                outputs.rows(), n);
  if (input_channels_.empty()) input_channels_ = DefaultChannels("u", inputs.cols());
  if (output_channels_.empty()) output_channels_ = DefaultChannels("y", outputs.cols());
  PNEUMID_CHECK(static_cast<Eigen::Index>(input_channels_.size()) == inputs.cols(),
                "Dataset: {} input channel names for {} input columns", input_channels_.size(),
                inputs.cols());
  PNEUMID_CHECK(static_cast<Eigen::Index>(output_channels_.size()) == outputs.cols(),
                "Dataset: {} output channel names for {} output columns", output_channels_.size(),
                outputs.cols());
  CheckFinite(time, "time");
  CheckFinite(inputs, "input");
  CheckFinite(outputs, "output");
  for (Eigen::Index i = 1; i < n; ++i) {
    PNEUMID_CHECK(time[i] > time[i - 1],
                  "Dataset: time is not strictly increasing at sample {}: t[{}] = {} <= t[{}] = {}",
                  i, i, time[i], i - 1, time[i - 1]);
  }
  samples_ = std::make_shared<const Samples>(
      Samples{std::move(time), std::move(inputs), std::move(outputs)});
}

const Dataset::Samples& Dataset::Empty() {
  static const Samples empty;
  return empty;
}

Dataset Dataset::FromUniform(double Ts, const Eigen::VectorXd& u, const Eigen::VectorXd& y,
                             double t0, Channel input, Channel output) {
  PNEUMID_CHECK(std::isfinite(Ts) && Ts > 0,
                "Dataset::FromUniform: sample time must be > 0, got {}", Ts);
  PNEUMID_CHECK(std::isfinite(t0), "Dataset::FromUniform: start time must be finite, got {}", t0);
  PNEUMID_CHECK(u.size() == y.size(),
                "Dataset::FromUniform: u has {} samples but y has {} (length mismatch)", u.size(),
                y.size());
  Eigen::VectorXd t(u.size());
  for (Eigen::Index i = 0; i < t.size(); ++i) t[i] = t0 + static_cast<double>(i) * Ts;
  return Dataset(std::move(t), u, y, {std::move(input)}, {std::move(output)});
}

Eigen::VectorXd Dataset::u(int i) const {
  PNEUMID_CHECK(i >= 0 && i < num_inputs(), "Dataset::u: input {} out of range [0, {})", i,
                num_inputs());
  return inputs().col(i);
}

Eigen::VectorXd Dataset::y(int i) const {
  PNEUMID_CHECK(i >= 0 && i < num_outputs(), "Dataset::y: output {} out of range [0, {})", i,
                num_outputs());
  return outputs().col(i);
}

Dataset Dataset::SelectChannels(const std::vector<int>& inputs,
                                const std::vector<int>& outputs) const {
  auto identity = [](const std::vector<int>& v, int n) {
    if (static_cast<int>(v.size()) != n) return false;
    for (int i = 0; i < n; ++i) {
      if (v[static_cast<std::size_t>(i)] != i) return false;
    }
    return true;
  };
  auto pick = [](const Eigen::MatrixXd& m, const std::vector<int>& v,
                 const std::vector<Channel>& channels, const char* what,
                 std::vector<Channel>* picked) {
    Eigen::MatrixXd out(m.rows(), static_cast<Eigen::Index>(v.size()));
    for (std::size_t k = 0; k < v.size(); ++k) {
      PNEUMID_CHECK(v[k] >= 0 && v[k] < m.cols(),
                    "Dataset::SelectChannels: {} {} out of range [0, {})", what, v[k], m.cols());
      out.col(static_cast<Eigen::Index>(k)) = m.col(v[k]);
      picked->push_back(channels[static_cast<std::size_t>(v[k])]);
    }
    return out;
  };
  Dataset out;
  if (identity(inputs, num_inputs()) && identity(outputs, num_outputs())) {
    out = *this;
    return out;
  }
  std::vector<Channel> ic, oc;
  Eigen::MatrixXd u = pick(this->inputs(), inputs, input_channels_, "input", &ic);
  Eigen::MatrixXd y = pick(this->outputs(), outputs, output_channels_, "output", &oc);
  out = Dataset(time(), std::move(u), std::move(y), std::move(ic), std::move(oc));
  out.time_channel_ = time_channel_;
  out.source_ = source_;
  out.line_samples_ = line_samples_;
  out.line_numbers_ = line_numbers_;
  return out;
}

double Dataset::SampleTime() const {
  PNEUMID_CHECK(size() >= 2, "Dataset::SampleTime: needs at least 2 samples, {} has {}",
                SourcePrefix(source_), size());
  return (time()[size() - 1] - time()[0]) / static_cast<double>(size() - 1);
}

double Dataset::MedianSampleInterval() const {
  PNEUMID_CHECK(size() >= 2, "Dataset::MedianSampleInterval: needs at least 2 samples, {} has {}",
                SourcePrefix(source_), size());
  return MedianInterval(time());
}

bool Dataset::IsUniform(double rel_tol) const {
  PNEUMID_CHECK(rel_tol >= 0, "Dataset::IsUniform: tolerance must be >= 0, got {}", rel_tol);
  if (size() < 3) return true;
  if (IntervalsWithin(time(), rel_tol)) return true;
  const double Ts = MedianInterval(time());
  for (Eigen::Index i = 1; i < size(); ++i) {
    if (std::abs((time()[i] - time()[i - 1]) - Ts) > rel_tol * Ts) return false;
  }
  return true;
}

void Dataset::RequireUniform(double rel_tol) const {
  PNEUMID_CHECK(rel_tol >= 0, "Dataset::RequireUniform: tolerance must be >= 0, got {}", rel_tol);
  if (size() < 3) return;
  if (IntervalsWithin(time(), rel_tol)) return;
  const double Ts = MedianInterval(time());
  for (Eigen::Index i = 1; i < size(); ++i) {
    const double dt = time()[i] - time()[i - 1];
    if (std::abs(dt - Ts) > rel_tol * Ts) {
      throw DataError(fmt::format(
          "{}: column '{}': sampling is not uniform: interval {:g} s between t = {:g} and t = {:g} "
          "differs from the typical (median) interval {:g} s by {:.3g} % (tolerance {:g} %); "
          "resample the data "
          "to a uniform grid first (pneumid::Resample, or `pneumid info {} --resample {:g} -o "
          "FILE`)",
          Where(i), time_channel_.name, dt, time()[i - 1], time()[i], Ts,
          100.0 * std::abs(dt - Ts) / Ts, 100.0 * rel_tol,
          source_.empty() ? std::string("DATA") : source_, Ts));
    }
  }
}

void Dataset::RequireSamples(Eigen::Index n, const std::string& what) const {
  if (size() < n) {
    throw DataError(fmt::format("{}: {} needs at least {} samples, the data has {}",
                                SourcePrefix(source_), what, n, size()));
  }
}

void Dataset::RequireNumericScale() const {
  auto check = [&](const Eigen::Ref<const Eigen::VectorXd>& v, const std::string& kind,
                   const Channel& channel) {
    if (v.size() == 0) return;
    const double lo = v.minCoeff();
    const double hi = v.maxCoeff();
    const double magnitude = std::max(std::abs(lo), std::abs(hi));
    const std::string column =
        fmt::format("{}: {} column '{}'", SourcePrefix(source_), kind, Excerpt(channel.name));
    if (magnitude > kMaxMagnitude) {
      throw DataError(
          fmt::format("{}: values range from {:g} to {:g}; magnitudes above {:g} overflow in the "
                      "computations (differences and squares exceed the double range): rescale the "
                      "column (e.g. change its unit)",
                      column, lo, hi, kMaxMagnitude));
    }
    const double spread = hi - lo;
    if (spread > 0 && spread < kMinSpread) {
      throw DataError(fmt::format(
          "{}: values range from {:g} to {:g}, a spread of {:g}; variations below {:g} "
          "underflow to zero in the computations (extreme scale): rescale the column (e.g. "
          "change its unit)",
          column, lo, hi, spread, kMinSpread));
    }
  };
  check(time(), "time", time_channel_);
  for (int i = 0; i < num_inputs(); ++i) {
    check(inputs().col(i), "input", input_channels_[static_cast<std::size_t>(i)]);
  }
  for (int i = 0; i < num_outputs(); ++i) {
    check(outputs().col(i), "output", output_channels_[static_cast<std::size_t>(i)]);
  }
}

long Dataset::SourceLine(Eigen::Index i) const {
  PNEUMID_CHECK(i >= 0 && i < size(), "Dataset::SourceLine: sample {} out of range [0, {})", i,
                size());
  if (line_samples_.empty()) return 0;
  auto it = std::upper_bound(line_samples_.begin(), line_samples_.end(), i);
  const auto j = static_cast<std::size_t>(std::distance(line_samples_.begin(), it)) - 1;
  return line_numbers_[j] + static_cast<long>(i - line_samples_[j]);
}

std::string Dataset::Where(Eigen::Index i) const {
  const long line = (i >= 0 && i < size()) ? SourceLine(i) : 0;
  if (line > 0) return fmt::format("{}:{}", SourcePrefix(source_), line);
  if (source_.empty()) return fmt::format("sample {}", i);
  return fmt::format("{}: sample {}", source_, i);
}

void Dataset::set_source_lines(std::vector<Eigen::Index> first_samples,
                               std::vector<long> first_lines) {
  PNEUMID_CHECK(first_samples.size() == first_lines.size(),
                "Dataset::set_source_lines: {} sample break points but {} lines",
                first_samples.size(), first_lines.size());
  PNEUMID_CHECK(first_samples.empty() || first_samples.front() == 0,
                "Dataset::set_source_lines: the first break point must be sample 0, got {}",
                first_samples.empty() ? 0 : first_samples.front());
  for (std::size_t j = 1; j < first_samples.size(); ++j) {
    PNEUMID_CHECK(first_samples[j] > first_samples[j - 1],
                  "Dataset::set_source_lines: break points must increase");
  }
  line_samples_ = std::move(first_samples);
  line_numbers_ = std::move(first_lines);
}

}  // namespace pneumid
