// Command-line options that select a linear model, shared by every command
// that takes one (convert, step, bode, tune, simulate, ...):
//
//   --model SPEC      a model spec (pneumid/models/model_file.hpp): arx-paper,
//                     arx-paper-ct, fopdt-paper, fopdt:K=..,tau=..,theta=..,
//                     sopdt:..., tf:num=..,den=..[,Ts=..][,delay=..], FILE.json[#method]
//   --num B0,B1,...   numerator coefficients, comma-separated: descending powers
//   --den A0,A1,...   of s, or ascending powers of z^-1 when --Ts is given
//   --Ts TS           sample time in s of the model given by --num/--den (0 = continuous)
//   --delay S         input delay in s (overrides the model's; a multiple of Ts
//                     for a discrete model)
// A list that starts with a minus sign is written --num=-1,2.
#pragma once

#include <limits>
#include <string>

#include <CLI/CLI.hpp>

#include "pneumid/lti/transfer_function.hpp"

namespace pneumid::cli {

struct ModelOptions {
  std::string model;
  std::string num;
  std::string den;
  double Ts = 0.0;
  double delay = std::numeric_limits<double>::quiet_NaN();  ///< NaN: not given
};

/// Adds the flags above to `app`, storing into `options` (which must outlive the
/// parse). With `with_ts` false the caller defines --Ts itself (e.g. as a target
/// sample time) and copies it into options.Ts when it describes the model.
void AddModelOptions(CLI::App& app, ModelOptions& options, bool with_ts = true);

/// Adds --t-final T and --dt DT (s, >= 0; 0 = automatic) of a simulated time
/// response (lti/response.hpp: Step, Impulse), storing into the arguments.
void AddTimeGridOptions(CLI::App& app, double& t_final, double& dt);

/// Parses "1,-0.5,2" into numbers.
/// @throws InvalidArgument naming `option` and the offending entry.
std::vector<double> ParseCoefficientList(const std::string& option, const std::string& text);

/// The model selected by `options`.
/// @throws InvalidArgument when neither or both of --model and --num/--den are
///   given, or for invalid coefficients; DataError for an unreadable model file.
TransferFunction ResolveModel(const ModelOptions& options);

/// Short name of the selected model for legends and titles: the --model spec,
/// or "G(s) = ..." / "G(z) = ..." for --num/--den.
std::string ModelLabel(const ModelOptions& options, const TransferFunction& g);

/// Human-readable description: the transfer function, its poles (conjugate
/// pairs as a +/- bj), DC gain and stability, one item per line, each line
/// starting with `indent`.
std::string DescribeModel(const TransferFunction& g, const std::string& indent = "");

}  // namespace pneumid::cli
