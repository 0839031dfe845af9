// Bindings of identify/ipa_calibration.hpp and the IPA parameter table of
// plant/ipa_simulator.hpp: calibrate(), the grey-box identification of the IPA
// simulator's physical parameters from measured experiments (as `pneumid
// calibrate`), and the helpers to read, write and simulate parameter sets.
#include <cmath>
#include <fstream>
#include <map>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <fmt/format.h>
#include <pybind11/eigen.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include "bindings.hpp"
#include "pneumid/common/check.hpp"
#include "pneumid/identify/evaluation/fit_metrics.hpp"
#include "pneumid/identify/nonlinear/ipa_calibration.hpp"
#include "pneumid/plant/ipa_simulator.hpp"

namespace py = pybind11;
using namespace py::literals;

namespace pneumid::python {

namespace {

py::object Number(double v) { return std::isfinite(v) ? py::object(py::float_(v)) : py::none(); }

bool IsPath(const py::handle& obj) {
  return py::isinstance<py::str>(obj) ||
         py::isinstance(obj, py::module_::import("os").attr("PathLike"));
}

std::string PathOf(const py::handle& obj) {
  return py::module_::import("os").attr("fspath")(obj).cast<std::string>();
}

// Parameters from None (the built-in twin), a TOML path or a dict {name: value}
// over the built-in twin (names as FindIpaParameter accepts them; 'mode' and
// 'pwm_mode' take their strings).
IpaParameters ParametersFromPython(const py::handle& obj, const char* function,
                                   const char* argument) {
  IpaParameters p;
  if (obj.is_none()) return p;
  if (IsPath(obj)) return LoadIpaParameters(PathOf(obj));
  PNEUMID_CHECK(py::isinstance<py::dict>(obj),
                "{}: {} must be None, a TOML file path or a dict {{name: value}}", function,
                argument);
  for (const auto& [key, value] : obj.cast<py::dict>()) {
    const std::string name = py::str(key).cast<std::string>();
    if (name == "mode") {
      p.mode = IpaModeFromString(py::str(value).cast<std::string>());
    } else if (name == "pwm_mode") {
      p.pwm_mode = PwmModeFromString(py::str(value).cast<std::string>());
    } else {
      const IpaParameterInfo& info = FindIpaParameter(name);  // InvalidArgument when unknown
      double v = 0.0;
      try {
        v = value.cast<double>();
      } catch (const py::cast_error&) {
        throw InvalidArgument(
            fmt::format("{}: {}['{}'] must be a number", function, argument, name));
      }
      SetIpaParameter(p, info.key, v);
    }
  }
  return p;
}

// {key: value} of every parameter of the table, with 'mode' and 'pwm_mode'.
py::dict ParametersToPython(const IpaParameters& p) {
  py::dict d;
  d["mode"] = ToString(p.mode);
  d["pwm_mode"] = ToString(p.pwm_mode);
  for (const IpaParameterInfo& info : IpaParameterTable())
    d[py::str(info.key)] = GetIpaParameter(p, info.key);
  return d;
}

// Experiments as a list of Dataset or (name, Dataset); a Dataset is named by
// its source, else "experiment N" (validation: "validation N"). A single
// Dataset is a list of one.
std::vector<CalibrationExperiment> ExperimentsFromPython(const py::handle& obj,
                                                         const char* argument,
                                                         const char* default_name) {
  std::vector<CalibrationExperiment> out;
  if (obj.is_none()) return out;
  const py::handle dataset_type = py::type::of<Dataset>();
  py::list items;
  if (py::isinstance(obj, dataset_type)) {
    items.append(obj);  // a single experiment
  } else {
    PNEUMID_CHECK(py::isinstance<py::sequence>(obj) && !py::isinstance<py::str>(obj),
                  "calibrate: {} must be a list of Dataset or (name, Dataset) pairs", argument);
    for (const auto item : obj.cast<py::sequence>()) items.append(item);
  }
  for (const auto item : items) {
    CalibrationExperiment e;
    if (py::isinstance(item, dataset_type)) {
      e.data = item.cast<Dataset>();
    } else if (py::isinstance<py::tuple>(item) && py::len(item) == 2 &&
               py::isinstance(item.cast<py::tuple>()[1], dataset_type)) {
      e.name = py::str(item.cast<py::tuple>()[0]).cast<std::string>();
      e.data = item.cast<py::tuple>()[1].cast<Dataset>();
    } else {
      throw InvalidArgument(fmt::format(
          "calibrate: {}[{}] is neither a Dataset nor a (name, Dataset) pair", argument,
          out.size()));
    }
    if (e.name.empty())
      e.name = !e.data.source().empty() ? e.data.source()
                                        : fmt::format("{} {}", default_name, out.size() + 1);
    out.push_back(std::move(e));
  }
  return out;
}

void WriteText(const std::string& path, const std::string& text) {
  std::ofstream out(path);
  if (!out) throw DataError(fmt::format("{}: cannot open for writing", path));
  out << text;
  if (!out) throw DataError(fmt::format("{}: write failed", path));
}

}  // namespace

void BindCalibration(py::module_& m) {
  m.def(
      "ipa_parameter_table",
      [] {
        py::list l;
        for (const IpaParameterInfo& i : IpaParameterTable())
          l.append(py::dict("key"_a = i.key, "unit"_a = i.unit, "lower"_a = i.lower,
                            "upper"_a = i.upper, "calibratable"_a = i.calibratable));
        return l;
      },
      "The IPA simulator's floating-point parameters: [{'key', 'unit', 'lower', 'upper', "
      "'calibratable'}] with the physical range that bounds a calibration.");
  m.def(
      "load_ipa_parameters",
      [](const py::object& source) {
        return ParametersToPython(ParametersFromPython(source, "load_ipa_parameters", "source"));
      },
      "source"_a = py::none(),
      "IPA parameters as a dict {key: value, 'mode', 'pwm_mode'} from a TOML file (as "
      "--plant-config reads it), a dict of changes to the built-in twin, or None (the built-in "
      "twin).");
  m.def(
      "ipa_parameters_to_toml",
      [](const py::object& parameters, const std::string& comment) {
        return IpaParametersToToml(
            ParametersFromPython(parameters, "ipa_parameters_to_toml", "parameters"), comment);
      },
      "parameters"_a, "comment"_a = "",
      "The parameters (dict over the built-in twin, TOML path or None) as TOML text that "
      "--plant-config, make_plant('ipa:config=FILE') and load_ipa_parameters read back.");
  m.def(
      "simulate_ipa_on_data",
      [](const py::object& parameters, const Dataset& data, const std::string& initial_state,
         double warmup) {
        const IpaParameters p =
            ParametersFromPython(parameters, "simulate_ipa_on_data", "parameters");
        const CalibrationInitialState s = CalibrationInitialStateFromString(initial_state);
        py::gil_scoped_release release;
        return SimulateIpaOnData(p, data, s, warmup);
      },
      "parameters"_a, "data"_a, "initial_state"_a = "measured", "warmup"_a = 2.0,
      "Output of the noise-free IPA simulator with `parameters` (dict, TOML path or None) on "
      "the data's input, started as calibrate starts it ('measured' or 'steady').");
  m.def(
      "calibrate",
      [](const py::object& experiments, const py::object& start,
         std::optional<std::vector<std::string>> free,
         std::optional<std::map<std::string, std::pair<double, double>>> bounds,
         const std::string& initial_state, int max_iterations, int num_threads,
         const py::object& validation, std::optional<std::string> mode,
         std::optional<std::string> pwm_mode, const py::object& output) {
        IpaCalibrationOptions o;
        o.start = ParametersFromPython(start, "calibrate", "start");
        if (mode) o.start.mode = IpaModeFromString(*mode);
        if (pwm_mode) o.start.pwm_mode = PwmModeFromString(*pwm_mode);
        if (free) o.free = *free;
        if (bounds) o.bounds = *bounds;
        o.initial_state = CalibrationInitialStateFromString(initial_state);
        o.max_iterations = max_iterations;
        o.num_threads = num_threads;
        const std::vector<CalibrationExperiment> data =
            ExperimentsFromPython(experiments, "experiments", "experiment");
        const std::vector<CalibrationExperiment> held_out =
            ExperimentsFromPython(validation, "validation", "validation");
        const std::string output_path = output.is_none() ? std::string() : PathOf(output);

        IpaCalibrationSummary s;
        std::vector<Eigen::VectorXd> validation_sim;
        {
          py::gil_scoped_release release;
          s = CalibrateIpa(data, o);
          if (s.termination != Termination::kFailure)
            for (const CalibrationExperiment& v : held_out)
              validation_sim.push_back(SimulateIpaOnData(
                  s.parameters, v.data, o.initial_state, o.warmup, o.integration_tolerance));
        }

        py::dict parameters;
        for (const CalibratedParameter& e : s.estimates)
          parameters[py::str(e.name)] =
              py::dict("value"_a = e.value, "std"_a = Number(e.std), "unit"_a = e.unit,
                       "start"_a = e.start, "lower"_a = e.lower, "upper"_a = e.upper,
                       "determined"_a = e.determined, "at_bound"_a = e.at_bound);
        py::list fits;
        for (const CalibrationExperimentFit& e : s.experiments)
          fits.append(py::dict("name"_a = e.name, "samples"_a = e.samples,
                               "fit_percent"_a = Number(e.fit_percent),
                               "initial_fit_percent"_a = Number(e.initial_fit_percent),
                               "simulated"_a = e.simulated));
        py::list val;
        for (std::size_t i = 0; i < validation_sim.size(); ++i)
          val.append(py::dict("name"_a = held_out[i].name,
                              "samples"_a = held_out[i].data.size(),
                              "fit_percent"_a = Number(NrmseFit(held_out[i].data.y(0),
                                                                validation_sim[i])),
                              "simulated"_a = validation_sim[i]));
        py::list correlations;
        for (const ParameterCorrelation& c : s.correlations)
          correlations.append(py::dict("first"_a = c.first, "second"_a = c.second,
                                       "correlation"_a = c.correlation));

        // The twin as TOML, its comment naming the experiments and free parameters.
        std::string toml;
        if (s.termination != Termination::kFailure) {
          std::string comment = fmt::format(
              "IPA parameters calibrated by pneumid.calibrate ({}, {} iterations) from:",
              ToString(s.termination), s.iterations);
          for (const CalibrationExperimentFit& e : s.experiments)
            comment += fmt::format("\n  {} (fit {:.2f} %)", e.name, e.fit_percent);
          std::string names;
          for (const CalibratedParameter& e : s.estimates)
            names += (names.empty() ? "" : ", ") + e.name;
          comment += "\nfree parameters: " + names;
          toml = IpaParametersToToml(s.parameters, comment);
          if (!output_path.empty()) WriteText(output_path, toml);
        }
        return py::dict(
            "parameters"_a = parameters, "experiments"_a = fits, "validation"_a = val,
            "correlations"_a = correlations, "warnings"_a = s.warnings,
            "termination"_a = ToString(s.termination), "message"_a = s.message,
            "iterations"_a = s.iterations, "initial_cost"_a = Number(s.initial_cost),
            "final_cost"_a = Number(s.final_cost), "simulations"_a = s.simulations,
            "seconds"_a = s.seconds, "mode"_a = ToString(o.start.mode),
            "pwm_mode"_a = ToString(o.start.pwm_mode),
            "initial_state"_a = ToString(o.initial_state),
            "twin"_a = ParametersToPython(s.parameters),
            "toml"_a = toml.empty() ? py::object(py::none()) : py::object(py::str(toml)),
            "output"_a = toml.empty() || output_path.empty() ? py::object(py::none())
                                                             : py::object(py::str(output_path)));
      },
      "experiments"_a, "start"_a = py::none(), "free"_a = py::none(), "bounds"_a = py::none(),
      "initial_state"_a = "measured", "max_iterations"_a = 100, "num_threads"_a = 2,
      "validation"_a = py::none(), "mode"_a = py::none(), "pwm_mode"_a = py::none(),
      "output"_a = py::none(),
      "Calibrates the IPA simulator's physical parameters to measured experiments (grey-box "
      "output-error identification, as `pneumid calibrate`). experiments: [Dataset or (name, "
      "Dataset)], input 0 the PWM duty in %, output 0 the force in N (position mode: m). "
      "start: None (the built-in twin), a TOML path or a dict {name: value} over the built-in "
      "twin; free: parameter names (TOML keys or unique last parts such as 'bore'; None: the "
      "default set of the mode); bounds: {name: (lower, upper)} replacing physical ranges; "
      "initial_state 'measured' or 'steady'; validation: held-out experiments, scored and not "
      "used; mode/pwm_mode override the start's; output: path to write the twin's TOML to. "
      "Returns a dict: 'parameters' {name: {'value', 'std', 'unit', 'start', 'lower', 'upper', "
      "'determined', 'at_bound'}}, 'experiments' and 'validation' [{'name', 'samples', "
      "'fit_percent', 'initial_fit_percent' (experiments), 'simulated'}], 'correlations', "
      "'warnings', 'termination', 'message', 'iterations', costs, 'twin' (every parameter "
      "value), 'toml' (None on failure), 'output'. Raises InvalidArgument (a ValueError) for "
      "bad names, bounds or data (no excitation, ...); a numerical failure is "
      "termination 'failure' with the message.");
}

}  // namespace pneumid::python
