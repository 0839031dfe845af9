// Preprocessing of measured data before identification: offsets, trends, step
// detection, resampling, decimation, time windows, zero-phase filtering, and a
// pipeline (Preprocess) whose record re-applies the same steps to other data.
//
// Every function returns a new Dataset with the same channels and source();
// the map from samples to file lines is kept only where samples keep their
// rows (SelectWindow, and the offset/trend removals).
//
// References
// [1] L. Ljung, System Identification: Theory for the User, 2nd ed., 1999,
//     sec. 14.1 (removing offsets and trends: "detrend" of the data).
// [2] S. Butterworth, "On the theory of filter amplifiers", 1930; the digital
//     low-pass is obtained with the bilinear transform and a prewarped cutoff
//     (A. V. Oppenheim, R. W. Schafer, Discrete-Time Signal Processing, 3rd
//     ed., 2010, sec. 7.2).
// [3] F. Gustafsson, "Determining the initial states in forward-backward
//     filtering", IEEE Trans. Signal Processing 44(4), 1996 (zero-phase
//     filtering with odd extension at the ends, as scipy.signal.sosfiltfilt).
#pragma once

#include <limits>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "pneumid/data/dataset.hpp"

namespace pneumid {

/// Which channels an operation applies to.
enum class ChannelSet { kInputs, kOutputs, kBoth };
std::string ToString(ChannelSet s);  ///< "inputs", "outputs", "both"
/// Parses "inputs", "outputs", "both"; @throws InvalidArgument otherwise.
ChannelSet ChannelSetFromString(const std::string& s);

/// Values removed from the channels by RemoveMeans / RemoveInitialOffset (the
/// operating point): data_out = data_in - offset, per channel.
struct OperatingPoint {
  Eigen::VectorXd u0;  ///< one value per input (0 for channels left alone)
  Eigen::VectorXd y0;  ///< one value per output
};

/// Subtracts the mean of each selected channel over all samples.
/// @param data     the samples (not changed).
/// @param which    the channels to centre.
/// @param removed  if not null, receives the subtracted values.
/// @throws DataError when the dataset is empty.
Dataset RemoveMeans(const Dataset& data, ChannelSet which = ChannelSet::kBoth,
                    OperatingPoint* removed = nullptr);

/// Subtracts, from each selected channel, its mean over the first `n` samples
/// (the initial steady state before an experiment starts).
/// @throws InvalidArgument when n < 1; DataError when the data has fewer than n samples.
Dataset RemoveInitialOffset(const Dataset& data, Eigen::Index n,
                            ChannelSet which = ChannelSet::kBoth,
                            OperatingPoint* removed = nullptr);

/// Subtracts a given operating point (e.g. a model's u0, y0) from the
/// channels: the deviations a linear model around that point acts on.
/// @throws InvalidArgument when the sizes of op.u0 / op.y0 differ from the
/// numbers of inputs / outputs.
Dataset SubtractOperatingPoint(const Dataset& data, const OperatingPoint& op);

/// A straight line per channel: value_i(t) = level_i + slope_i * (t - time).
struct LinearTrend {
  OperatingPoint level;  ///< value at `time` (the channel mean), one per channel
  OperatingPoint slope;  ///< per second (0 for channels left alone)
  double time = 0.0;     ///< time origin in seconds (the mean time of the data)
};

/// Removes a least-squares straight line a + b t (t in seconds) from each
/// selected channel; the result has zero mean and no linear trend [1]. For
/// uniform sampling this is scipy.signal.detrend(x, type='linear').
/// @param data     the samples (not changed).
/// @param which    the channels to detrend.
/// @param removed  if not null, receives the lines that were subtracted.
/// @throws DataError when the dataset has fewer than 2 samples.
Dataset Detrend(const Dataset& data, ChannelSet which = ChannelSet::kBoth,
                LinearTrend* removed = nullptr);

/// How DetectStep searches an input channel for a step.
struct StepDetectOptions {
  /// Input channel searched for the step. Default 0.
  int input = 0;
  /// Samples averaged on each side of a candidate step (0: automatic,
  /// clamp(N / 20, 1, 25)). Longer windows tolerate more noise.
  Eigen::Index window = 0;
  /// Minimum ratio of the jump to the spread (standard deviation) of the input
  /// inside the two windows; below it the data holds no step (a ramp gives
  /// about 3.5, white noise about 1-2). Default 5.
  double min_significance = 5.0;
  /// Minimum absolute jump in input units (default 0: only the ratio counts).
  double min_size = 0.0;

