// Dataset: measured input/output data of one experiment (the `iddata` of pneumid).
//
// Layout (N samples, nu inputs, ny outputs):
//   time     N        seconds, strictly increasing
//   inputs   N x nu   one column per input channel
//   outputs  N x ny   one column per output channel
// Names and units describe each channel; `source` names the file the data came
// from so that later errors can point at it.
//
// The samples are immutable and shared: copying a Dataset (passing it by value,
// storing it in a vector, SelectChannels of all channels) copies no sample, so
// a million-row record goes from the reader to an estimator without copies.
// Only the metadata (names, source, line map) is per object.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include <Eigen/Core>

namespace pneumid {

/// Name and unit of one measured signal, e.g. {"F", "N"} or {"u", "%"}.
struct Channel {
  std::string name;  ///< signal name as in a file header, e.g. "F"
  std::string unit;  ///< unit symbol, e.g. "N", "%", "s"; empty when unknown
};

/// Sampled input/output record of one experiment: time in s, N x nu inputs, N x ny
/// outputs, channel names and units, and the source file for messages.
class Dataset {
 public:
  /// An empty dataset: no samples, no channels, time channel {"t", "s"}.
  Dataset() = default;

  /// Builds a dataset from columns. Unnamed channels are called u, y (u1, u2, ... for
  /// several). Throws InvalidArgument when lengths differ, the channel names do not
  /// match the columns, a value is not finite, or time is not strictly increasing.
  Dataset(Eigen::VectorXd time, Eigen::MatrixXd inputs, Eigen::MatrixXd outputs,
          std::vector<Channel> input_channels = {}, std::vector<Channel> output_channels = {});

  /// Uniformly sampled SISO dataset starting at t = t0.
  static Dataset FromUniform(double Ts, const Eigen::VectorXd& u, const Eigen::VectorXd& y,
                             double t0 = 0.0, Channel input = {"u", ""},
                             Channel output = {"y", ""});

  Eigen::Index size() const { return time().size(); }                     ///< number of samples N
  int num_inputs() const { return static_cast<int>(inputs().cols()); }    ///< nu
  int num_outputs() const { return static_cast<int>(outputs().cols()); }  ///< ny

  /// Sample instants in s (N, strictly increasing).
  const Eigen::VectorXd& time() const { return samples().time; }
  /// Input samples, N x nu, one column per input channel.
  const Eigen::MatrixXd& inputs() const { return samples().inputs; }
  /// Output samples, N x ny, one column per output channel.
  const Eigen::MatrixXd& outputs() const { return samples().outputs; }
  /// Column i of the inputs / outputs (throws InvalidArgument when out of range).
  Eigen::VectorXd u(int i = 0) const;
  Eigen::VectorXd y(int i = 0) const;  ///< column i of the outputs (a copy); same check

  /// The dataset restricted to the given input and output channels (in that
  /// order), with their names, the time channel, source and line map. Selecting
  /// all channels in their order shares the samples (no copy).
  /// @throws InvalidArgument when a channel index is out of range.
  Dataset SelectChannels(const std::vector<int>& inputs, const std::vector<int>& outputs) const;

  /// Name and unit of each input column (nu entries).
  const std::vector<Channel>& input_channels() const { return input_channels_; }
  /// Name and unit of each output column (ny entries).
  const std::vector<Channel>& output_channels() const { return output_channels_; }
  /// Name and unit of the time column (default {"t", "s"}), as written to files.
  Channel time_channel() const { return time_channel_; }
  /// Renames the time column (e.g. the header a file used); the samples stay in s.
  void set_time_channel(Channel c) { time_channel_ = std::move(c); }

  /// Where the data came from (file name), used in error messages.
  const std::string& source() const { return source_; }
  void set_source(std::string s) { source_ = std::move(s); }  ///< sets source()

  /// Mean sample interval (t_end - t_0) / (N - 1) in seconds; throws when N < 2.
  double SampleTime() const;
  /// Median sample interval in seconds: the nominal sample time of data with
  /// gaps or jitter; throws InvalidArgument when N < 2.
  double MedianSampleInterval() const;
  /// True when every sample interval is within `rel_tol` times the median
  /// interval from it. The median interval is the nominal sample time:
  /// a few gaps do not move it, and for uniform data it equals SampleTime().
  bool IsUniform(double rel_tol = 1e-3) const;
  /// Throws DataError naming the source and the first offending sample when the
  /// sampling is not uniform within `rel_tol` (suggesting resampling).
  void RequireUniform(double rel_tol = 1e-3) const;
  /// Throws DataError naming the source when fewer than `n` samples are present;
  /// `what` names the method that needs them.
  void RequireSamples(Eigen::Index n, const std::string& what) const;

  /// Largest magnitude and smallest nonzero spread (max - min) of a column that
  /// RequireNumericScale accepts. Beyond 1e150 the squares and products formed
  /// by least squares overflow the double range (about 1.8e308) and differences
  /// of values near 1e308 are infinite; below 1e-150 they underflow to zero, so
  /// a step of that size is indistinguishable from no step.
  static constexpr double kMaxMagnitude = 1e150;
  static constexpr double kMinSpread = 1e-150;  ///< smallest nonzero spread (see above)
  /// Throws DataError naming the source, the column and its value range when a
  /// column (time, inputs, outputs) holds a value of magnitude above
  /// kMaxMagnitude (overflow risk) or varies by less than kMinSpread without
  /// being constant (extreme scale): rescale the column, e.g. change its
  /// unit. Identification calls it before it uses the data.
  void RequireNumericScale() const;

  /// Line (1-based) of `source()` that holds sample `i`, or 0 when unknown (the
  /// dataset was not read from a text file, or was derived from one by
  /// resampling, filtering, ...). Throws InvalidArgument when i is out of range.
  long SourceLine(Eigen::Index i) const;
  /// Where sample `i` is, for error messages: "data.csv:12" when the line is
  /// known, "data.mat: sample 11" otherwise ("sample 11" without a source).
  std::string Where(Eigen::Index i) const;
  /// Records the file lines of the samples as break points: sample
  /// `first_samples[j] + k` lies on line `first_lines[j] + k` until the next
  /// break point. Both vectors have equal length, first_samples starts at 0 and
  /// increases. An empty map clears the information.
  void set_source_lines(std::vector<Eigen::Index> first_samples, std::vector<long> first_lines);

 private:
  struct Samples {
    Eigen::VectorXd time;
    Eigen::MatrixXd inputs;
    Eigen::MatrixXd outputs;
  };
  const Samples& samples() const { return samples_ ? *samples_ : Empty(); }
  static const Samples& Empty();

  std::shared_ptr<const Samples> samples_;
  std::vector<Channel> input_channels_;
  std::vector<Channel> output_channels_;
  Channel time_channel_{"t", "s"};
  std::string source_;
  std::vector<Eigen::Index> line_samples_;
  std::vector<long> line_numbers_;
};

}  // namespace pneumid
