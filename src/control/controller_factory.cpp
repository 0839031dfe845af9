#include "pneumid/control/controller_factory.hpp"

#include <optional>

#include <cmath>
#include <limits>
#include <sstream>
#include <vector>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "pneumid/common/check.hpp"
#include "pneumid/common/spec.hpp"
#include "pneumid/control/dmc.hpp"
#include "pneumid/control/gpc.hpp"
#include "pneumid/control/inverse_map_controller.hpp"
#include "pneumid/control/mpc.hpp"
#include "pneumid/models/model_file.hpp"
#include "predictive_controller_design.hpp"

namespace pneumid {

TuningRule InferTuningRule(const std::string& rule, int P, int M, double lambda) {
  if (!rule.empty()) return TuningRuleFromString(rule);
  return P > 0 && M > 0 && std::isfinite(lambda) ? TuningRule::kExplicit
                                                 : TuningRule::kShridharCooper;
}

ControllerSpec ToControllerSpec(const ControllerSettings& settings) {
  ControllerSpec spec;
  spec.type = ControllerTypeFromString(settings.controller);
  spec.auto_tune = settings.rule == "auto";
  spec.tuning.rule = spec.auto_tune
                         ? TuningRule::kShridharCooper
                         : InferTuningRule(settings.rule, settings.P, settings.M, settings.lambda);
  spec.auto_options.response_time = settings.response_time;
  spec.auto_options.max_overshoot = settings.overshoot;
  spec.auto_options.aggressiveness = settings.aggressiveness;
  spec.auto_options.M = settings.M;
  spec.tuning.P = settings.P;
  spec.tuning.M = settings.M;
  spec.tuning.lambda = settings.lambda;
  spec.limits = settings.limits;
  spec.constrained = settings.constrained;
  spec.y_min = settings.y_min;
  spec.y_max = settings.y_max;
  spec.t_filter = settings.t_filter;
  spec.pid_rule = PidTuningRuleFromString(settings.pid_rule);
  spec.tau_c = settings.tau_c;
  spec.pid_kc = settings.pid_kc;
  spec.pid_ti = settings.pid_ti;
  spec.pid_td = settings.pid_td;
  spec.pid_kff = settings.pid_kff;
  spec.disturbance = DisturbanceModelFromString(settings.disturbance);
  spec.measurement_noise = settings.measurement_noise;
  spec.state_noise = settings.state_noise;
  spec.disturbance_noise = settings.disturbance_noise;
  spec.auto_options.disturbance = spec.disturbance;
  if (!settings.input_map.empty()) spec.input_map = ReadStaticMap(settings.input_map);
  spec.guard.y_min = settings.y_valid_min;
  spec.guard.y_max = settings.y_valid_max;
  spec.guard.safe_input = settings.safe_input;
  std::string error;
  PNEUMID_CHECK(spec.guard.IsValid(&error), "{}", error);
  PNEUMID_CHECK(std::isnan(settings.safe_input) || (settings.safe_input >= settings.limits.u_min &&
                                                    settings.safe_input <= settings.limits.u_max),
                "the safe input {} lies outside the input limits [{}, {}] (--safe-input, "
                "--u-min, --u-max)",
                settings.safe_input, settings.limits.u_min, settings.limits.u_max);
  spec.input_gaps = ParseInputGaps(settings.input_gaps);
  return spec;
}

ControllerSpec WithModelInputMap(ControllerSpec spec, const std::string& model_spec) {
  if (std::optional<NarxWithMap> n = ParseModelNarx(model_spec)) {
    PNEUMID_CHECK(!spec.input_map,
                  "{}: a NARX model brings its own input map; --input-map does not apply",
                  model_spec);
    spec.narx_model = InputAffineNarx(n->narx, n->input_map);
    return spec;
  }
  if (!spec.input_map) spec.input_map = ParseModelInputMap(model_spec);
  if (!spec.output_map) spec.output_map = ParseModelOutputMap(model_spec);
  return spec;
}

TransferFunction ParseControllerModel(const std::string& model_spec) {
  const std::optional<NarxWithMap> n = ParseModelNarx(model_spec);
  if (!n) return ParseModelSpec(model_spec);
  const InputAffineNarx m(n->narx, n->input_map);
  double lo = n->input_map ? n->input_map->u_min() : 0.0;
  double hi = n->input_map ? n->input_map->u_max() : 1.0;
  const double mid = 0.5 * (lo + hi), h = 0.01 * (hi - lo);
  const double y0 = m.SteadyOutput(mid - h), y1 = m.SteadyOutput(mid + h, y0);
  const double K = (y1 - y0) / (2.0 * h);
  const double tau = m.TypicalTimeConstant(mid - h, mid + h);
  PNEUMID_CHECK(std::isfinite(K) && std::isfinite(tau) && tau > 0.0,
                "{}: the NARX model has no stable steady state at u = {:g}", model_spec, mid);
  return TransferFunction::Fopdt(K, tau, 0.0);
}

std::string BuiltController::Label() const {
  if (type == ControllerType::kPid) return "pid";
  return auto_summary.empty() ? ToString(tuning.rule) : "auto";
}

std::string BuiltController::Summary() const {
  const std::string tail = auto_summary.empty() ? "" : "; auto: " + auto_summary;
  if (type == ControllerType::kPid && !auto_summary.empty())
    return fmt::format("pid auto from FOPDT K={:g} tau={:g} theta={:g}: Kc={:g} Ti={:g} Td={:g}{}",
                       fopdt.K, fopdt.tau, fopdt.theta, pid_gains.Kc, pid_gains.Ti, pid_gains.Td,
                       tail);
  const std::string ff = pid_kff != 0.0 ? fmt::format(" Kff={:g}", pid_kff) : "";
  if (type == ControllerType::kPid && pid_explicit && !std::isfinite(fopdt.K))
    return fmt::format("pid with gains given on an integrating model: Kc={:g} Ti={:g} Td={:g}{}",
                       pid_gains.Kc, pid_gains.Ti, pid_gains.Td, ff);
  if (type == ControllerType::kPid && pid_explicit)
    return fmt::format(
        "pid with gains given (the others by {} from FOPDT K={:g} tau={:g} theta={:g}): Kc={:g} "
        "Ti={:g} Td={:g}{}",
        ToString(pid_rule), fopdt.K, fopdt.tau, fopdt.theta, pid_gains.Kc, pid_gains.Ti,
        pid_gains.Td, ff);
  if (type == ControllerType::kPid)
    return fmt::format(
        "pid {} from FOPDT K={:g} tau={:g} theta={:g} ({}): Kc={:g} Ti={:g} Td={:g}{}",
        ToString(pid_rule), fopdt.K, fopdt.tau, fopdt.theta, fopdt.method, pid_gains.Kc,
        pid_gains.Ti, pid_gains.Td, ff);
  return fmt::format("{}: P={} M={} lambda={:g}; {}{}", ToString(tuning.rule), tuning.P, tuning.M,
                     tuning.lambda, tuning.formula, tail);
}

nlohmann::ordered_json BuiltController::SettingsToJson() const {
  nlohmann::ordered_json j;
  if (type == ControllerType::kPid) {
    j["Kc"] = pid_gains.Kc;
    j["Ti"] = std::isfinite(pid_gains.Ti) ? nlohmann::json(pid_gains.Ti) : nlohmann::json();
    j["Td"] = pid_gains.Td;
    j["Kff"] = pid_kff;
    j["rule"] = pid_explicit          ? std::string("explicit")
                : !auto_summary.empty() ? std::string("auto")
                                        : ToString(pid_rule);
    j["b"] = pid_setpoint_weight;
    j["N"] = pid_derivative_filter;
  } else {
    // Settings tuned to specifications say so (their tuning result is explicit).
    j["rule"] = auto_summary.empty() ? ToString(tuning.rule) : std::string("auto");
    j["P"] = tuning.P;
    j["M"] = tuning.M;
    j["lambda"] = tuning.lambda;
    j["formula"] = tuning.formula;
  }
  return j;
}

namespace {

// dmc (QDMC when constrained) with the tuning of spec.
BuiltController MakeDmc(const PredictionModel& model, const ControllerSpec& spec) {
  BuiltController b;
  b.tuning = Tune(model, spec.tuning);
  DmcOptions o;
  o.P = b.tuning.P;
  o.M = b.tuning.M;
  o.lambda = b.tuning.lambda;
  o.limits = spec.limits;
  o.constrained = spec.constrained;
  o.y_min = spec.y_min;
  o.y_max = spec.y_max;
  b.controller = std::make_unique<DmcController>(model, o);
  return b;
}

// gpc with N1 = 1, N2 = P, Nu = M and the T filter of spec.
BuiltController MakeGpc(const PredictionModel& model, const ControllerSpec& spec) {
  PNEUMID_CHECK(!spec.constrained,
                "the constrained form is implemented for dmc (QDMC) and mpc; gpc clips its "
                "input");
  BuiltController b;
  b.tuning = Tune(model, spec.tuning);
  GpcOptions o;
  o.N1 = 1;
  o.N2 = b.tuning.P;
  o.Nu = b.tuning.M;
  o.lambda = b.tuning.lambda;
  o.limits = spec.limits;
  if (spec.t_filter == "A" || spec.t_filter == "a") {
    o.t_equals_a = true;
  } else if (spec.t_filter != "1" && !spec.t_filter.empty()) {
    // '1', 'A' or coefficients such as '1 -0.8'.
    const std::vector<double> coef = ParseNumberList("T filter", spec.t_filter);
    o.t_polynomial = Eigen::Map<const Eigen::VectorXd>(coef.data(), coef.size());
  }
  b.controller = std::make_unique<GpcController>(model, o);
  return b;
}

// The state-space mpc on the design's sampled state space.
BuiltController MakeMpc(const PredictionModel& model, const ControllerSpec& spec) {
  BuiltController b;
  b.tuning = Tune(model, spec.tuning);
  MpcOptions o;
  o.P = b.tuning.P;
  o.M = b.tuning.M;
  o.lambda = b.tuning.lambda;
  o.limits = spec.limits;
  o.y_min = spec.y_min;
  o.y_max = spec.y_max;
  o.disturbance = spec.disturbance;
  if (!std::isnan(spec.measurement_noise)) o.measurement_noise = spec.measurement_noise;
  if (!std::isnan(spec.state_noise)) o.state_noise = spec.state_noise;
  if (!std::isnan(spec.disturbance_noise)) o.disturbance_noise = spec.disturbance_noise;
  b.controller = std::make_unique<MpcController>(model, o);
  return b;
}

}  // namespace

BuiltController internal::MakePredictiveController(const PredictionModel& model,
                                                   const ControllerSpec& spec) {
  PNEUMID_CHECK(!spec.auto_tune && !spec.input_map && !spec.output_map && !spec.narx_model,
                "MakePredictiveController: resolve the rule auto and the model's maps first");
  BuiltController b;
  switch (spec.type) {
    case ControllerType::kDmc:
      b = MakeDmc(model, spec);
      break;
    case ControllerType::kGpc:
      b = MakeGpc(model, spec);
      break;
    case ControllerType::kMpc:
      b = MakeMpc(model, spec);
      break;
    case ControllerType::kPid:
      PNEUMID_CHECK(false, "MakePredictiveController builds dmc, gpc or mpc, not pid");
  }
  b.type = spec.type;
  b.pid_rule = spec.pid_rule;
  return b;
}

bool internal::AutoTunedDmcIsConstrained(const InputLimits& limits, bool constrained) {
  return constrained || std::isfinite(limits.u_min) || std::isfinite(limits.u_max) ||
         std::isfinite(limits.du_max);
}

namespace {

BuiltController BuildController(const TransferFunction& model, double Ts,
                                const ControllerSpec& spec);
BuiltController BuildController(const PredictionModel& model, const ControllerSpec& spec);

// The gains of `spec` given explicitly replace the rule's in `gains`; true
// when any was given.
bool ApplyExplicitPidGains(const ControllerSpec& spec, PidGains& gains) {
  bool any = false;
  if (!std::isnan(spec.pid_kc)) {
    PNEUMID_CHECK(std::isfinite(spec.pid_kc) && spec.pid_kc != 0.0,
                  "Kc must be finite and non-zero, got {}", spec.pid_kc);
    gains.Kc = spec.pid_kc;
    any = true;
  }
  if (!std::isnan(spec.pid_ti)) {
    PNEUMID_CHECK(spec.pid_ti > 0.0, "Ti must be positive (inf: no integral action), got {}",
                  spec.pid_ti);
    gains.Ti = spec.pid_ti;
    any = true;
  }
  if (!std::isnan(spec.pid_td)) {
    PNEUMID_CHECK(std::isfinite(spec.pid_td) && spec.pid_td >= 0.0,
                  "Td must be finite and >= 0, got {}", spec.pid_td);
    gains.Td = spec.pid_td;
    any = true;
  }
  return any;
}

// The velocity feed-forward given in `spec` (not NaN), checked finite.
double ExplicitKff(const ControllerSpec& spec) {
  PNEUMID_CHECK(std::isfinite(spec.pid_kff), "Kff must be finite, got {}", spec.pid_kff);
  return spec.pid_kff;
}

// The velocity gain Ki = lim_{s->0} s G(s) of a model with one pole at s = 0
// (z = 1), in output units per second per input unit; NaN for other models.
// Continuous G = B(s)/(s A'(s)): Ki = B(0)/A'(0). Discrete, in q = z^-1:
// A(q) = (1 - q) A'(q), so A'(1) = -dA/dq(1) and Ki = B(1)/(A'(1) Ts).
double VelocityGain(const TransferFunction& model) {
  const Eigen::VectorXd& b = model.num();
  const Eigen::VectorXd& a = model.den();
  const double nan = std::numeric_limits<double>::quiet_NaN();
  if (model.IsContinuous()) {
    const Eigen::Index n = a.size();
    if (n < 2 || a(n - 1) != 0.0 || a(n - 2) == 0.0) return nan;
    return b(b.size() - 1) / a(n - 2);
  }
  const double scale = a.cwiseAbs().sum();
  if (std::abs(a.sum()) > 1e-12 * scale) return nan;
  double da = 0.0;
  for (Eigen::Index k = 1; k < a.size(); ++k) da -= static_cast<double>(k) * a(k);
  if (std::abs(da) <= 1e-12 * scale) return nan;
  return b.sum() / (da * model.Ts());
}

// The auto-tuner's specification of `spec`: auto_options with the options
// of the controller that will run (type, limits, dmc: the constrained form,
// mpc: the disturbance model and the Kalman filter's noises), so that its
// candidates are that controller.
AutoTuneOptions AutoTuneOptionsOf(const ControllerSpec& spec) {
  PNEUMID_CHECK(spec.type != ControllerType::kGpc,
                "--rule auto tunes mpc, dmc and pid; for gpc give a tuning rule");
  AutoTuneOptions o = spec.auto_options;
  o.controller = spec.type;
  o.limits = spec.limits;
  o.constrained = spec.constrained;
  o.disturbance = spec.disturbance;
  o.measurement_noise = spec.measurement_noise;
  o.state_noise = spec.state_noise;
  o.disturbance_noise = spec.disturbance_noise;
  return o;
}

// The spec's tuning replaced by the auto-tuner's design (rule "auto").
AutoTuneResult AutoTuned(const TransferFunction& model, double Ts, const ControllerSpec& spec) {
  return AutoTune(model, Ts, AutoTuneOptionsOf(spec));
}

// The same on the design's sampled model (mpc, dmc: no second sampling).
AutoTuneResult AutoTuned(const PredictionModel& model, const ControllerSpec& spec) {
  return AutoTune(model, AutoTuneOptionsOf(spec));
}

}  // namespace

namespace {

// The controller of `spec` without its input map, designed by `make` on the
// linear part with the map's image of the limits, behind the map's inverse.
template <typename Make>
BuiltController WithInverseMap(const ControllerSpec& spec, Make make) {
  const StaticMap map = InvertibleInputMap(MapThroughGaps(*spec.input_map, spec.input_gaps));
  ControllerSpec inner = spec;
  inner.input_map.reset();
  inner.limits = InnerLimits(map, spec.limits);
  BuiltController b = make(inner);
  b.controller = std::make_unique<InverseMapController>(std::move(b.controller), map, spec.limits);
  return b;
}

// The controller of `spec` designed on the reference model of its NARX
// model's linearization, behind the linearization.
BuiltController WithNarxLinearization(const ControllerSpec& spec, double Ts) {
  const InputAffineNarx& narx = *spec.narx_model;
  PNEUMID_CHECK(!spec.input_map,
                "a NARX model brings its own input map; --input-map does not apply");
  PNEUMID_CHECK(std::abs(Ts - narx.Ts()) <= 1e-9 * narx.Ts(),
                "the NARX model was identified at Ts = {} s; the controller runs at {} s",
                narx.Ts(), Ts);
  const double tau = ReferenceTimeConstant(narx, spec.limits, spec.narx_options);
  ControllerSpec inner = spec;
  inner.narx_model.reset();
  inner.limits = NarxInnerLimits(narx, spec.limits);
  // --rule auto without a response time: the actuator's typical speed (the
  // fastest robust design on H trusts the linearization more than a fitted
  // model deserves at the ends of the range).
  if (inner.auto_tune && !std::isfinite(inner.auto_options.response_time))
    inner.auto_options.response_time = tau;
  BuiltController b = BuildController(TransferFunction::Fopdt(1.0, tau, 0.0), Ts, inner);
  b.controller =
      std::make_unique<NarxLinearizingController>(std::move(b.controller), narx, tau, spec.limits);
  return b;
}

// The controller of `spec` without its output map, made by `make`, on the
// output map's inverse.
template <typename Make>
BuiltController WithOutputMap(const ControllerSpec& spec, Make make) {
  ControllerSpec inner = spec;
  inner.output_map.reset();
  BuiltController b = make(inner);
  b.controller = std::make_unique<OutputMapController>(std::move(b.controller), *spec.output_map);
  return b;
}

// `model` scaled to a unit static gain: behind the inverse map the map holds
// the actuator's gain and the linear part only the dynamics.
TransferFunction UnitGain(const TransferFunction& model) {
  const double K = model.DcGain();
  PNEUMID_CHECK(std::isfinite(K) && K != 0.0,
                "a controller behind an input map needs a model with a finite nonzero static "
                "gain, got {}",
                K);
  return TransferFunction(model.num() / K, model.den(), model.Ts(), model.delay());
}

BuiltController BuildController(const TransferFunction& model, double Ts,
                                const ControllerSpec& spec) {
  if (spec.narx_model) return WithNarxLinearization(spec, Ts);
  if (spec.output_map)
    return WithOutputMap(spec,
                         [&](const ControllerSpec& s) { return BuildController(model, Ts, s); });
  if (spec.input_map) {
    const TransferFunction g = UnitGain(model);
    return WithInverseMap(spec, [&](const ControllerSpec& s) { return BuildController(g, Ts, s); });
  }
  if (spec.auto_tune && spec.type == ControllerType::kPid) {
    PNEUMID_CHECK(std::isnan(spec.pid_kc) && std::isnan(spec.pid_ti) && std::isnan(spec.pid_td),
                  "explicit PID gains (Kc, Ti, Td) do not apply to the rule auto, which designs "
                  "them; give a rule (simc, imc) or leave the gains out");
    const AutoTuneResult a = AutoTuned(model, Ts, spec);
    BuiltController b;
    b.type = spec.type;
    b.pid_rule = spec.pid_rule;
    b.fopdt = FopdtFromModel(model);
    b.pid_gains = a.pid;
    b.auto_summary = a.message;
    b.auto_response_time = a.response_time_target;
    b.auto_fastest = a.fastest;
    b.auto_converged = a.termination == AutoTuneTermination::kConverged;
    PidOptions o;
    o.gains = a.pid;
    o.setpoint_weight = b.pid_setpoint_weight = a.setpoint_weight;
    o.derivative_filter = b.pid_derivative_filter = a.derivative_filter;
    if (!std::isnan(spec.pid_kff)) o.velocity_feedforward = b.pid_kff = ExplicitKff(spec);
    o.limits = spec.limits;
    b.controller = std::make_unique<PidController>(Ts, o);
    return b;
  }
  // A PID is tuned from the continuous FOPDT description; it needs no sampled
  // model. An integrating or unstable model has none: then the gains are given.
  if (spec.type == ControllerType::kPid) {
    BuiltController b;
    b.type = spec.type;
    b.pid_rule = spec.pid_rule;
    if (model.IsStable()) {
      b.fopdt = FopdtFromModel(model);
      b.pid_gains = TunePid(b.fopdt.K, b.fopdt.tau, b.fopdt.theta, Ts, spec.pid_rule, spec.tau_c);
    } else {
      PNEUMID_CHECK(!std::isnan(spec.pid_kc),
                    "the model {} is integrating or unstable: it has no FOPDT description to "
                    "tune a PID from; give the gains (Kc, and Ti, Td if wanted)",
                    model.ToString());
      b.fopdt = FopdtEstimate{};
      b.fopdt.K = b.fopdt.tau = b.fopdt.theta = std::numeric_limits<double>::quiet_NaN();
      b.fopdt.method = "none (integrating or unstable model)";
      b.pid_gains = PidGains{};  // no integral, no derivative; Kc from the spec below
    }
    b.pid_explicit = ApplyExplicitPidGains(spec, b.pid_gains);
    if (!std::isnan(spec.pid_kff)) {
      b.pid_kff = ExplicitKff(spec);
    } else if (const double ki = VelocityGain(model); std::isfinite(ki) && ki != 0.0) {
      b.pid_kff = 1.0 / ki + b.pid_gains.Kc * b.pid_gains.Td;
    }
    PidOptions o;
    o.gains = b.pid_gains;
    o.velocity_feedforward = b.pid_kff;
    o.limits = spec.limits;
    b.controller = std::make_unique<PidController>(Ts, o);
    return b;
  }
  return BuildController(PredictionModel(model, Ts), spec);
}

BuiltController BuildController(const PredictionModel& model, const ControllerSpec& spec_in) {
  if (spec_in.narx_model) return WithNarxLinearization(spec_in, model.Ts());
  if (spec_in.output_map)
    return WithOutputMap(spec_in,
                         [&](const ControllerSpec& s) { return BuildController(model, s); });
  if (spec_in.input_map) {
    const PredictionModel unit(UnitGain(model.model()), model.Ts());
    return WithInverseMap(spec_in,
                          [&](const ControllerSpec& s) { return BuildController(unit, s); });
  }
  // A PID needs no sampled model (tuned from the FOPDT description or by the
  // auto-tuner's loop shaping).
  if (spec_in.type == ControllerType::kPid)
    return BuildController(model.model(), model.Ts(), spec_in);
  if (!spec_in.auto_tune) return internal::MakePredictiveController(model, spec_in);
  // The rule auto: the auto-tuner's P, M and lambda as explicit settings, on
  // the same sampled model; its candidates were built by the same function
  // with the same options: a dmc with a finite limit is the QDMC the tuner
  // evaluated, not a clipping dmc.
  const AutoTuneResult a = AutoTuned(model, spec_in);
  ControllerSpec spec = spec_in;
  spec.auto_tune = false;
  spec.tuning.rule = TuningRule::kExplicit;
  spec.tuning.P = a.P;
  spec.tuning.M = a.M;
  spec.tuning.lambda = a.lambda;
  const bool qdmc_for_limits = spec.type == ControllerType::kDmc && !spec.constrained &&
                               internal::AutoTunedDmcIsConstrained(spec.limits, spec.constrained);
  if (qdmc_for_limits) spec.constrained = true;
  BuiltController b = internal::MakePredictiveController(model, spec);
  b.auto_summary = a.message;
  b.auto_response_time = a.response_time_target;
  b.auto_fastest = a.fastest;
  b.auto_converged = a.termination == AutoTuneTermination::kConverged;
  b.tuning = a.ToTuningResult();
  if (qdmc_for_limits)
    b.tuning.formula +=
        "; QDMC (moves optimized under the input limits), as the tuner evaluated it";
  return b;
}

}  // namespace

// The guard goes on the outermost controller only: behind an output map the
// inner controller sees g^-1(y), and behind an input map its input is v.
// So does the modulator over the input gaps: it acts on the input that
// reaches the actuator.
namespace {
BuiltController WithOuterLayers(BuiltController b, const ControllerSpec& spec) {
  if (!spec.input_gaps.empty())
    b.controller = std::make_unique<ModulatedController>(std::move(b.controller), spec.input_gaps,
                                                         spec.limits);
  b.controller->SetMeasurementGuard(spec.guard);
  return b;
}
}  // namespace

BuiltController MakeController(const TransferFunction& model, double Ts,
                               const ControllerSpec& spec) {
  return WithOuterLayers(BuildController(model, Ts, spec), spec);
}

BuiltController MakeController(const PredictionModel& model, const ControllerSpec& spec) {
  return WithOuterLayers(BuildController(model, spec), spec);
}

}  // namespace pneumid
