// Open-loop experiments: drive a plant with a signal and record what it does.
//
// Samples k = 0 .. N-1 at t_k = k Ts with N = round(duration / Ts) + 1 (the
// last sample at t = duration): u_k = signal(t_k), y_k = plant.Measure() (taken
// before u_k is applied, as a data acquisition loop does), then
// plant.Advance(u_k). The plant's Extras() at t_k are recorded beside.
#pragma once

#include <functional>
#include <string>
#include <vector>

#include "pneumid/data/csv.hpp"
#include "pneumid/data/dataset.hpp"
#include "pneumid/plant/plant.hpp"
#include "pneumid/plant/signal.hpp"

namespace pneumid {

/// Options of RunExperiment: reset, channel names and a progress callback.
struct ExperimentOptions {
  /// Reset the plant before the run (default true).
  bool reset = true;
  /// Channel names and units of the recorded input and output.
  Channel input_channel{"u", ""};
  Channel output_channel{"y", ""};  ///< e.g. {"F", "N"} for the IPA's force
  /// Called now and then with the fraction done (0..1), e.g. for a progress bar.
  std::function<void(double)> progress;
  /// True when both channel names are non-empty; otherwise false with the reason in
  /// *error (when not null).
  bool IsValid(std::string* error) const;
};

/// Result of a run: the dataset (time, input, measured output) and the extra
/// signals of the plant, one column per Extras() entry ("p_a [Pa]" becomes the
/// channel {"p_a", "Pa"}).
struct Experiment {
  Dataset data;                   ///< time (s), the applied input and the measured output
  std::vector<CsvColumn> extras;  ///< the plant's Extras() per sample, e.g. chamber pressures
  std::string plant;              ///< plant.Describe()
  std::string signal;             ///< signal.ToString()
};

/// Runs the experiment described above for `duration` seconds.
/// @throws InvalidArgument when duration < Ts or is not finite.
Experiment RunExperiment(Plant& plant, const Signal& input, double duration,
                         const ExperimentOptions& options = {});

/// Writes an experiment by file extension: CSV (.csv/.txt/.tsv/.dat; extras as
/// additional columns, plant and signal as comment lines) or MAT (.mat;
/// variables t, u, y and one variable per extra, e.g. p_a).
/// @throws DataError when the file cannot be written or the extension is unknown.
void SaveExperiment(const Experiment& experiment, const std::string& path);

}  // namespace pneumid
