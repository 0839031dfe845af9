// Builds a controller (DMC, GPC, PID or MPC) from a model, a tuning rule and
// limits: the one place where the command line, the bindings and the
// real-time loop turn settings into a Controller.
//
//   dmc  P, M, lambda from the tuning rule (tuning.hpp); QDMC when constrained,
//        and with the rule auto also whenever an input limit is finite (the
//        auto-tuner evaluates a QDMC then)
//   gpc  N1 = 1, N2 = P, Nu = M, lambda from the tuning rule; T filter "1",
//        "A" (= the model's denominator, DMC's disturbance model) or
//        coefficients "1 -0.8" (ascending powers of q^-1)
//   pid  gains by SIMC or IMC from the model's FOPDT description (tuning.hpp,
//        FopdtFromModel), tau_c <= 0 = the rule's default; each of Kc, Ti,
//        Td given explicitly replaces the rule's value; an integrating model
//        (a pole at s = 0 / z = 1, no FOPDT) takes Kc (and Ti, Td) as given,
//        and its velocity feed-forward Kff defaults to 1/Ki + Kc Td (pid.hpp,
//        Ki the model's velocity gain lim s G(s)): a ramp set-point is then
//        tracked without lag
//   mpc  state-space MPC (mpc.hpp) from the model with its delay as states:
//        P, M, lambda from the tuning rule as for dmc, the input limits and
//        soft output bounds (a QP whenever one is finite), the disturbance
//        model and the Kalman filter's noises of the spec (defaults: input
//        disturbance model, measurement noise R = 1, disturbance noise 1)
//
// A design samples its model once (PredictionModel): dmc, gpc, the tuning
// rules and the mpc's state space all come from that one discretization, and
// the auto-tuner (rule auto, auto_tuning.hpp) builds each candidate it
// evaluates the way the dmc and mpc are built here, on that same model and
// with the spec's options (limits, constrained form, disturbance model,
// Kalman noises): the controller deployed is the one evaluated.
#pragma once

#include <limits>
#include <memory>
#include <optional>
#include <string>

#include <nlohmann/json_fwd.hpp>

#include "pneumid/control/auto_tuning.hpp"
#include "pneumid/control/controller.hpp"
#include "pneumid/control/duty_modulator.hpp"
#include "pneumid/control/mpc.hpp"
#include "pneumid/control/narx_linearizing_controller.hpp"
#include "pneumid/control/pid.hpp"
#include "pneumid/control/prediction_model.hpp"
#include "pneumid/control/tuning.hpp"
#include "pneumid/models/static_map.hpp"
#include "pneumid/lti/transfer_function.hpp"

