// Bindings of the plant and control areas, frequency responses and block
// diagrams.
#include <optional>

#include <pybind11/eigen.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <utility>
#include <variant>

#include <fmt/format.h>

#include "bindings.hpp"
#include "pneumid/common/check.hpp"
#include "pneumid/control/closed_loop.hpp"
#include "pneumid/control/controller_factory.hpp"
#include "pneumid/control/tuning.hpp"
#include "pneumid/lti/frequency.hpp"
#include "pneumid/lti/interconnect.hpp"
#include "pneumid/plant/actuator.hpp"
#include "pneumid/plant/experiment.hpp"
#include "pneumid/plant/plant.hpp"
#include "pneumid/plant/plant_factory.hpp"
#include "pneumid/plant/signal.hpp"
#include "pneumid/workflow/commission.hpp"
#include "pneumid/workflow/commission_files.hpp"
#include "pneumid/workflow/control_scenario.hpp"
#include "pneumid/workflow/tune_workflow.hpp"

namespace py = pybind11;
using namespace py::literals;

namespace pneumid::python {

namespace {

// Controller settings from make_controller's and simulate_control's keyword
// arguments, as `pneumid control` and `pneumid run` read them.
ControllerSettings Settings(const std::string& type, const std::string& rule, int M, int P,
                            double lambda, double u_min, double u_max, bool constrained, double Kc,
                            double Ti, double Td, double Kff, const std::string& disturbance,
                            const std::string& input_gaps) {
  ControllerSettings s;
  s.controller = type;
  s.rule = rule;
  s.M = M;
  s.P = P;
  s.lambda = lambda;
  s.limits.u_min = u_min;
  s.limits.u_max = u_max;
  s.constrained = constrained;
  s.pid_kc = Kc;
  s.pid_ti = Ti;
  s.pid_td = Td;
  s.pid_kff = Kff;
  s.disturbance = disturbance;
  s.input_gaps = input_gaps;
  return s;
}

// make_controller's settings keywords (with its defaults) as ControllerSettings,
// for functions that take them as **kwargs. @throws InvalidArgument naming an
// unknown keyword.
ControllerSettings SettingsFromKeywords(const py::kwargs& keywords) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  auto get = [&keywords](const char* key, auto fallback) {
    using T = decltype(fallback);
    return keywords.contains(key) ? keywords[key].cast<T>() : fallback;
  };
  const std::vector<std::string> known = {"type",  "rule",  "M",           "P",         "lambda_",
                                          "u_min", "u_max", "constrained", "Kc",        "Ti",
                                          "Td",    "Kff",   "disturbance", "input_gaps"};
  for (const auto& item : keywords) {
    const std::string key = py::str(item.first);
    PNEUMID_CHECK(std::find(known.begin(), known.end(), key) != known.end(),
                  "unknown controller setting '{}' (settings: {})", key, fmt::join(known, ", "));
  }
  return Settings(get("type", std::string("dmc")), get("rule", std::string("shridhar-cooper")),
                  get("M", 0), get("P", 0), get("lambda_", nan), get("u_min", -inf),
                  get("u_max", inf), get("constrained", false), get("Kc", nan), get("Ti", nan),
                  get("Td", nan), get("Kff", nan), get("disturbance", std::string("input")),
                  get("input_gaps", std::string()));
}

// TuningResult::ToJson (as `pneumid tune --json`), plus the keys earlier
// versions had for every rule: K, tau, theta (= fopdt), lambda_condition,
// lambda_formula, P_unrounded, tau_used (None when the rule does not use them).
py::dict TuningToDict(const TuningResult& t) {
  py::dict d = JsonToPython(t.ToJson());
  const bool fopdt = t.rule == TuningRule::kShridharCooper;
  auto number = [](double v) { return std::isfinite(v) ? py::object(py::float_(v)) : py::none(); };
  for (const auto& [key, value] : {std::pair<const char*, double>{"K", fopdt ? t.fopdt.K : NAN},
                                   {"tau", fopdt ? t.fopdt.tau : NAN},
                                   {"theta", fopdt ? t.fopdt.theta : NAN},
                                   {"lambda_condition", t.lambda_condition},
                                   {"lambda_formula", t.lambda_formula},
                                   {"P_unrounded", fopdt ? t.P_unrounded : NAN},
                                   {"tau_used", fopdt ? t.tau_used : NAN}}) {
    if (!d.contains(key)) d[key] = number(value);
  }
  return d;
}

// ClosedLoopMetrics::ToJson (as `pneumid control --json`): None for a metric
// that does not exist in the run.
py::dict MetricsToDict(const ClosedLoopMetrics& m) { return JsonToPython(m.ToJson()); }

}  // namespace