  /// True for input >= 0, window >= 0 and finite min_significance, min_size >= 0;
  /// otherwise false with the reason in *error (when not null).
  bool IsValid(std::string* error) const;
};

/// A step found in an input channel.
struct StepEvent {
  int input = 0;                 ///< input channel
  Eigen::Index index = 0;        ///< first sample at the new level
  double time = 0.0;             ///< time[index], s
  double size = 0.0;             ///< level_after - baseline_before (input units)
  double baseline_before = 0.0;  ///< mean input over all samples before `index`
  double level_after = 0.0;      ///< mean input over the window after `index`
  /// Mean of each output over all samples before `index` (initial steady state).
  Eigen::VectorXd outputs_before;
  /// |jump| / spread inside the windows (see StepDetectOptions::min_significance).
  double significance = 0.0;
};

/// Finds the largest jump of an input channel: the sample k maximising
/// |mean(u[k, k+w)) - mean(u[k-w, k))|, i.e. a matched filter for a step,
/// which averages noise over w samples on each side (computed in O(N) with
/// prefix sums; windows shrink at the ends of the record).
/// @throws InvalidArgument for invalid options or a missing input channel.
/// @throws DataError naming the source when the input holds no step (constant,
///         too noisy for min_significance, or a ramp/slow change) or when fewer
///         than 2 samples are present.
StepEvent DetectStep(const Dataset& data, const StepDetectOptions& options = {});

/// Subtracts the mean of every channel over the samples before the detected
/// step (the steady state before the test).
/// @throws DataError as DetectStep, or when the step is at the first sample.
Dataset RemoveInitialOffset(const Dataset& data, const StepEvent& step,
                            ChannelSet which = ChannelSet::kBoth,
                            OperatingPoint* removed = nullptr);

/// Linear interpolation onto the uniform grid t0, t0 + Ts, ... <= t_end, where
/// t0 is the first time instant (or `start`, when given and inside the data).
/// @throws InvalidArgument when Ts <= 0 or start lies outside the data.
/// @throws DataError when the data has fewer than 2 samples.
Dataset Resample(const Dataset& data, double Ts,
                 double start = std::numeric_limits<double>::quiet_NaN());

/// Anti-alias filter of Decimate.
struct DecimateOptions {
  /// Order of the Butterworth low-pass (even, 2..16). Default 8.
  int order = 8;
  /// Cutoff as a fraction of the new Nyquist frequency (0, 1). Default 0.8,
  /// as scipy.signal.decimate.
  double cutoff = 0.8;
  /// Relative tolerance on uniform sampling (Dataset::RequireUniform).
  double uniform_tolerance = 1e-3;

  /// True for an even order in [2, 16], cutoff in (0, 1) and uniform_tolerance >= 0;
  /// otherwise false with the reason in *error (when not null).
  bool IsValid(std::string* error) const;
};

/// Keeps every `factor`-th sample (starting with the first) after a zero-phase
/// anti-alias filter: a Butterworth low-pass of `order` at cutoff *
/// (fs / 2) / factor [2], run forward and backward with odd extension of
/// 3 * (order + 1) samples at each end and steady-state initial conditions [3]
/// (identical to scipy.signal.sosfiltfilt(butter(order, cutoff / factor,
/// output='sos'), x) sliced with step factor). The magnitude response is |H|^2: no phase
/// shift, -6 dB at the cutoff, DC gain exactly 1.
/// @throws InvalidArgument when factor < 1 or the options are invalid.
/// @throws DataError when the sampling is not uniform or the data is shorter
///         than the filter's edge padding (3 * (order + 1) + 1 samples).
Dataset Decimate(const Dataset& data, int factor, const DecimateOptions& options = {});

/// Samples with t_start <= t <= t_end (seconds, inclusive up to 1e-9 of the
/// sample time).
/// @throws InvalidArgument when t_start > t_end.
/// @throws DataError naming the source when no sample lies in the window.
Dataset SelectWindow(const Dataset& data, double t_start, double t_end);

/// Kind of a zero-phase Butterworth filter (Filter, FilterSpec).
enum class FilterKind { kLowpass, kBandpass };
std::string ToString(FilterKind k);  ///< "lowpass", "bandpass"
/// Parses "lowpass" or "bandpass"; @throws InvalidArgument otherwise.
FilterKind FilterKindFromString(const std::string& s);

/// A zero-phase Butterworth filter, written "lowpass:F" or "bandpass:F1,F2"
/// (frequencies in Hz), optionally followed by ",order=N":
///   lowpass:10            low-pass, cutoff 10 Hz, order 5
///   bandpass:0.5,20       band-pass, pass band 0.5..20 Hz, order 5
///   lowpass:10,order=2
/// The default order 5 is that of MATLAB's idfilt. A band-pass of order N has
/// 2N poles (as scipy.signal.butter(N, [w1, w2], 'bandpass')). Run forward
/// and backward (Filter), the magnitude response is |H|^2: -6 dB at the
/// cutoffs, slope 2 * 20 N dB/decade, no phase shift.
struct FilterSpec {
  static constexpr int kDefaultOrder = 5;  ///< Butterworth order when none is written