namespace pneumid {

/// Everything MakeController needs to design a controller, names parsed (see
/// ControllerSettings for the user-facing form).
struct ControllerSpec {
  ControllerType type = ControllerType::kDmc;  ///< which controller (default dmc)
  TuningOptions tuning;                        ///< P, M, lambda (dmc, gpc, mpc)
  InputLimits limits;                          ///< limits on the plant input u (default: none)
  bool constrained = false;                    ///< dmc: QDMC with the QP solver
  double y_min = -std::numeric_limits<double>::infinity();  ///< soft output bounds (QDMC, mpc)
  double y_max = std::numeric_limits<double>::infinity();   ///< upper soft output bound
  /// gpc: T filter: "1" (none), "A" (T = A) or monic coefficients such as "1 -0.8".
  std::string t_filter = "1";
  PidTuningRule pid_rule = PidTuningRule::kSimc;  ///< pid tuning rule (default SIMC)
  double tau_c = 0.0;  ///< pid closed-loop time constant (s); <= 0 = rule default
  /// pid gains given explicitly (NaN = the rule's value of that gain): the
  /// proportional gain Kc, the integral time Ti in s (inf = no integral
  /// action) and the derivative time Td in s. Not with auto_tune.
  double pid_kc = std::numeric_limits<double>::quiet_NaN();
  double pid_ti = std::numeric_limits<double>::quiet_NaN();  ///< explicit Ti in s (NaN = rule's)
  double pid_td = std::numeric_limits<double>::quiet_NaN();  ///< explicit Td in s (NaN = rule's)
  /// pid velocity feed-forward Kff (PidOptions::velocity_feedforward); NaN =
  /// 1/Ki + Kc Td for an integrating model, 0 otherwise (file comment).
  double pid_kff = std::numeric_limits<double>::quiet_NaN();
  DisturbanceModel disturbance = DisturbanceModel::kInput;  ///< mpc (mpc.hpp)
  /// mpc: the Kalman filter's noise variances (MpcOptions::measurement_noise,
  /// state_noise, disturbance_noise); NaN = MpcOptions' defaults.
  double measurement_noise = std::numeric_limits<double>::quiet_NaN();
  double state_noise = std::numeric_limits<double>::quiet_NaN();        ///< (NaN = default 0)
  double disturbance_noise = std::numeric_limits<double>::quiet_NaN();  ///< (NaN = default 1)
  /// Tune from specifications (auto_tuning.hpp) instead of the tuning rule:
  /// mpc and dmc get P, M, lambda, pid its gains. auto_options.controller,
  /// .limits, .constrained, .disturbance and the noise variances are taken
  /// from this spec (type, limits, ...), so the tuner evaluates the
  /// controller that runs; a dmc with a finite input limit (u_min, u_max or
  /// du_max) is then a QDMC, as the tuner evaluates it, also without
  /// `constrained`.
  bool auto_tune = false;
  AutoTuneOptions auto_options;  ///< the specification when auto_tune is set
  /// The actuator's static map f (a Hammerstein model's input map): the
  /// controller is designed on the linear part with input v = f(u), limits
  /// InnerLimits(f, limits), and runs behind f's inverse
  /// (inverse_map_controller.hpp); `limits` stay the limits on u.
  std::optional<StaticMap> input_map;
  /// An input-affine NARX model of the actuator (an affine-narx model file):
  /// the controller is designed on the reference model of its linearization
  /// and runs behind it (narx_linearizing_controller.hpp); `limits` stay the
  /// limits on u. Excludes input_map (the model brings its own).
  std::optional<InputAffineNarx> narx_model;
  /// The output map g of a Wiener or Hammerstein-Wiener model y = g(G ...):
  /// the controller is designed on the rest of the model and takes set point
  /// and measurement through g's inverse (OutputMapController).
  std::optional<StaticMap> output_map;
  NarxLinearizingOptions narx_options;  ///< the reference model's time constant
  /// The measurements the controller accepts and its input on the others
  /// (controller.hpp), set on the outermost controller.
  MeasurementGuard guard;
  /// Inputs the actuator cannot hold (duty_modulator.hpp); not empty: the
  /// controller's input goes through a sigma-delta modulator over them
  /// (ModulatedController, outermost).
  std::vector<InputGap> input_gaps;
};

/// Controller settings as a user states them (command line, configuration,
/// bindings): names as strings, unset numbers as 0 / NaN.
struct ControllerSettings {
  std::string controller = "dmc";  ///< dmc, gpc, pid or mpc
  /// Tuning rule name (TuningRuleFromString); empty: inferred (InferTuningRule).
  std::string rule;
  int P = 0;  ///< prediction horizon override (0 = the rule's)
  int M = 0;  ///< control horizon override (0 = the rule's)
  double lambda = std::numeric_limits<double>::quiet_NaN();  ///< override (NaN = the rule's)
  InputLimits limits;        ///< limits on the plant input u (default: none)
  bool constrained = false;  ///< dmc: QDMC with the QP solver
  /// Soft lower output bound (QDMC, mpc); -inf = none.
  double y_min = -std::numeric_limits<double>::infinity();
  double y_max = std::numeric_limits<double>::infinity();  ///< soft upper output bound
  std::string t_filter = "1";     ///< gpc T filter: "1", "A" or coefficients ("1 -0.8")
  std::string pid_rule = "simc";  ///< pid tuning rule: "simc" or "imc"
  double tau_c = 0.0;             ///< pid closed-loop time constant (s); <= 0 = the rule's default
  /// pid: explicit gains (NaN = the rule's value of that gain; Ti inf = no
  /// integral action), as --Kc, --Ti, --Td.
  double pid_kc = std::numeric_limits<double>::quiet_NaN();
  double pid_ti = std::numeric_limits<double>::quiet_NaN();  ///< pid: explicit Ti in s
  double pid_td = std::numeric_limits<double>::quiet_NaN();  ///< pid: explicit Td in s
  /// pid: velocity feed-forward, input per unit set-point rate, as --Kff (NaN
  /// = 1/Ki + Kc Td for an integrating model, 0 otherwise).
  double pid_kff = std::numeric_limits<double>::quiet_NaN();
  std::string disturbance = "input";  ///< mpc: input, output or none
  /// mpc: Kalman filter noise variances, as --measurement-noise (output
  /// units squared), --state-noise, --disturbance-noise; NaN = the defaults
  /// (1, 0, 1: mpc.hpp).
  double measurement_noise = std::numeric_limits<double>::quiet_NaN();
  double state_noise = std::numeric_limits<double>::quiet_NaN();  ///< mpc: see measurement_noise
  double disturbance_noise = std::numeric_limits<double>::quiet_NaN();  ///< mpc: ditto
  /// rule "auto": the specifications (auto_tuning.hpp; NaN = from the model).
  double response_time = std::numeric_limits<double>::quiet_NaN();
  double overshoot = 5.0;       ///< rule "auto": maximum overshoot, percent (default 5)
  double aggressiveness = 0.5;  ///< rule "auto": 0 robust .. 1 aggressive (default 0.5)
  /// A file with the actuator's static map (models/model_file.hpp ReadStaticMap:
  /// a static-map or Hammerstein model file, or {"u", "y"}); empty = none,
  /// or the model file's own input map (WithModelInputMap).
  std::string input_map;
  /// The range of valid measurements (MeasurementGuard; infinite = any
  /// finite value) and the input on a faulty sample (NaN = hold).
  double y_valid_min = -std::numeric_limits<double>::infinity();
  double y_valid_max = std::numeric_limits<double>::infinity();  ///< upper valid measurement
  double safe_input = std::numeric_limits<double>::quiet_NaN();  ///< input on faults (NaN = hold)
  /// Sigma-delta modulation over the actuator's input gaps, "LO:HI[,LO:HI]"
  /// (duty_modulator.hpp ParseInputGaps; IPA: "0:15,85:100"); empty = none.
  std::string input_gaps;
};

/// The tuning rule settings ask for: the named rule when `rule` is not empty;
/// otherwise explicit when P > 0, M > 0 and a finite lambda are all given,
/// else shridhar-cooper.
/// @throws InvalidArgument for an unknown rule name.
TuningRule InferTuningRule(const std::string& rule, int P, int M, double lambda);

/// The spec of `settings`: names parsed, the rule inferred, P, M and lambda
/// as overrides of the rule.
/// @throws InvalidArgument for an unknown controller, rule or PID rule name.
/// @throws DataError naming the file of an input map that cannot be read.
ControllerSpec ToControllerSpec(const ControllerSettings& settings);
/// `spec` with the input map of the model file `model_spec` (a Hammerstein
/// model's, models/model_file.hpp ParseModelInputMap) when it has none yet, its
/// output map (a Wiener model's, ParseModelOutputMap), or its NARX model
/// (narx_model, models/model_file.hpp ParseModelNarx).
/// @throws InvalidArgument for a NARX model together with an input map, or a
/// NARX model a controller cannot use (InputAffineNarx).
ControllerSpec WithModelInputMap(ControllerSpec spec, const std::string& model_spec);
/// The transfer function of a controller's --model: ParseModelSpec, or for a
/// NARX model file its linearization (gain and time constant) at the steady
/// state in the middle of its input map's range, a nominal description only:
/// the controller itself uses the NARX model (WithModelInputMap).
/// @throws as ParseModelSpec and ParseModelNarx.
TransferFunction ParseControllerModel(const std::string& model_spec);

/// A designed controller with the settings it was designed with.
struct BuiltController {
  /// The controller to run, wrapped in the input map, NARX or output map layers, if any.
  std::unique_ptr<Controller> controller;
  ControllerType type = ControllerType::kDmc;     ///< the type of the core controller
  TuningResult tuning;                            ///< horizons and lambda (dmc, gpc, mpc)
  PidTuningRule pid_rule = PidTuningRule::kSimc;  ///< (pid)
  PidGains pid_gains;                             ///< (pid)
  bool pid_explicit = false;  ///< (pid) some gains given explicitly (ControllerSpec::pid_kc ...)
  FopdtEstimate fopdt;        ///< the FOPDT the PID was tuned from (pid)
  double pid_kff = 0.0;       ///< (pid) velocity feed-forward Kff (0: none)
  /// (pid) set-point weight b of the proportional term (1 unless the rule
  /// auto chose another).
  double pid_setpoint_weight = 1.0;
  double pid_derivative_filter = 10.0;  ///< (pid) derivative filter N (Td / N)
  /// Rule "auto": the auto-tuner's message (what it met or why not).
  std::string auto_summary;
  /// Rule "auto": t_r, the response time it aimed at (given, from the
  /// model, or the fastest robust design's: AutoTuneResult::
  /// response_time_target); NaN for other rules.
  double auto_response_time = std::numeric_limits<double>::quiet_NaN();
  /// Rule "auto": t_r is the fastest robust design's (no response time given).
  bool auto_fastest = false;
  /// Rule "auto": the design met the specification on the model and on every
  /// robustness row (AutoTuneTermination::kConverged); false otherwise and
  /// for other rules.
  bool auto_converged = false;

