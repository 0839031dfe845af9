// Preprocessing of measured data before identification: offsets, trends, step
// detection, resampling, decimation, time windows.
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
#include <string>

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

/// Removes a least-squares straight line a + b t (t in seconds) from each
/// selected channel; the result has zero mean and no linear trend [1].
/// @throws DataError when the dataset has fewer than 2 samples.
Dataset Detrend(const Dataset& data, ChannelSet which = ChannelSet::kBoth);

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

struct DecimateOptions {
  /// Order of the Butterworth low-pass (even, 2..16). Default 8.
  int order = 8;
  /// Cutoff as a fraction of the new Nyquist frequency (0, 1). Default 0.8,
  /// as scipy.signal.decimate.
  double cutoff = 0.8;
  /// Relative tolerance on uniform sampling (Dataset::RequireUniform).
  double uniform_tolerance = 1e-3;

  bool IsValid(std::string* error) const;
};

/// Keeps every `factor`-th sample (starting with the first) after a zero-phase
/// anti-alias filter: a Butterworth low-pass of `order` at cutoff *
/// (fs / 2) / factor [2], run forward and backward with odd extension of
/// 3 * (order + 1) samples at each end and steady-state initial conditions [3]
/// (identical to scipy.signal.sosfiltfilt(butter(order, cutoff / factor,
/// output='sos'), x)[::factor]). The magnitude response is |H|^2: no phase
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

}  // namespace pneumid
