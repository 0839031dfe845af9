// Open-loop experiments (see include/pneumid/plant/experiment.hpp).
#include "pneumid/plant/experiment.hpp"

#include <cmath>
#include <map>

#include <fmt/format.h>
#include <matio.h>

#include "pneumid/common/check.hpp"
#include "pneumid/data/load.hpp"

namespace pneumid {

bool ExperimentOptions::IsValid(std::string* error) const {
  if (input_channel.name.empty() || output_channel.name.empty()) {
    if (error) *error = "input and output channel names must not be empty";
    return false;
  }
  return true;
}

namespace {

/// "p_a [Pa]" -> {"p_a", "Pa"}.
Channel ChannelFromLabel(const std::string& label) {
  const auto open = label.find('[');
  const auto close = label.rfind(']');
  if (open == std::string::npos || close == std::string::npos || close < open) return {label, ""};
  std::string name = label.substr(0, open);
  while (!name.empty() && name.back() == ' ') name.pop_back();
  return {name, label.substr(open + 1, close - open - 1)};
}

}  // namespace

Experiment RunExperiment(Plant& plant, const Signal& input, double duration,
                         const ExperimentOptions& options) {
  std::string error;
  PNEUMID_CHECK(options.IsValid(&error), "invalid experiment options: {}", error);
  const double Ts = plant.Ts();
  PNEUMID_CHECK(std::isfinite(duration) && duration >= Ts,
                "duration must be at least one sample period (Ts = {} s), got {} s", Ts, duration);
  const double steps = std::round(duration / Ts);
  PNEUMID_CHECK(steps < 1e8, "duration {} s at Ts = {} s gives too many samples ({})", duration, Ts,
                steps);
  const auto n = static_cast<Eigen::Index>(steps) + 1;
  input.CheckSampleTime(Ts);
  if (options.reset) plant.Reset();
  const double t0 = plant.time();

  Eigen::VectorXd t(n), u(n), y(n);
  std::map<std::string, Eigen::VectorXd> extras;
  const Eigen::Index report_every = std::max<Eigen::Index>(1, n / 200);
  for (Eigen::Index k = 0; k < n; ++k) {
    t[k] = t0 + static_cast<double>(k) * Ts;
    u[k] = input(t[k] - t0);
    y[k] = plant.Measure();
    for (const auto& [label, value] : plant.Extras()) {
      auto it = extras.find(label);
      if (it == extras.end()) it = extras.emplace(label, Eigen::VectorXd::Zero(n)).first;
      it->second[k] = value;
    }
    if (k + 1 < n) plant.Advance(u[k]);
    if (options.progress && (k % report_every == 0 || k + 1 == n))
      options.progress(static_cast<double>(k + 1) / static_cast<double>(n));
  }
  Experiment e;
  e.data = Dataset(t, u, y, {options.input_channel}, {options.output_channel});
  e.data.set_source("simulation of " + plant.Describe());
  for (auto& [label, values] : extras) e.extras.push_back({ChannelFromLabel(label), values});
  e.plant = plant.Describe();
  e.signal = input.ToString();
  return e;
}

void SaveExperiment(const Experiment& experiment, const std::string& path) {
  const DataFormat format = DataFormatFromPath(path);
  if (format == DataFormat::kCsv) {
    CsvWriteOptions csv;
    csv.comments = {"plant: " + experiment.plant, "input: " + experiment.signal};
    WriteCsv(experiment.data, path, experiment.extras, csv);
    return;
  }
  WriteMat(experiment.data, path);
  if (experiment.extras.empty()) return;
  // Append the extra signals as N x 1 double variables.
  mat_t* mat = Mat_Open(path.c_str(), MAT_ACC_RDWR);
  if (!mat) throw DataError(fmt::format("{}: cannot reopen the MAT file to add variables", path));
  for (const auto& column : experiment.extras) {
    Eigen::VectorXd values = column.values;
    size_t dims[2] = {static_cast<size_t>(values.size()), 1};
    matvar_t* var = Mat_VarCreate(column.channel.name.c_str(), MAT_C_DOUBLE, MAT_T_DOUBLE, 2, dims,
                                  values.data(), 0);
    const int status = var ? Mat_VarWrite(mat, var, MAT_COMPRESSION_NONE) : 1;
    if (var) Mat_VarFree(var);
    if (status != 0) {
      Mat_Close(mat);
      throw DataError(fmt::format("{}: cannot write variable '{}'", path, column.channel.name));
    }
  }
  Mat_Close(mat);
}

}  // namespace pneumid