  /// "pid" for a PID, "auto" for settings tuned to specifications, else the
  /// tuning rule's name (as in a comparison table).
  std::string Label() const;
  /// One line stating the design: the rule with P, M, lambda and its formula,
  /// or the PID rule, the FOPDT it used and the gains.
  std::string Summary() const;
  /// `settings` of `pneumid control --json`: {rule, P, M, lambda, formula}
  /// (dmc, gpc, mpc) or {Kc, Ti, Td, Kff, rule, b, N} (pid; Ti null when
  /// infinite; rule "auto" for the rule auto; b the set-point weight, N the
  /// derivative filter).
  nlohmann::ordered_json SettingsToJson() const;
};

/// Designs the controller from a sampled model (dmc and gpc use it as is; mpc
/// its state space, model.sampled_state_space() with the delay as states,
/// which equals SampledStateSpace(model.model(), model.Ts()); the rule auto
/// tunes on it, AutoTune(model, ...), whose candidates are built as here; pid
/// tunes from the FOPDT description of model.model()).
/// @throws InvalidArgument for invalid settings (messages name the setting).
BuiltController MakeController(const PredictionModel& model, const ControllerSpec& spec);
/// dmc, gpc, mpc: MakeController(PredictionModel(model, Ts), spec), the
/// design's one discretization; pid: from the FOPDT description of `model`.
/// @throws InvalidArgument for invalid settings (messages name the setting).
BuiltController MakeController(const TransferFunction& model, double Ts,
                               const ControllerSpec& spec);

}  // namespace pneumid
