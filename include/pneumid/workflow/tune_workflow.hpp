// Tuning from a model: the horizons P, M and move suppression lambda of a
// predictive controller by a rule (control/tuning.hpp), or with the rule
// "auto" the settings of an MPC, DMC or PID that meet a specification
// (control/auto_tuning.hpp). This is the work of `pneumid tune`; the command
// line, the app's /api/tune and Python's tune_json all call RunTuneWorkflow,
// so that the same model and settings give the same numbers everywhere.
//
//   TuneWorkflowOptions o;
//   o.model = "fopdt-paper";   // model spec (models/model_file.hpp)
//   o.Ts = 0.01;
//   o.rule = "auto";           // or shridhar-cooper, paper-modified, explicit
//   o.controller = "pid";      // auto only: mpc (default), dmc, pid
//   o.plant = "ipa";           // auto only: the plant's input range bounds the design
//   const TuneWorkflowResult r = RunTuneWorkflow(o);
//   r.ToJson();                // what `tune --json` prints
//
// Settings are given as the command line writes them, and errors name the flags.
#pragma once

#include <limits>
#include <optional>
#include <string>

#include <nlohmann/json.hpp>

#include "pneumid/control/auto_tuning.hpp"
#include "pneumid/control/tuning.hpp"
#include "pneumid/lti/transfer_function.hpp"

namespace pneumid {

/// What to tune (see the file comment). The auto-only settings left at their
/// defaults take AutoTuneOptions' defaults.
struct TuneWorkflowOptions {
  std::string model;  ///< model spec (ParseModelSpec); unused when the model is passed
  double Ts = 0.0;    ///< controller sample time [s], > 0
  /// shridhar-cooper, paper-modified, explicit (TuningRuleFromString) or auto.
  std::string rule = "shridhar-cooper";
  int M = 0;  ///< control horizon; 0 = the rule's
  int P = 0;  ///< prediction horizon; 0 = the rule's (not with auto)
  /// Move suppression; NaN = the rule's (not with auto).
  double lambda = std::numeric_limits<double>::quiet_NaN();
  int tau_digits = 2;  ///< significant digits tau is rounded to in the P formula (0 = none)
  // --- rule auto only
  std::string controller;  ///< mpc, dmc or pid; empty = mpc
  double response_time = std::numeric_limits<double>::quiet_NaN();  ///< s; NaN = from the model
  std::string measure;  ///< what response_time measures: rise or settling; empty = rise
  double overshoot = std::numeric_limits<double>::quiet_NaN();       ///< percent; NaN = 5
  double aggressiveness = std::numeric_limits<double>::quiet_NaN();  ///< 0..1; NaN = 0.5
  double u_min = -std::numeric_limits<double>::infinity();           ///< input limits
  double u_max = std::numeric_limits<double>::infinity();            ///< upper input limit
  double du_max = std::numeric_limits<double>::infinity();  ///< largest input change per sample
  /// Plant spec whose physical input range gives the limits u_min/u_max leave
  /// open (as `control --plant` designs); empty = none.
  std::string plant;
  /// mpc: the Kalman filter's noise variances the design is evaluated with
  /// (AutoTuneOptions::measurement_noise, state_noise, disturbance_noise, as
  /// `control --measurement-noise` ... deploy them); NaN = MpcOptions' defaults.
  double measurement_noise = std::numeric_limits<double>::quiet_NaN();
  double state_noise = std::numeric_limits<double>::quiet_NaN();  ///< mpc: see measurement_noise
  double disturbance_noise = std::numeric_limits<double>::quiet_NaN();  ///< mpc: ditto

  /// False (with the reason) for a Ts that is not positive and finite.
  bool IsValid(std::string* error) const;
};

/// The settings RunTuneWorkflow found: one of the two results.
struct TuneWorkflowResult {
  std::optional<TuningResult> tuning;       ///< a rule other than auto
  std::optional<AutoTuneResult> automatic;  ///< rule auto
  /// TuningResult::ToJson or AutoTuneResult::ToJson: what `tune --json` prints.
  nlohmann::ordered_json ToJson() const;
};

/// Tunes the model of options.model.
/// @throws InvalidArgument for invalid options (auto-only settings with
///         another rule, P or lambda with auto, unknown names) or specs;
///         DataError for an unreadable model file.
TuneWorkflowResult RunTuneWorkflow(const TuneWorkflowOptions& options);
/// The same for a model given directly (options.model is not read).
TuneWorkflowResult RunTuneWorkflow(const TuneWorkflowOptions& options,
                                   const TransferFunction& model);

}  // namespace pneumid
