// Bindings of the identify and report areas.
#include <optional>
#include <string>
#include <variant>
#include <vector>

#include <pybind11/eigen.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include "bindings.hpp"
#include "pneumid/common/check.hpp"
#include "pneumid/data/preprocess.hpp"
#include "pneumid/data/preprocess_io.hpp"
#include "pneumid/identify/evaluation/fit_metrics.hpp"
#include "pneumid/identify/evaluation/initial_state.hpp"
#include "pneumid/identify/evaluation/model_evaluation.hpp"
#include "pneumid/identify/identified_model.hpp"
#include "pneumid/identify/identified_model_io.hpp"
#include "pneumid/identify/identify.hpp"
#include "pneumid/identify/step/step_analysis.hpp"
#include "pneumid/identify/step/step_methods.hpp"
#include "pneumid/report/figures.hpp"
#include "pneumid/report/identification_report.hpp"
#include "pneumid/report/paper.hpp"
#include "pneumid/report/plot.hpp"
#include "pneumid/workflow/identify_workflow.hpp"

namespace py = pybind11;
using namespace py::literals;

namespace pneumid::python {

namespace {

std::vector<NamedModel> ToNamed(const std::vector<std::pair<std::string, TransferFunction>>& v) {
  std::vector<NamedModel> out;
  for (const auto& [label, g] : v) out.push_back({label, g});
  return out;
}

// {name: float | int | list}, as the JSON form.
py::dict ParamsToPython(const ModelParams& params) {
  py::dict d;
  for (const auto& [name, value] : params) {
    d[py::str(name)] = std::visit([](const auto& v) { return py::cast(v); }, value);
  }
  return d;
}

void SaveFigure(const Figure& fig, const std::string& path) {
  py::gil_scoped_release release;
  fig.Save(path);
}

// The channels and orders of identify() and identify_models().
IdentifyRequest MakeRequest(int input, int output, int order, int na, int nb, int nk, int nc,
                            int nd, int nf) {
  IdentifyRequest r;
  r.input = input;
  r.output = output;
  r.order = order;
  r.na = na;
  r.nb = nb;
  r.nk = nk;
  r.nc = nc;
  r.nd = nd;
  r.nf = nf;
  return r;
}

PreprocessOptions PythonPreprocessOptions(const std::string& window, double resample,
                                          bool remove_initial, const std::string& detrend,
                                          const std::string& filter, int decimate) {
  PreprocessOptions o;
  if (!window.empty()) o.window = TimeWindow::Parse(window);
  o.resample_ts = resample;
  o.remove_initial = remove_initial;
  o.detrend = DetrendKindFromString(detrend);
  if (!filter.empty()) o.filter = FilterSpec::Parse(filter);
  o.decimate = decimate;
  std::string why;
  PNEUMID_CHECK(o.IsValid(&why), "{}", why);
  return o;
}

}  // namespace

void BindIdentify(py::module_& m) {
  py::class_<IdentifiedModel>(m, "IdentifiedModel",
                              "Result of an identification method: named parameters, the "
                              "model, its fit to the data.")
      .def_readonly("method", &IdentifiedModel::method,
                    "Identification method, e.g. 'reaction-curve', 'fit-p1d', 'arx'.")
      .def_readonly("structure", &IdentifiedModel::structure,
                    "Model structure, e.g. 'FOPDT', 'PTn', 'P2D', 'ARX'.")
      .def_property_readonly(
          "params", [](const IdentifiedModel& r) { return ParamsToPython(r.params); },
          "Named parameters (dict), e.g. {'K': 1.6, 'tau': 0.245, 'theta': 0.001}.")
      .def_property_readonly(
          "param_std", [](const IdentifiedModel& r) { return ParamsToPython(r.param_std); },
          "Standard deviations of the parameters where known (dict with the names of params; "
          "empty when the method gives none).")
      .def_readonly("tf", &IdentifiedModel::tf, "Model (continuous when it exists).")
      .def_readonly("discrete", &IdentifiedModel::discrete,
                    "Discrete form of polynomial models, else None.")
      .def_property_readonly(
          "continuous_form",
          [](const IdentifiedModel& m) -> std::optional<std::string> {
            if (!m.continuous_form) return std::nullopt;
            return ToString(*m.continuous_form);
          },
          "How tf derives from discrete: 'zoh' (exact), 'tustin' (no zoh equivalent; the "
          "model is used in discrete form), 'none' (tf is the discrete model); None for "
          "models estimated in continuous time.")
      .def_readonly("fit_percent", &IdentifiedModel::fit_percent, "NRMSE fit [%].")
      .def_readonly("iae", &IdentifiedModel::iae, "Integrated absolute error [units s].")
      .def_readonly("notes", &IdentifiedModel::notes,
                    "Warnings of the method (list of str): poor excitation, not converged, ...")
      .def_readonly("u0", &IdentifiedModel::u0,
                    "Operating point: the model predicts y0 + G (u - u0) (simulate_model).")
      .def_readonly("y0", &IdentifiedModel::y0,
                    "Output level of the operating point (output units); see u0.")
      .def_property_readonly(
          "termination", [](const IdentifiedModel& r) { return ToString(r.termination); },
          "How the estimator ended: 'convergence', 'no_convergence', ...")
      .def_readonly("validation_fit_percent", &IdentifiedModel::validation_fit_percent,
                    "NRMSE fit [%] on held-out data (identify_models), NaN when none.")
      .def_readonly("determined_fit_percent", &IdentifiedModel::determined_fit_percent,
                    "NRMSE fit on the held-out samples outside the input intervals the "
                    "estimation data leave undetermined, which the ranking uses when the "
                    "held-out data visit them (NaN otherwise)")
      .def_property_readonly(
          "flags",
          [](const IdentifiedModel& r) {
            py::list l;
            for (const ModelFlagNote& f : r.flags)
              l.append(py::dict("flag"_a = ToString(f.flag), "reason"_a = f.reason));
            return l;
          },
          "Reasons not to trust the model: [{'flag': 'nyquist_pole', 'reason': ...}, ...].")
      .def_property_readonly(
          "rank_reason", [](const IdentifiedModel& r) { return RankReason(r); },
          "One line on why the model stands where it does in identify_models' ranking.")
      .def_property_readonly(
          "preprocessing",
          [](const IdentifiedModel& r) -> py::object {
            if (!r.preprocessing) return py::none();
            return JsonToPython(ToJson(*r.preprocessing));
          },
          "The preprocessing of the estimation data (dict), or None.")
      .def_property_readonly(
          "covariance",
          [](const IdentifiedModel& r) -> py::object {
            if (!r.covariance) return py::none();
            return py::dict("names"_a = r.covariance->names, "matrix"_a = r.covariance->matrix);
          },
          "Parameter covariance {'names': [...], 'matrix': ndarray} (names of params, e.g. "
          "a1, b1), or None (model_uncertainty: step_response_std, bode_std).")
      .def_property_readonly(
          "input_map",
          [](const IdentifiedModel& r) -> py::object {
            return r.input_map ? py::cast(*r.input_map) : py::none();
          },
          "StaticMap of a static-map, Hammerstein or Hammerstein-Wiener model, or None.")
      .def_property_readonly(
          "output_map",
          [](const IdentifiedModel& r) -> py::object {
            return r.output_map ? py::cast(*r.output_map) : py::none();
          },
          "StaticMap of a Wiener or Hammerstein-Wiener model, or None.")
      .def_readonly("input_map_undetermined", &IdentifiedModel::input_map_undetermined,
                    "Input intervals [(lo, hi), ...] between neighbouring levels of the "
                    "estimation data across which the input map changes steeply with no "
                    "sample inside: the data leave the map undetermined there.")
      .def_readonly("structure_chosen_on", &IdentifiedModel::structure_chosen_on,
                    "The held-out record a structure search chose the orders, delay, degree "
                    "or terms on (e.g. 'the last 30 % of est.csv'); '' when they were given "
                    "or chosen on a split of the estimation data.")
      .def_property_readonly(
          "narx",
          [](const IdentifiedModel& r) -> py::object {
            return r.narx ? JsonToPython(ToJson(*r.narx)) : py::none();
          },
          "NARX model {'terms', 'theta', 'err', ...} (narx.hpp), or None.")
      .def(
          "to_dict", [](const IdentifiedModel& r) { return JsonToPython(ToJson(r)); },
          "The JSON form of `pneumid identify --json`.")
      .def("__repr__", [](const IdentifiedModel& r) {
        return "<IdentifiedModel " + r.method + " " + r.structure + ": " + r.tf.ToString(5) + ">";
      });

  m.def("identify_methods", &IdentifyMethodNames,
        "Names of the identification methods (as `pneumid identify --method`).");
  m.def(
      "identify",
      [](const std::string& method, const Dataset& data, int input, int output, int order, int na,
         int nb, int nk, int nc, int nd, int nf, bool feedthrough, const std::string& n4sid_weight,
         const std::string& operating_point) {
        IdentifyRequest r = MakeRequest(input, output, order, na, nb, nk, nc, nd, nf);
        r.feedthrough = feedthrough;
        r.n4sid_weight = SubspaceWeightingFromString(n4sid_weight);
        r.operating_point = OperatingPointKindFromString(operating_point);
        py::gil_scoped_release release;
        return Identify(method, data, r);
      },
      "method"_a, "data"_a, "input"_a = 0, "output"_a = 0, "order"_a = 2, "na"_a = 3, "nb"_a = 3,
      "nk"_a = 1, "nc"_a = 1, "nd"_a = 1, "nf"_a = 3, "feedthrough"_a = false,
      "n4sid_weight"_a = "moesp", "operating_point"_a = "auto",
      "Identifies a model of data with a method of identify_methods(): e.g. "
      "'reaction-curve' (FOPDT, paper Eq. 2), 'ptn' (PTn of order `order`, Eq. 3), 'arx' "
      "(ARX(na, nb, nk), Eq. 4); 'n4sid' (order na, D term when `feedthrough`, weighting "
      "`n4sid_weight` 'moesp', 'n4sid' or 'cva'). `operating_point` ('auto', 'zero', 'mean', "
      "'initial') sets the levels u0, y0 the polynomial and subspace models are identified "
      "around (auto: zero for a record starting at rest at zero, else the raw signals or the "
      "means, "
      "whichever simulates the data better). Raises DataError when the data do not suit the "
      "method.");
  m.def(
      "preprocess",
      [](const Dataset& data, const std::string& window, double resample, bool remove_initial,
         const std::string& detrend, const std::string& filter, int decimate) {
        const PreprocessOptions o =
            PythonPreprocessOptions(window, resample, remove_initial, detrend, filter, decimate);
        PreprocessRecord record;
        Dataset out;
        {
          py::gil_scoped_release release;
          out = Preprocess(data, o, &record);
        }
        return py::make_tuple(out, JsonToPython(ToJson(record)));
      },
      "data"_a, "window"_a = "", "resample"_a = 0.0, "remove_initial"_a = false,
      "detrend"_a = "none", "filter"_a = "", "decimate"_a = 1,
      "Preprocesses data as the command-line flags do (window 'T0:T1', resample Ts, "
      "remove_initial, detrend 'constant'|'linear', filter 'lowpass:F'|'bandpass:F1,F2', "
      "decimate N), in that order. Returns (dataset, record) with record the dict stored in "
      "model files.");
  m.def(
      "identify_models",
      [](const std::vector<std::string>& methods, const Dataset& data, int input, int output,
         int order, std::optional<int> na, std::optional<int> nb, std::optional<int> nk, int nc,
         int nd, int nf, double split, std::optional<Dataset> validation,
         const std::string& window, double resample, bool remove_initial,
         const std::string& detrend, const std::string& filter, int decimate,
         const std::string& operating_point) {
        const IdentifyRequest defaults;
        IdentifyRequest r = MakeRequest(input, output, order, na.value_or(defaults.na),
                                        nb.value_or(defaults.nb), nk.value_or(defaults.nk), nc,
                                        nd, nf);
        r.operating_point = OperatingPointKindFromString(operating_point);
        IdentifyOptions o;
        o.split = split;
        // As `pneumid identify -m`: without na, nb, nk the nonlinear structures
        // (hammerstein, wiener, hw, narx) are chosen on the held-out data.
        o.nonlinear.choose_structure = !na && !nb && !nk;
        const PreprocessOptions p =
            PythonPreprocessOptions(window, resample, remove_initial, detrend, filter, decimate);
        IdentificationSummary s;
        {
          py::gil_scoped_release release;
          PreprocessRecord record;
          const Dataset d = Preprocess(data, p, &record);
          std::optional<Dataset> v;
          if (validation) v = ApplyRecorded(*validation, record);
          s = IdentifyModels(methods, d, r, o, v ? &*v : nullptr);
          if (!record.IsIdentity())
            for (IdentifiedModel& m : s.models) m.preprocessing = record;
        }
        py::list failures;
        for (const auto& [method, reason] : s.failures)
          failures.append(py::dict("method"_a = method, "reason"_a = reason));
        return py::dict("models"_a = s.models, "failures"_a = failures,
                        "best"_a = s.models.empty() ? py::object(py::none())
                                                    : py::cast(s.models.front().method),
                        "termination"_a = ToString(s.termination), "message"_a = s.message,
                        "warnings"_a = s.warnings);
      },
      "methods"_a, "data"_a, "input"_a = 0, "output"_a = 0, "order"_a = 2, "na"_a = py::none(),
      "nb"_a = py::none(), "nk"_a = py::none(), "nc"_a = 1, "nd"_a = 1, "nf"_a = 3, "split"_a = 0.0,
      "validation"_a = py::none(),
      "window"_a = "", "resample"_a = 0.0, "remove_initial"_a = false, "detrend"_a = "none",
      "filter"_a = "", "decimate"_a = 1, "operating_point"_a = "auto",
      "Runs several methods as `pneumid identify -m` does: each fails alone, models are "
      "flagged and ranked (unflagged first; by validation fit with `split` or `validation` "
      "data). na, nb, nk default to 3, 3, 1 for the linear methods; when none of them is "
      "given the nonlinear structures are chosen on the held-out data, as the command does. Returns {'models': [IdentifiedModel, best first], 'failures': [{'method', "
      "'reason'}], 'best', 'termination', 'message', 'warnings': [what the held-out part cannot "
      "tell, e.g. a constant input]}.");
  m.def(
      "identify_json",
      [](const Dataset& data, const std::variant<std::string, std::vector<std::string>>& methods,
         int input, int output, int order, std::optional<int> na, std::optional<int> nb,
         std::optional<int> nk, int nc, int nd, int nf, bool feedthrough,
         const std::string& n4sid_weight, const std::string& operating_point,
         const std::string& loss, double split, std::optional<Dataset> validation,
         const std::string& window, double resample, bool remove_initial,
         const std::string& detrend, const std::string& filter, int decimate,
         std::optional<int> knots, bool monotone_map, std::optional<double> settle,
         std::optional<double> min_segment, std::optional<int> degree, std::optional<int> max_terms,
         std::optional<double> err_tolerance, const std::string& focus) {
        IdentifyWorkflowOptions o;
        if (const auto* list = std::get_if<std::vector<std::string>>(&methods)) {
          std::string joined;
          for (const std::string& name : *list) joined += (joined.empty() ? "" : ",") + name;
          o.methods = joined;
        } else {
          o.methods = std::get<std::string>(methods);
        }
        o.preprocess.window = window;
        o.preprocess.resample = resample;
        o.preprocess.remove_initial = remove_initial;
        o.preprocess.detrend = detrend;
        o.preprocess.filter = filter;
        o.preprocess.decimate = decimate;
        IdentifyRequest& r = o.request;
        r.input = input;
        r.output = output;
        r.order = order;
        if (na) r.na = *na;
        if (nb) r.nb = *nb;
        if (nk) r.nk = *nk;
        r.nc = nc;
        r.nd = nd;
        r.nf = nf;
        r.feedthrough = feedthrough;
        r.n4sid_weight = SubspaceWeightingFromString(n4sid_weight);
        r.operating_point = OperatingPointKindFromString(operating_point);
        o.loss = loss;
        o.split = split;
        // As `pneumid identify`: without na, nb, nk the nonlinear structures are chosen.
        o.nonlinear.choose_structure = !na && !nb && !nk;
        if (knots) o.nonlinear.block.num_knots = *knots;
        o.nonlinear.block.monotone_map = monotone_map;
        if (settle) o.nonlinear.static_map.settle_fraction = *settle;
        if (min_segment) o.nonlinear.static_map.min_segment_duration = *min_segment;
        if (degree) o.nonlinear.narx.degree = *degree;
        if (max_terms) {
          o.nonlinear.narx.max_terms = *max_terms;
          o.nonlinear.max_narx_terms = *max_terms;
        }
        if (err_tolerance) o.nonlinear.narx.err_tolerance = *err_tolerance;
        o.nonlinear.narx.focus = NarxFocusFromString(focus);
        std::string text;
        {
          py::gil_scoped_release release;
          const IdentifyWorkflowResult result =
              RunIdentifyWorkflow(o, data, validation ? &*validation : nullptr);
          if (result.summary.models.empty()) throw DataError(result.summary.message);
          text = result.ToJson().dump();
        }
        return py::module_::import("json").attr("loads")(text);
      },
      "data"_a, "methods"_a = "auto", "input"_a = 0, "output"_a = 0, "order"_a = 2,
      "na"_a = py::none(), "nb"_a = py::none(), "nk"_a = py::none(), "nc"_a = 1, "nd"_a = 1,
      "nf"_a = 3, "feedthrough"_a = false, "n4sid_weight"_a = "moesp", "operating_point"_a = "auto",
      "loss"_a = "none", "split"_a = 0.0, "validation"_a = py::none(), "window"_a = "",
      "resample"_a = 0.0, "remove_initial"_a = false, "detrend"_a = "none", "filter"_a = "",
      "decimate"_a = 1, "knots"_a = py::none(), "monotone_map"_a = false, "settle"_a = py::none(),
      "min_segment"_a = py::none(), "degree"_a = py::none(), "max_terms"_a = py::none(),
      "err_tolerance"_a = py::none(), "focus"_a = "prediction",
      "The identification of `pneumid identify DATA --json` (workflow/identify_workflow.hpp): "
      "methods as a list or the --method text ('fit-p1d,arx', 'all', 'auto': the default, as the "
      "command's), the flags' settings by "
      "their names (na, nb, nk None as when the flags are not given: hammerstein, wiener, hw "
      "and narx then choose their structure; knots, settle, min_segment, degree, max_terms, "
      "err_tolerance None: the command's defaults; focus 'prediction' or 'simulation' as "
      "--focus). Returns the dict `identify --json` prints "
      "(the model file: 'models' best first, 'best', 'ranked_by', 'failures', 'termination', "
      "...). Raises DataError when no method produced a model.");
  m.def(
      "simulate_model",
      [](const IdentifiedModel& model, const Dataset& data, int input) {
        py::gil_scoped_release release;
        return SimulateModel(model, data, input);
      },
      "model"_a, "data"_a, "input"_a = 0,
      "Output of an identified model on the data's input: y0 + G (u - u0), as identify, "
      "validate and the report compute it.");
  m.def(
      "simulate_on_data",
      [](const TransferFunction& g, const Dataset& data, int input, int output, double y0) {
        py::gil_scoped_release release;
        return SimulateOnData(g, data, input, output, y0);
      },
      "g"_a, "data"_a, "input"_a = 0, "output"_a = 0,
      "y0"_a = std::numeric_limits<double>::quiet_NaN(),
      "Model output on the data's input in deviation variables: y0 + lsim(g, u - u0).");
  m.def("nrmse_fit", &NrmseFit, "y"_a, "yhat"_a, "NRMSE fit [%] (MATLAB compare).");
  m.def("estimate_initial_state", &EstimateInitialState, "sys"_a, "u"_a, "y"_a,
        "Least-squares initial state of the discrete StateSpace sys for input u (N x nu) and "
        "output y (N x ny) (MATLAB findstates).");
  m.def("simulate_from_state", &SimulateFromState, "sys"_a, "u"_a, "x0"_a,
        "Output (N x ny) of the discrete StateSpace sys from initial state x0 for input u.");
  m.def("rmse", &Rmse, "y"_a, "yhat"_a,
        "Root mean square error of yhat against y (output units). Raises InvalidArgument when "
        "the sizes differ, y is empty or a value is not finite.");
  m.def(
      "analyze_step",
      [](const Dataset& data, int input, int output) {
        const StepAnalysis s = AnalyzeStep(data, input, output);
        return py::dict("step_time"_a = s.step_time, "Ts"_a = s.Ts, "u0"_a = s.u0, "u1"_a = s.u1,
                        "du"_a = s.du, "y0"_a = s.y0, "y_final"_a = s.y_final, "dy"_a = s.dy,
                        "gain"_a = s.gain, "noise_std"_a = s.noise_std,
                        "departure_time"_a = s.departure_time, "t"_a = s.t, "r"_a = s.r);
      },
      "data"_a, "input"_a = 0, "output"_a = 0,
      "Step analysis (baseline, final value, gain, noise) as a dict.");
}

void BindReport(py::module_& m) {
  m.def(
      "residual_correlation",
      [](const Eigen::VectorXd& e, const Eigen::VectorXd& u, int max_lag, double confidence) {
        const ResidualCorrelation c = ComputeResidualCorrelation(e, u, max_lag, confidence);
        return py::dict("auto_lags"_a = c.auto_lags, "autocorr"_a = c.autocorr,
                        "cross_lags"_a = c.cross_lags, "crosscorr"_a = c.crosscorr,
                        "bound"_a = c.bound, "confidence"_a = c.confidence);
      },
      "residuals"_a, "input"_a, "max_lag"_a = 25, "confidence"_a = 0.99,
      "Normalized residual auto- and cross-correlations with the confidence bound.");
  m.def(
      "plot_step_responses",
      [](const std::vector<std::pair<std::string, TransferFunction>>& models,
         const std::string& path, double amplitude, double t_final, const std::string& title) {
        StepFigureOptions o;
        o.amplitude = amplitude;
        o.t_final = t_final;
        o.title = title;
        SaveFigure(StepResponseFigure(ToNamed(models), o), path);
      },
      "models"_a, "path"_a, "amplitude"_a = 1.0, "t_final"_a = 0.0, "title"_a = "Step response",
      "Step responses of [(label, model), ...] (paper Fig. 4) to a PNG or SVG file.");
  m.def(
      "plot_model_comparison",
      [](const Dataset& data, const std::vector<std::pair<std::string, TransferFunction>>& models,
         const std::string& path, const std::string& title) {
        ComparisonFigureOptions o;
        o.title = title;
        SaveFigure(ModelComparisonFigure(data, ToNamed(models), o), path);
      },
      "data"_a, "models"_a, "path"_a, "title"_a = "Model comparison",
      "Measured data and models simulated on its input (paper Fig. 5).");
  m.def(
      "plot_bode",
      [](const std::vector<std::pair<std::string, TransferFunction>>& models,
         const std::string& path) { SaveFigure(BodeFigure(ToNamed(models)), path); },
      "models"_a, "path"_a, "Bode diagram of [(label, model), ...].");
  m.def(
      "plot_residuals",
      [](const Eigen::VectorXd& e, const Eigen::VectorXd& u, const std::string& path, int max_lag) {
        SaveFigure(ResidualFigure(ComputeResidualCorrelation(e, u, max_lag)), path);
      },
      "residuals"_a, "input"_a, "path"_a, "max_lag"_a = 25,
      "Residual correlations with the 99 % confidence band.");
  m.def(
      "plot_closed_loop",
      [](const Eigen::VectorXd& t, const Eigen::VectorXd& r,
         const std::vector<std::tuple<std::string, Eigen::VectorXd, Eigen::VectorXd>>& runs,
         const std::string& path, const std::string& title) {
        std::vector<ClosedLoopTrace> traces;
        for (const auto& [label, y, u] : runs) traces.push_back({label, y, u});
        ClosedLoopFigureOptions o;
        o.title = title;
        SaveFigure(ClosedLoopFigure(t, r, traces, o), path);
      },
      "t"_a, "setpoint"_a, "runs"_a, "path"_a, "title"_a = "Closed-loop response",
      "Set-point, outputs and inputs of [(label, y, u), ...] (paper Fig. 6).");
  m.def(
      "write_identification_report",
      [](const Dataset& data, const std::string& dir, std::vector<std::string> methods, int order,
         int na, int nb, int nk, double confidence) {
        ReportOptions o;
        o.confidence = confidence;
        o.methods = std::move(methods);
        o.request.order = order;
        o.request.na = na;
        o.request.nb = nb;
        o.request.nk = nk;
        ReportSummary s;
        {
          py::gil_scoped_release release;
          s = WriteIdentificationReport(data, o, dir);
        }
        py::list models;
        for (const auto& mm : s.models) models.append(py::cast(mm));
        py::list failures;
        for (const auto& [mm, e] : s.failures) failures.append(py::make_tuple(mm, e));
        return py::dict("termination"_a = ToString(s.termination), "message"_a = s.message,
                        "html"_a = s.html_path, "models_json"_a = s.models_path,
                        "models"_a = models, "failures"_a = failures, "figures"_a = s.num_figures,
                        "tables"_a = s.num_tables);
      },
      "data"_a, "dir"_a, "methods"_a = std::vector<std::string>{"reaction-curve", "ptn", "arx"},
      "order"_a = 2, "na"_a = 3, "nb"_a = 3, "nk"_a = 1, "confidence"_a = 0.0,
      "Writes DIR/report.html and DIR/models.json (as `pneumid report`; confidence > 0 draws "
      "bands of that many standard deviations on the step and Bode figures); returns a summary "
      "dict.");

  // --- the paper -------------------------------------------------------------
  m.def(
      "run_paper",
      [](const std::string& figures_dir, std::uint64_t seed) {
        PaperOptions o;
        o.seed = seed;
        PaperResult r;
        std::vector<std::string> files;
        {
          py::gil_scoped_release release;
          r = RunPaper(o);
          if (!figures_dir.empty()) files = WritePaperFigures(r, figures_dir);
        }
        py::object j = JsonToPython(r.ToJson());
        j["figures"] = files;
        return j;
      },
      "figures_dir"_a = "", "seed"_a = 1,
      "The paper's workflow on the IPA simulator (as `pneumid paper --json`): dict with "
      "'rows' [{'quantity', 'paper', 'pneumid', 'note'}]; figures written when "
      "figures_dir is given.");
}

}  // namespace pneumid::python