  FilterKind kind = FilterKind::kLowpass;  ///< low-pass (high_hz) or band-pass (low_hz..high_hz)
  /// Band-pass: lower edge F1 in Hz, 0 < F1 < F2. Unused for a low-pass.
  double low_hz = 0.0;
  /// Low-pass: cutoff F in Hz (> 0). Band-pass: upper edge F2 in Hz.
  double high_hz = 0.0;
  /// Butterworth order, 1..10.
  int order = kDefaultOrder;

  /// True when the frequencies and the order are usable (independent of the
  /// data; Filter also checks them against the data's Nyquist frequency).
  bool IsValid(std::string* error) const;
  /// "lowpass:10" / "bandpass:0.5,20", with ",order=N" when not the default;
  /// Parse(ToString()) gives the same spec.
  std::string ToString() const;
  /// Parses the syntax above.
  /// @throws InvalidArgument with a message starting "filter 'TEXT': ", e.g.
  ///         "filter 'bandpass:20,5': need F1 < F2, got F1 = 20 Hz, F2 = 5 Hz".
  static FilterSpec Parse(const std::string& text);
};

/// Filters the selected channels with the zero-phase Butterworth filter of
/// `spec`: the digital filter of butter(order, f / (fs / 2)) [2] run forward
/// and backward with odd extension of 3 * (2 * sections + 1) samples at each
/// end (fewer for a low-pass of odd order, whose first-order section has no
/// z^-2 term) and steady-state initial conditions [3]; identical to
/// scipy.signal.sosfiltfilt(butter(order, Wn, btype, output='sos'), x). The
/// samples keep their times and file lines.
/// @throws InvalidArgument when spec is invalid.
/// @throws DataError when the sampling is not uniform, a frequency is not below
///         the Nyquist frequency of the data ("filter cutoff 60 Hz is above the
///         Nyquist frequency 50 Hz of data.csv"), or the data is not longer
///         than the edge padding.
Dataset Filter(const Dataset& data, const FilterSpec& spec, ChannelSet which = ChannelSet::kBoth);

/// A time window [start, end] in seconds, written "T0:T1"; either side may be
/// left empty ("5:" from 5 s to the end, ":9" up to 9 s).
struct TimeWindow {
  double start = -std::numeric_limits<double>::infinity();  ///< s; -inf: from the first sample
  double end = std::numeric_limits<double>::infinity();     ///< s; +inf: to the last sample

