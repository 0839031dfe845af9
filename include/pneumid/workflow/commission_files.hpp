// The files of a commissioning run (docs/commission.md): the experiment's
// data, the verification trace, the controller configuration that
// `pneumid control|run|codegen --config` take as they are, the figures, the
// C module of the final design and, on request, the HTML report. The
// command line (`pneumid commission -o DIR`) and the app (POST
// /api/commission) write the same files through WriteCommissionFiles.
#pragma once

#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "pneumid/plant/actuator.hpp"
#include "pneumid/workflow/commission.hpp"

namespace pneumid {

/// Where and what WriteCommissionFiles writes.
struct CommissionFilesOptions {
  /// Existing directory the files go to (the model file is already there:
  /// CommissionOptions::directory).
  std::string directory = ".";
  /// Loop period in s of the controller ([loop] period).
  double Ts = 0.01;
  /// [io] backend: "sim", "udp://HOST:PORT" or "comedi[:DEVICE]".
  std::string io = "sim";
  /// [io] plant of the "sim" backend: a MakePlant spec (plant_factory.hpp),
  /// e.g. "ipa" or "ipa:config=/abs/twin.toml".
  std::string plant = "ipa";
  /// The plant's name in the report's title (Plant::Describe()).
  std::string plant_description;
  /// Also write report.html (commission_report.hpp).
  bool report = false;
  /// Also write the C module of the final design to DIR/c (pneumid codegen).
  bool c_module = true;
  /// True when the options are consistent; else false with the reason.
  bool IsValid(std::string* error) const;
};

/// What WriteCommissionFiles wrote.
struct CommissionFiles {
  std::vector<std::string> written;  ///< paths of the files written, in order
  /// DIR/c when the C module was written, else "not written: REASON" (or
  /// empty when not asked for or there is no design).
  std::string c_module;
  /// {written, c_module}.
  nlohmann::ordered_json ToJson() const;
};

/// Writes DIR/data.csv (the experiment: t, u, y), DIR/experiment.png and
/// DIR/validation.png (the chosen model on the estimation and held-out
/// sequences), and, when a controller was designed, DIR/verification.csv
/// (t, r, y, u, d of the final verification), DIR/verification.png,
/// DIR/controller.toml ([controller] with the model reference and the final
/// settings, [loop], [io], [safety]: inputs within the limits, outputs
/// within the reachable range widened by half its span), DIR/c and, with
/// `options.report`, DIR/report.html. `actuator` labels the axes.
/// @throws InvalidArgument for invalid options; DataError when a file cannot
/// be written.
CommissionFiles WriteCommissionFiles(const CommissionResult& result, const Actuator& actuator,
                                     const CommissionFilesOptions& options);

}  // namespace pneumid
