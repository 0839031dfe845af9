// JSON form of a PreprocessRecord, stored in model files so that validate,
// simulate, control and Python re-apply the preprocessing of the estimation
// data (ApplyRecorded) and restore its operating point.
//
//   {"window": "5:9", "resample_ts": 0.01, "offsets": "initial",
//    "channels": "both",
//    "u0": [0.61], "y0": [0.3], "u_slope": [0], "y_slope": [0],
//    "trend_time": 0.0, "filter": "lowpass:10", "decimate": 4,
//    "decimate_order": 8, "decimate_cutoff": 0.8,
//    "steps": ["window 5:9 s", ...]}
// Keys with default values may be missing; unknown keys are ignored.
#pragma once

#include <nlohmann/json.hpp>

#include "pneumid/data/preprocess.hpp"

namespace pneumid {

/// The object above; window, resample_ts, slopes and decimation keys are written only
/// when used (levels are always written, u0/y0 in the channels' units).
nlohmann::json ToJson(const PreprocessRecord& record);
/// @throws InvalidArgument naming the key when a value has the wrong type or
///         is invalid (e.g. "preprocessing: key 'filter': filter 'x': ...").
PreprocessRecord PreprocessRecordFromJson(const nlohmann::json& j);

}  // namespace pneumid