void BindExtras(py::module_& m) {
  // --- frequency responses and block diagrams (lti) -------------------------
  m.def("log_space", &LogSpace, "lo"_a, "hi"_a, "n"_a, "n points from 10^lo to 10^hi.");
  m.def(
      "bode",
      [](const TransferFunction& g, const std::optional<Eigen::VectorXd>& omega) {
        // None: an automatic grid; an explicit array must hold frequencies.
        if (omega) RequireNonEmpty(omega->size(), "bode", "omega");
        const BodeData b = Bode(g, omega.value_or(Eigen::VectorXd()));
        return py::dict("omega"_a = b.omega, "magnitude"_a = b.magnitude,
                        "magnitude_db"_a = b.magnitude_db, "phase_deg"_a = b.phase_deg);
      },
      "g"_a, "omega"_a = py::none(),
      "Frequency response: dict of omega [rad/s], magnitude, magnitude_db, phase_deg "
      "(omega None: an automatic grid).");
  m.def(
      "compute_margins",
      [](const TransferFunction& g) {
        const Margins mg = ComputeMargins(g);
        return py::dict("gain_margin"_a = mg.gain_margin, "gain_margin_db"_a = mg.gain_margin_db,
                        "phase_crossover"_a = mg.phase_crossover,
                        "phase_margin"_a = mg.phase_margin, "gain_crossover"_a = mg.gain_crossover);
      },
      "g"_a, "Gain and phase margins of the open loop g (dict).");
  m.def("series", &Series, "g1"_a, "g2"_a, "g2 * g1 (delays add).");
  m.def("parallel", &Parallel, "g1"_a, "g2"_a, "g1 + g2.");
  m.def("feedback", &Feedback, "g"_a, "h"_a = TransferFunction(), "sign"_a = -1,
        "g / (1 - sign g h); negative feedback by default.");
  m.def("minimal_realization", &MinimalRealization, "g"_a, "tol"_a = 1e-6,
        "g without its pole-zero pairs closer than tol (relative to max(1, |pole|)), like "
        "MATLAB minreal; the high-frequency gain is kept. Raises InvalidArgument for tol < 0.");

  // --- plants and experiments ----------------------------------------------
  py::class_<Plant>(m, "Plant",
                    "A sampled plant: the IPA simulator or a linear model. Per sample: "
                    "y = measure(); advance(u).")
      .def("reset", &Plant::Reset,
           "Back to the initial state at time 0: noise generators to their seed, no load "
           "disturbance.")
      .def("measure", &Plant::Measure, "Measured output now (sensor model included).")
      .def("advance", &Plant::Advance, "u"_a, "Holds u for one sample period (zero-order hold).",
           py::call_guard<py::gil_scoped_release>())
      .def("set_load_disturbance", &Plant::SetLoadDisturbance, "d"_a,
           "Load disturbance d added to the measured output (output units: N in force mode), "
           "held until changed; reset() clears it.")
      .def_property_readonly("Ts", &Plant::Ts, "Sample period [s].")
      .def_property_readonly("time", &Plant::time, "Current time [s] since reset().")
      .def("extras", &Plant::Extras, "Extra signals, e.g. chamber pressures.")
      .def("describe", &Plant::Describe,
           "Short description for logs, e.g. 'ipa (force mode, pwm 50 Hz)'.")
      .def("__repr__", [](const Plant& p) { return "<Plant " + p.Describe() + ">"; });
  m.def(
      "make_plant",
      [](const std::string& spec, double Ts, std::uint64_t seed, std::optional<double> noise,
         const std::string& config_path) {
        PlantOptions o;
        o.seed = seed;
        o.noise_sigma = noise;
        o.config_path = config_path;
        return MakePlant(spec, Ts, o);
      },
      "spec"_a = "ipa", "Ts"_a = 0.01, "seed"_a = 1, "noise_sigma"_a = py::none(),
      "config_path"_a = "",
      "Plant by name: 'ipa' (IPA simulator, force mode, input duty %), 'ipa-position', "
      "'ipa:config=FILE.toml', or any model spec (linear plant).");
  m.def(
      "run_experiment",
      [](Plant& plant, const std::string& signal, double duration) {
        const auto s = ParseSignal(signal);
        py::gil_scoped_release release;
        return RunExperiment(plant, *s, duration).data;
      },
      "plant"_a, "signal"_a, "duration"_a,
      "Drives the plant with a signal spec ('step:from=0.61,to=82,at=0.5', "
      "'prbs:low=20,high=80,order=7,clock=0.05', ...) and returns the Dataset.");

  // --- tuning, controllers and closed loops -------------------------------
  m.def(
      "tune",
      [](const TransferFunction& model, double Ts, const std::string& rule, int M, int P,
         double lambda) {
        TuningOptions o;
        o.rule = TuningRuleFromString(rule);
        o.M = M;
        o.P = P;
        o.lambda = lambda;
        return TuningToDict(Tune(model, Ts, o));
      },
      "model"_a, "Ts"_a, "rule"_a = "shridhar-cooper", "M"_a = 0, "P"_a = 0,
      "lambda_"_a = std::numeric_limits<double>::quiet_NaN(),
      "Horizons and move suppression: rule 'shridhar-cooper' (conventional), "
      "'paper-modified' or 'explicit' (dict with P, M, lambda, formula).");
  m.def(
      "tune_json",
      [](const std::variant<std::string, TransferFunction>& model, double Ts,
         const std::string& rule, int M, int P, double lambda, int tau_digits,
         const std::string& controller, double response_time, const std::string& measure,
         double overshoot, double aggressiveness, double u_min, double u_max, double du_max,
         const std::string& plant) {
        TuneWorkflowOptions o;
        o.Ts = Ts;
        o.rule = rule;
        o.M = M;
        o.P = P;
        o.lambda = lambda;
        o.tau_digits = tau_digits;
        o.controller = controller;
        o.response_time = response_time;
        o.measure = measure;
        o.overshoot = overshoot;
        o.aggressiveness = aggressiveness;
        o.u_min = u_min;
        o.u_max = u_max;
        o.du_max = du_max;
        o.plant = plant;
        std::string text;
        {
          py::gil_scoped_release release;
          if (const auto* spec = std::get_if<std::string>(&model)) {
            o.model = *spec;
            text = RunTuneWorkflow(o).ToJson().dump();
          } else {
            text = RunTuneWorkflow(o, std::get<TransferFunction>(model)).ToJson().dump();
          }
        }
        return py::module_::import("json").attr("loads")(text);
      },
      "model"_a, "Ts"_a, "rule"_a = "shridhar-cooper", "M"_a = 0, "P"_a = 0,
      "lambda_"_a = std::numeric_limits<double>::quiet_NaN(), "tau_digits"_a = 2,
      "controller"_a = "", "response_time"_a = std::numeric_limits<double>::quiet_NaN(),
      "measure"_a = "", "overshoot"_a = std::numeric_limits<double>::quiet_NaN(),
      "aggressiveness"_a = std::numeric_limits<double>::quiet_NaN(),
      "u_min"_a = -std::numeric_limits<double>::infinity(),
      "u_max"_a = std::numeric_limits<double>::infinity(),
      "du_max"_a = std::numeric_limits<double>::infinity(), "plant"_a = "",
      "The tuning of `pneumid tune --json` (workflow/tune_workflow.hpp): model a spec "
      "('fopdt-paper', 'FILE.json#fit-p1d', ...) or a TransferFunction; rule "
      "'shridhar-cooper', 'paper-modified', 'explicit' or 'auto' (then controller 'mpc', 'dmc' "
      "or 'pid', response_time, measure 'rise'|'settling', overshoot, aggressiveness, input "
      "limits u_min, u_max, du_max, and a plant spec whose input range bounds the design; NaN "
      "or empty: the command's defaults). Returns the dict `tune --json` prints.");
  py::class_<Controller>(m, "Controller", "A sampled controller (DMC, GPC, PID, MPC).")
      .def("reset", &Controller::Reset, "u0"_a = 0.0, "y0"_a = 0.0,
           "Back to rest at an operating point: input u0 applied long enough for the output to "
           "settle at y0 (plant units, e.g. duty % and N). Clears last_fault and fault_count.")
      .def("update", &Controller::Update, "setpoint"_a, "measurement"_a,
           "One control step; returns the input to hold over the next period. A NaN or "
           "infinite measurement or set-point, or a measurement outside the guard's range, "
           "leaves the controller's state untouched and returns the last valid input (or the "
           "guard's safe input); last_fault and fault_count say so.")
      .def("applied", &Controller::Applied, "u"_a,
           "The input actually applied after the last update (anti-windup); NaN is ignored.")
      .def(
          "set_measurement_guard",
          [](Controller& c, double y_min, double y_max, double safe_input) {
            MeasurementGuard g;
            g.y_min = y_min;
            g.y_max = y_max;
            g.safe_input = safe_input;
            c.SetMeasurementGuard(g);
          },
          "y_min"_a = -std::numeric_limits<double>::infinity(),
          "y_max"_a = std::numeric_limits<double>::infinity(),
          "safe_input"_a = std::numeric_limits<double>::quiet_NaN(),
          "Measurements outside [y_min, y_max] are faults; safe_input (NaN: hold the last "
          "input) is applied on a faulty sample.")
      .def_property_readonly(
          "last_fault", [](const Controller& c) { return ToString(c.last_fault()); },
          "'none', 'measurement-not-finite', 'measurement-out-of-range', "
          "'setpoint-not-finite' or 'output-not-finite'")
      .def_property_readonly("fault_count", &Controller::fault_count,
                             "Faulty samples since the last reset.")
      .def_property_readonly("last_input", &Controller::last_input,
                             "The input of the last update() or applied() (the held input on a "
                             "fault; u0 after reset).")
      .def_property_readonly("Ts", &Controller::Ts, "Sample period [s].")
      .def("describe", &Controller::Describe,
           "Short description, e.g. 'dmc P=126 M=5 lambda=2.25'.")
      .def("__repr__", [](const Controller& c) { return "<Controller " + c.Describe() + ">"; });
  m.def(
      "make_controller",
      [](const TransferFunction& model, double Ts, const std::string& type, const std::string& rule,
         int M, int P, double lambda, double u_min, double u_max, bool constrained, double Kc,
         double Ti, double Td, double Kff, const std::string& disturbance,
         const std::string& input_gaps) {
        const ControllerSettings s = Settings(type, rule, M, P, lambda, u_min, u_max, constrained,
                                              Kc, Ti, Td, Kff, disturbance, input_gaps);
        BuiltController b = MakeController(model, Ts, ToControllerSpec(s));
        return std::move(b.controller);
      },
      "model"_a, "Ts"_a, "type"_a = "dmc", "rule"_a = "shridhar-cooper", "M"_a = 0, "P"_a = 0,
      "lambda_"_a = std::numeric_limits<double>::quiet_NaN(),
      "u_min"_a = -std::numeric_limits<double>::infinity(),
      "u_max"_a = std::numeric_limits<double>::infinity(), "constrained"_a = false,
      "Kc"_a = std::numeric_limits<double>::quiet_NaN(),
      "Ti"_a = std::numeric_limits<double>::quiet_NaN(),
      "Td"_a = std::numeric_limits<double>::quiet_NaN(),
      "Kff"_a = std::numeric_limits<double>::quiet_NaN(), "disturbance"_a = "input",
      "input_gaps"_a = "",
      "Controller of type 'dmc', 'gpc', 'pid' or 'mpc' designed from `model` at Ts, with the "
      "settings of `pneumid control`: PID gains Kc, Ti, Td and velocity feed-forward Kff (NaN: "
      "the rule's; an integrating model needs Kc and gets Kff = 1/Ki + Kc Td), the MPC "
      "disturbance model, and input gaps 'LO:HI[,LO:HI]' to modulate across.");
  m.def(
      "simulate_control",
      [](const std::string& model, const std::string& plant, double Ts, const std::string& setpoint,
         double duration, const std::vector<std::pair<double, double>>& load_steps, double noise,
         std::uint64_t seed, const std::vector<std::string>& compare, const py::kwargs& settings) {
        ControlScenarioOptions o;
        o.model = model;
        o.plant = plant;
        o.Ts = Ts;
        o.setpoint = setpoint;
        o.duration = duration;
        for (const auto& [at, size] : load_steps) o.load_steps.push_back({at, size});
        o.noise = noise;
        o.seed = seed;
        o.compare_rules = compare;
        o.controller = SettingsFromKeywords(settings);
        std::string text;
        std::vector<std::string> warnings;
        {
          py::gil_scoped_release release;
          ControlScenarioResult result = RunControlScenario(o);
          text = result.ToJson().dump();
          warnings = std::move(result.warnings);
        }
        // What `pneumid control` says on stderr: Python warnings (UserWarning).
        for (const std::string& w : warnings)
          if (PyErr_WarnEx(PyExc_UserWarning, w.c_str(), 1) != 0) throw py::error_already_set();
        return py::module_::import("json").attr("loads")(text);
      },
      "model"_a, "plant"_a = "", "Ts"_a = 0.01, "setpoint"_a, "duration"_a,
      "load_steps"_a = std::vector<std::pair<double, double>>{}, "noise"_a = 0.0, "seed"_a = 1,
      "compare"_a = std::vector<std::string>{},
      "The closed-loop scenario of `pneumid control` (workflow/control_scenario.hpp): a "
      "controller designed from the model spec, run against the plant spec (empty: the model) "
      "through the set-point spec with load_steps = [(at_s, size), ...]; compare = rule names "
      "runs one per rule. Returns the dict `pneumid control --json` prints (the same numbers); "
      "what `control` warns of on stderr (a set-point beyond the model's reach) is a "
      "UserWarning. "
      "Controller settings are the keywords of make_controller after `Ts` (type, rule, M, P, "
      "lambda_, u_min, u_max, constrained, Kc, Ti, Td, Kff, disturbance, input_gaps), with its "
      "defaults; input limits left open take the plant's range.");
  m.def(
      "simulate_closed_loop",
      [](Controller& controller, Plant& plant, const std::string& setpoint, double duration,
         const std::vector<std::pair<double, double>>& load_steps, double noise_std, double u_min,
         double u_max, double u0, std::uint64_t seed) {
        const auto sp = ParseSignal(setpoint);
        ClosedLoopOptions o;
        o.duration = duration;
        for (const auto& [at, size] : load_steps) o.load_steps.push_back({at, size});
        o.noise_std = noise_std;
        o.actuator.u_min = u_min;
        o.actuator.u_max = u_max;
        o.u0 = u0;
        o.seed = seed;
        ClosedLoopResult r;
        {
          py::gil_scoped_release release;
          r = SimulateClosedLoop(controller, plant, *sp, o);
        }
        return py::dict("t"_a = r.t, "r"_a = r.r, "y"_a = r.y, "y_meas"_a = r.y_meas, "u"_a = r.u,
                        "d"_a = r.d, "metrics"_a = MetricsToDict(r.metrics),
                        "controller"_a = r.controller, "plant"_a = r.plant);
      },
      "controller"_a, "plant"_a, "setpoint"_a, "duration"_a,
      "load_steps"_a = std::vector<std::pair<double, double>>{}, "noise_std"_a = 0.0,
      "u_min"_a = -std::numeric_limits<double>::infinity(),
      "u_max"_a = std::numeric_limits<double>::infinity(), "u0"_a = 0.0, "seed"_a = 1,
      "Closed loop of controller and plant through a set-point signal spec; load_steps = "
      "[(at_s, size), ...]. Returns t, r, y, u, ... and metrics (dict).");
  m.def(
      "commission",
      [](Plant& plant, const std::string& directory, std::optional<std::pair<double, double>> range,
         double budget, const std::string& controller, double overshoot, double settling,
         double aggressiveness, std::optional<std::vector<std::string>> methods,
         std::optional<double> u_min, std::optional<double> u_max, bool modulate,
         std::uint64_t seed, std::optional<std::string> plant_spec) {
        CommissionOptions o;
        if (range) {
          o.range_min = range->first;
          o.range_max = range->second;
        }
        o.budget = budget;
        o.controller = controller;
        o.overshoot = overshoot;
        o.settling = settling;
        o.aggressiveness = aggressiveness;
        if (methods) o.methods = *methods;
        if (u_min) o.u_min = *u_min;
        if (u_max) o.u_max = *u_max;
        o.modulate = modulate;
        o.directory = directory;
        o.seed = seed;
        CommissionResult r;
        CommissionFiles files;
        {
          py::gil_scoped_release release;
          r = Commission(plant, o);
          if (plant_spec) {
            CommissionFilesOptions fo;
            fo.directory = directory;
            fo.Ts = plant.Ts();
            fo.plant = *plant_spec;
            fo.plant_description = plant.Describe();
            files = WriteCommissionFiles(r, PlantActuator(plant), fo);
          }
        }
        py::dict d = JsonToPython(r.ToJson());
        if (plant_spec) d["files"] = JsonToPython(files.ToJson());
        d["data"] = py::cast(r.experiment.data);
        if (!r.attempts.empty()) {
          const ClosedLoopResult& cl = r.attempts.back().result;
          d["trace"] =
              py::dict("t"_a = cl.t, "r"_a = cl.r, "y"_a = cl.y, "u"_a = cl.u, "d"_a = cl.d);
        }
        return d;
      },
      "plant"_a, "directory"_a, "range"_a = py::none(), "budget"_a = 120.0, "controller"_a = "mpc",
      "overshoot"_a = 5.0, "settling"_a = 0.5, "aggressiveness"_a = 0.5, "methods"_a = py::none(),
      "u_min"_a = py::none(), "u_max"_a = py::none(), "modulate"_a = true, "seed"_a = 1,
      "plant_spec"_a = py::none(),
      "From a plant to a verified controller, as `pneumid commission` (docs/commission.md): a "
      "probe step, a sweep of the reachable range, a shuffled multi-level excitation with a "
      "held-out part, models ranked on it, a design to the specification (overshoot in %, "
      "settling in s) and a closed-loop verification across `range` (lo, hi in output units; "
      "None = the reachable range less 5 % at each end) on the plant. `budget` is the plant "
      "time in s of the experiment and the verification runs of the first design and the "
      "redesigns (12 levels of max(1, 2 settling) s each); u_min/u_max default to the plant's "
      "input range (IPA 0..100 "
      "%, needed for a linear plant). models.json goes to `directory` (which must exist). "
      "Returns the dict of `commission --json` (termination, message, experiment, models, "
      "chosen_model, controller, verification, passed, limits, suggestions, plant_time) with "
      "'data' (the experiment as a Dataset) and 'trace' (the verification's t, r, y, u, d "
      "arrays). With `plant_spec` (the plant's spec as make_plant takes it, for controller.toml's "
      "[io] plant) the files of `pneumid commission -o DIR` are written too (data.csv, "
      "controller.toml, verification.csv, figures, the C module in c/; 'files' lists them). "
      "Raises InvalidArgument for invalid settings.");
}

}  // namespace pneumid::python
