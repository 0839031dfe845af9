// Output flags shared by the commands that write results:
//
//   --plot FILE.png|svg   a figure (format by extension, checked when parsing)
//   -o FILE               one output file; --output-dir DIR where a command
//                         writes several files
//   --json                JSON on stdout; with -o FILE the JSON goes to the file
//                         and stdout gets a short summary (never the same JSON twice)
#pragma once

#include <string>

#include <CLI/CLI.hpp>
#include <Eigen/Core>
#include <nlohmann/json.hpp>

namespace pneumid::cli {

/// Adds --plot FILE (PNG or SVG by extension) describing `what` is drawn.
CLI::Option* AddPlotOption(CLI::App& app, std::string& path, const std::string& what);

/// `v`, or null when it is not finite (JSON has no NaN/Inf).
nlohmann::json JsonNumber(double v);
/// The numbers of `v` as a JSON array (null where not finite).
nlohmann::json JsonNumbers(const Eigen::VectorXd& v);

}  // namespace pneumid::cli