  /// True when at least one side is bounded.
  bool IsSet() const;
  bool IsValid(std::string* error) const;  ///< start <= end, neither NaN
  std::string ToString() const;            ///< "5:9", "5:", ":9"
  /// @throws InvalidArgument "window '9:5': start 9 s is after end 5 s" and the like.
  static TimeWindow Parse(const std::string& text);
};

/// How Preprocess removes offsets or trends.
enum class DetrendKind {
  kNone,      ///< leave levels alone
  kConstant,  ///< subtract the mean of each channel (numpy: x - x.mean())
  kLinear,    ///< subtract the least-squares line (scipy.signal.detrend(x, 'linear'))
};
std::string ToString(DetrendKind k);  ///< "none", "constant", "linear"
/// Parses "none", "constant" (alias "mean"), "linear"; @throws InvalidArgument.
DetrendKind DetrendKindFromString(const std::string& s);

/// Options of Preprocess. The steps run in this fixed order:
///   1. window          keep the samples in [window.start, window.end]
///   2. resample        linear interpolation onto a uniform grid of resample_ts
///   3. offsets         remove_initial (level before the step, or of the first
///                      initial_samples samples) or detrend (mean or line)
///   4. filter          zero-phase Butterworth (FilterSpec)
///   5. decimate        keep every decimate-th sample after an anti-alias filter
/// Window first so that everything else sees only the selected part;
/// resampling before anything that assumes uniform sampling; offsets from the
/// unfiltered samples so that the operating point is in the units and levels
/// of the raw data; decimation last, after the filter, at the rate the filter
/// spec was written for.
struct PreprocessOptions {
  TimeWindow window;            ///< default: all samples
  double resample_ts = 0.0;     ///< seconds; 0: keep the time base
  bool remove_initial = false;  ///< subtract the initial steady state
  /// With remove_initial: 0 averages the samples before the step found by
  /// DetectStep(step); n > 0 averages the first n samples.
  Eigen::Index initial_samples = 0;
  StepDetectOptions step;                    ///< step search for remove_initial
  DetrendKind detrend = DetrendKind::kNone;  ///< not together with remove_initial
  std::optional<FilterSpec> filter;          ///< none by default
  int decimate = 1;                          ///< factor >= 1; 1: keep all samples
  DecimateOptions decimate_options;          ///< anti-alias filter of the decimation
  /// Channels the offsets, trends and the filter apply to.
  ChannelSet channels = ChannelSet::kBoth;

  /// False for a negative resample_ts, decimate < 1, remove_initial together
  /// with detrend, invalid window, filter or step/decimate options.
  bool IsValid(std::string* error) const;
  /// True when no step would change the data.
  bool IsIdentity() const;
};

/// What Preprocess did, enough to re-apply the same steps to other data
/// (ApplyRecorded) and to restore the original levels of a model's simulated
/// output: y_original(t) = y(t) + OutputOffsetAt(t).
///
/// The removed offset of channel i at time t is
///   offset_i(t) = level_i + slope_i * (t - trend_time)
/// with slope 0 for remove_initial and constant detrend.
struct PreprocessRecord {
  TimeWindow window;         ///< as applied (unbounded when none)
  double resample_ts = 0.0;  ///< 0: not resampled
  /// "none", "initial" (remove_initial) or ToString(DetrendKind).
  std::string offsets = "none";
  OperatingPoint level;                     ///< level_i, one value per channel (0 where untouched)
  OperatingPoint slope;                     ///< slope_i per second (zero unless linear detrend)
  double trend_time = 0.0;                  ///< time origin of the slope, s (mean time of the data)
  std::optional<FilterSpec> filter;         ///< zero-phase filter applied (none: not filtered)
  ChannelSet channels = ChannelSet::kBoth;  ///< channels offsets, trends and filter applied to
  int decimate = 1;                         ///< decimation factor (1: all samples kept)
  DecimateOptions decimate_options;         ///< anti-alias filter used when decimate > 1
  /// One line per step applied, for reports and model notes, e.g.
  /// "remove initial offset: mean of the 120 samples before the step at t = 1.2 s".
  std::vector<std::string> steps;

  /// Offsets removed from the inputs / outputs at time t (level + slope term).
  Eigen::VectorXd InputOffsetAt(double t) const;
  Eigen::VectorXd OutputOffsetAt(double t) const;  ///< see InputOffsetAt; one per output
  /// True when nothing was done.
  bool IsIdentity() const;
};

/// Applies the steps of `options` in the order documented at PreprocessOptions
/// and returns the result; *record (if not null) receives what was done.
/// @throws InvalidArgument when options are invalid ("decimation factor must be
///         >= 1, got 0").
/// @throws DataError naming the source when a step does not fit the data: the
///         window lies outside it ("window 5:9 s lies outside the data 0..4 s
///         of data.csv"), a filter frequency is at or above its Nyquist
///         frequency, no step is found for remove_initial, too few samples.
Dataset Preprocess(const Dataset& data, const PreprocessOptions& options,
                   PreprocessRecord* record = nullptr);

/// Applies a recorded preprocessing to other data (validation data, data to
/// simulate against): resampling, the recorded offsets and trends (not
/// re-estimated from `data`), the filter and decimation. The window is not
/// applied: it selected a part of the estimation data, whose times need not
/// mean anything in `data`.
/// @throws DataError as Preprocess, and when `data` has a different number of
///         inputs or outputs than the record.
Dataset ApplyRecorded(const Dataset& data, const PreprocessRecord& record);

}  // namespace pneumid
