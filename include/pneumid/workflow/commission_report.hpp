// The HTML report of a commissioning run (`pneumid commission --report`): the
// experiment and what the probe measured, the models ranked on the held-out
// part with the chosen one simulated on both sequences, every verification
// with its figure and per-step table, and what limits the loop.
#pragma once

#include <string>

#include "pneumid/data/dataset.hpp"
#include "pneumid/workflow/commission.hpp"

namespace pneumid {

/// Writes the report of `result` to `path` (a self-contained HTML page with
/// inline SVG figures, report/html.hpp); `plant` names the plant in the title,
/// `output` and `input` label the axes (with units).
/// @throws DataError when the file cannot be written.
void WriteCommissionReport(const CommissionResult& result, const std::string& plant,
                           const Channel& input, const Channel& output, const std::string& path);

}  // namespace pneumid
