// Bindings of the data and lti areas.
#include <pybind11/eigen.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include "bindings.hpp"
#include "pneumid/data/dataset.hpp"
#include "pneumid/data/load.hpp"
#include "pneumid/lti/conversion.hpp"
#include "pneumid/models/model_file.hpp"
#include "pneumid/lti/response.hpp"
#include "pneumid/lti/state_space.hpp"
#include "pneumid/lti/transfer_function.hpp"

namespace py = pybind11;
using namespace py::literals;

namespace pneumid::python {

namespace {

std::vector<Channel> Channels(const std::vector<std::string>& names,
                              const std::vector<std::string>& units) {
  std::vector<Channel> out;
  for (std::size_t i = 0; i < names.size(); ++i)
    out.push_back({names[i], i < units.size() ? units[i] : std::string()});
  return out;
}

py::dict StepInfoToDict(const StepInfo& s) {
  return py::dict("rise_time"_a = s.rise_time, "settling_time"_a = s.settling_time,
                  "settling_min"_a = s.settling_min, "settling_max"_a = s.settling_max,
                  "overshoot"_a = s.overshoot, "undershoot"_a = s.undershoot, "peak"_a = s.peak,
                  "peak_time"_a = s.peak_time, "steady_state"_a = s.steady_state);
}

}  // namespace

void BindData(py::module_& m) {
  py::class_<Channel>(m, "Channel", "Name and unit of one measured signal.")
      .def(py::init<std::string, std::string>(), "name"_a = "", "unit"_a = "",
           "Channel with a name and a unit, e.g. Channel('F', 'N') or Channel('u', '%').")
      .def_readwrite("name", &Channel::name, "Signal name, e.g. 'F' or 'u'.")
      .def_readwrite("unit", &Channel::unit, "Unit of the signal, e.g. 'N' or '%' ('' if none).")
      .def("__repr__",
           [](const Channel& c) { return "Channel('" + c.name + "', '" + c.unit + "')"; });

  py::class_<Dataset>(m, "Dataset",
                      "Measured input/output data of one experiment (time N, inputs N x nu, "
                      "outputs N x ny).")
      .def(py::init([](Eigen::VectorXd time, Eigen::MatrixXd inputs, Eigen::MatrixXd outputs,
                       std::vector<std::string> input_names, std::vector<std::string> input_units,
                       std::vector<std::string> output_names,
                       std::vector<std::string> output_units) {
             RequireNonEmpty(time.size(), "Dataset", "time");
             return Dataset(std::move(time), std::move(inputs), std::move(outputs),
                            Channels(input_names, input_units),
                            Channels(output_names, output_units));
           }),
           "time"_a, "inputs"_a, "outputs"_a, "input_names"_a = std::vector<std::string>{},
           "input_units"_a = std::vector<std::string>{},
           "output_names"_a = std::vector<std::string>{},
           "output_units"_a = std::vector<std::string>{},
           "Builds a dataset from columns (time in s, strictly increasing; 1-D arrays are "
           "single channels). Raises InvalidArgument when lengths differ or a value is not "
           "finite.")
      .def_static(
          "from_uniform",
          [](double Ts, const Eigen::VectorXd& u, const Eigen::VectorXd& y, double t0,
             const std::string& input_name, const std::string& input_unit,
             const std::string& output_name, const std::string& output_unit) {
            RequireNonEmpty(u.size(), "Dataset.from_uniform", "u");
            return Dataset::FromUniform(Ts, u, y, t0, {input_name, input_unit},
                                        {output_name, output_unit});
          },
          "Ts"_a, "u"_a, "y"_a, "t0"_a = 0.0, "input_name"_a = "u", "input_unit"_a = "",
          "output_name"_a = "y", "output_unit"_a = "",
          "Uniformly sampled SISO dataset starting at t0 (Ts in seconds).")
      .def_static(
          "load",
          [](const std::string& path, const std::string& time_column,
             std::vector<std::string> input_columns, std::vector<std::string> output_columns,
             double sample_time, const std::string& format) {
            LoadOptions o;
            o.time_column = time_column;
            o.input_columns = std::move(input_columns);
            o.output_columns = std::move(output_columns);
            o.sample_time = sample_time;
            o.format = DataFormatFromString(format);
            py::gil_scoped_release release;
            return LoadDataset(path, o);
          },
          "path"_a, "time_column"_a = "t", "input_columns"_a = std::vector<std::string>{"u"},
          "output_columns"_a = std::vector<std::string>{"y"}, "sample_time"_a = 0.0,
          "format"_a = "auto",
          "Reads a CSV/TXT or MAT file (format 'auto', 'csv' or 'mat'). Raises DataError "
          "naming file, line and column for bad content.")
      .def(
          "save",
          [](const Dataset& d, const std::string& path) {
            py::gil_scoped_release release;
            SaveDataset(d, path);
          },
          "path"_a, "Writes the dataset (CSV or MAT by extension).")
      .def_property_readonly("time", &Dataset::time, "Sample times [s].")
      .def_property_readonly("inputs", &Dataset::inputs, "Inputs, N x nu.")
      .def_property_readonly("outputs", &Dataset::outputs, "Outputs, N x ny.")
      .def("u", &Dataset::u, "i"_a = 0, "Input column i.")
      .def("y", &Dataset::y, "i"_a = 0, "Output column i.")
      .def_property_readonly("num_inputs", &Dataset::num_inputs,
                             "Number of input channels nu (columns of inputs).")
      .def_property_readonly("num_outputs", &Dataset::num_outputs,
                             "Number of output channels ny (columns of outputs).")
      .def_property_readonly("input_channels", &Dataset::input_channels,
                             "Name and unit of each input column (list of Channel; unnamed "
                             "inputs are 'u', or 'u1', 'u2', ... for several).")
      .def_property_readonly("output_channels", &Dataset::output_channels,
                             "Name and unit of each output column (list of Channel; unnamed "
                             "outputs are 'y', or 'y1', 'y2', ...).")
      .def_property("source", &Dataset::source, &Dataset::set_source,
                    "Where the data came from (the file path for loaded data, '' when "
                    "unknown), quoted in error messages; can be set.")
      .def("sample_time", &Dataset::SampleTime, "Mean sample interval [s].")
      .def("is_uniform", &Dataset::IsUniform, "rel_tol"_a = 1e-3,
           "True when every sample interval is within rel_tol times the median interval from "
           "it (always True below 3 samples). Raises InvalidArgument for rel_tol < 0.")
      .def("__len__", [](const Dataset& d) { return d.size(); })
      .def("__repr__", [](const Dataset& d) {
        return "<Dataset " + std::to_string(d.size()) + " samples, " +
               std::to_string(d.num_inputs()) + " input(s), " + std::to_string(d.num_outputs()) +
               " output(s)" + (d.source().empty() ? "" : ", from " + d.source()) + ">";
      });
}

void BindLti(py::module_& m) {
  py::class_<TransferFunction>(
      m, "TransferFunction",
      "SISO transfer function, continuous (Ts = 0; coefficients in descending powers of s) "
      "or discrete (Ts > 0; coefficients in ascending powers of z^-1), with an input delay "
      "in seconds.")
      .def(py::init<>(), "The static gain 1, continuous.")
      .def(py::init<Eigen::VectorXd, Eigen::VectorXd, double, double>(), "num"_a, "den"_a,
           "Ts"_a = 0.0, "delay"_a = 0.0,
           "Model from coefficients (Ts = 0: descending powers of s; Ts > 0 in s: ascending "
           "powers of z^-1) and an input delay in s. Raises InvalidArgument for an empty or "
           "all-zero denominator, Ts < 0, delay < 0, a discrete delay that is not a multiple "
           "of Ts, or an improper continuous model (deg num > deg den).")
      .def_static("continuous", &TransferFunction::Continuous, "num"_a, "den"_a, "delay"_a = 0.0,
                  "Continuous model, descending powers of s, delay in s.")
      .def_static("discrete", &TransferFunction::Discrete, "num_zinv"_a, "den_zinv"_a, "Ts"_a,
                  "delay_samples"_a = 0,
                  "Discrete model, ascending powers of z^-1, delay in samples.")
      .def_static("fopdt", &TransferFunction::Fopdt, "K"_a, "tau"_a, "theta"_a,
                  "K exp(-theta s) / (tau s + 1).")
      .def_static("sopdt", &TransferFunction::Sopdt, "K"_a, "tau1"_a, "tau2"_a, "theta"_a,
                  "K exp(-theta s) / ((tau1 s + 1)(tau2 s + 1)).")
      .def_property_readonly("num", &TransferFunction::num,
                             "Numerator coefficients: descending powers of s (continuous) or "
                             "ascending powers of z^-1 (discrete, as long as den).")
      .def_property_readonly("den", &TransferFunction::den,
                             "Denominator coefficients, ordered as num (continuous: without "
                             "leading zeros; discrete: den[0] != 0).")
      .def_property_readonly("Ts", &TransferFunction::Ts,
                             "Sample time [s]; 0 for a continuous model.")
      .def_property_readonly("delay", &TransferFunction::delay, "Input delay [s].")
      .def("is_discrete", &TransferFunction::IsDiscrete, "True for a discrete model (Ts > 0).")
      .def("delay_samples", &TransferFunction::DelaySamples,
           "Input delay in samples, delay / Ts. Raises InvalidArgument for a continuous model.")
      .def("with_delay", &TransferFunction::WithDelay, "delay"_a,
           "Copy of the model with input delay `delay` [s]. Raises InvalidArgument for a "
           "negative delay, or one that is not a multiple of Ts for a discrete model.")
      .def("order", &TransferFunction::Order,
           "Number of poles: the degree of the denominator without leading zeros.")
      .def("poles", &TransferFunction::Poles, "Roots of the denominator in s or z (complex array).")
      .def("zeros", &TransferFunction::Zeros, "Roots of the numerator in s or z (complex array).")
      .def("dc_gain", &TransferFunction::DcGain,
           "Static gain G(0) (continuous) or G(1) (discrete): +-inf for a pole at s = 0 / "
           "z = 1, NaN when numerator and denominator both vanish there.")
      .def("is_stable", &TransferFunction::IsStable,
           "True when every pole lies in the open left half plane (continuous) or strictly "
           "inside the unit circle (discrete).")
      .def("evaluate", &TransferFunction::Evaluate, "point"_a,
           "Rational part at a complex s or z (no delay).")
      .def("frequency_response", &TransferFunction::FrequencyResponse, "w"_a,
           "G(jw) or G(exp(jw Ts)) with the delay, w in rad/s.")
      .def("normalized", &TransferFunction::Normalized,
           "The same model with a monic denominator (leading coefficient 1) and, when "
           "continuous, the leading zeros of the numerator removed.")
      .def("to_string", &TransferFunction::ToString, "precision"_a = 6,
           "Readable form with `precision` significant digits, e.g. '(1.6) / (0.245 s + 1) * "
           "exp(-0.001 s)'; a discrete model in powers of z^-1 with its delay as z^-d and "
           "', Ts = ...'.")
      .def(
          "to_dict", [](const TransferFunction& g) { return JsonToPython(ToJson(g)); },
          "{'num', 'den', 'Ts', 'delay'} as in pneumid's JSON files.")
      .def_static(
          "from_dict", [](const py::dict& d) { return TransferFunctionFromJson(PythonToJson(d)); },
          "d"_a,
          "Model from the dict of to_dict ('Ts' and 'delay' default to 0). Raises "
          "InvalidArgument naming a missing or invalid key, or as the constructor.")
      .def("__repr__", [](const TransferFunction& g) { return g.ToString(6); });

  py::class_<StateSpace>(m, "StateSpace",
                         "Linear state-space model; Ts = 0 continuous, Ts > 0 discrete.")
      .def(py::init<Eigen::MatrixXd, Eigen::MatrixXd, Eigen::MatrixXd, Eigen::MatrixXd, double,
                    double>(),
           "A"_a, "B"_a, "C"_a, "D"_a, "Ts"_a = 0.0, "delay"_a = 0.0,
           "dx/dt = A x + B u(t - delay), y = C x + D u(t - delay) for Ts = 0; x[k+1] = A x[k] "
           "+ B u[k - d], y[k] = C x[k] + D u[k - d] with d = delay / Ts for Ts > 0 (Ts and "
           "delay in s). Raises InvalidArgument when the matrix sizes disagree, Ts < 0 or "
           "delay < 0.")
      .def_property_readonly("A", &StateSpace::A, "State matrix, nx x nx.")
      .def_property_readonly("B", &StateSpace::B, "Input matrix, nx x nu.")
      .def_property_readonly("C", &StateSpace::C, "Output matrix, ny x nx.")
      .def_property_readonly("D", &StateSpace::D, "Feedthrough matrix, ny x nu.")
      .def_property_readonly("Ts", &StateSpace::Ts, "Sample time [s]; 0 for a continuous model.")
      .def_property_readonly("delay", &StateSpace::delay,
                             "Input delay [s] (delay / Ts samples for a discrete model).")
      .def("poles", &StateSpace::Poles, "Eigenvalues of A (complex array).")
      .def("is_stable", &StateSpace::IsStable,
           "True when every pole lies in the open left half plane (continuous) or strictly "
           "inside the unit circle (discrete).")
      .def("dc_gain", &StateSpace::DcGain,
           "Steady-state gain matrix (ny x nu): D - C A^-1 B (continuous) or D + C (I - A)^-1 B "
           "(discrete); every entry inf when the inverse does not exist.");

  m.def("parse_model_spec", &ParseModelSpec, "spec"_a,
        "Model from a spec: 'arx-paper', 'fopdt:K=1.6,tau=0.245,theta=0.001', "
        "'tf:num=1,den=1 1', or a model JSON file.");
  m.def("paper_arx_model", &PaperArxModel, "The paper's ARX(3,3,1) force model, Ts = 0.01 s.");
  m.def("paper_fopdt_model", &PaperFopdtModel, "The paper's FOPDT 1.6 exp(-0.001 s)/(0.245 s+1).");
  m.def("to_state_space", &ToStateSpace, "g"_a,
        "Controllable canonical realization of the transfer function g (same Ts and delay): A "
        "has -a1..-an in its first row, B = e1, C = b - b0 a, D = b0.");
  m.def("to_transfer_function", &ToTransferFunction, "ss"_a, "input"_a = 0, "output"_a = 0,
        "Transfer function of ss from input `input` to output `output` (0-based; same Ts and "
        "delay). Raises InvalidArgument for an index out of range.");
  m.def(
      "c2d",
      [](const TransferFunction& g, double Ts, const std::string& method, double prewarp) {
        return C2D(g, Ts, DiscretizationMethodFromString(method), prewarp);
      },
      "g"_a, "Ts"_a, "method"_a = "zoh", "prewarp"_a = 0.0,
      "Continuous -> discrete with sample time Ts [s]: method 'zoh', 'foh', 'tustin', 'euler', "
      "'backward_diff', 'matched'; prewarp [rad/s] for 'tustin' (0 = none). Raises "
      "InvalidArgument for a discrete g, Ts <= 0, a prewarp for another method or not below "
      "pi/Ts, or an unknown method.");
  m.def(
      "c2d",
      [](const StateSpace& g, double Ts, const std::string& method, double prewarp) {
        return C2D(g, Ts, DiscretizationMethodFromString(method), prewarp);
      },
      "g"_a, "Ts"_a, "method"_a = "zoh", "prewarp"_a = 0.0,
      "Continuous StateSpace -> discrete with sample time Ts [s] (methods as above; prewarp in "
      "rad/s, 'tustin' only, 0 = none). Raises InvalidArgument for a discrete g, Ts <= 0, a "
      "prewarp for another method or not below pi/Ts, or an unknown method.");
  m.def(
      "d2c",
      [](const TransferFunction& g, const std::string& method, double prewarp) {
        return D2C(g, DiscretizationMethodFromString(method), prewarp);
      },
      "g"_a, "method"_a = "zoh", "prewarp"_a = 0.0,
      "Discrete -> continuous ('zoh' through the matrix logarithm, or 'tustin').");
  m.def(
      "d2c",
      [](const StateSpace& g, const std::string& method, double prewarp) {
        return D2C(g, DiscretizationMethodFromString(method), prewarp);
      },
      "g"_a, "method"_a = "zoh", "prewarp"_a = 0.0,
      "Discrete StateSpace -> continuous ('zoh' or 'tustin'). Raises InvalidArgument for "
      "another method, a continuous g, (zoh) a pole on the closed negative real axis "
      "including z = 0, or (tustin) a pole at z = -1.");
  m.def(
      "step",
      [](const TransferFunction& g, double t_final, double dt) {
        TimeResponse r;
        {
          py::gil_scoped_release release;
          r = Step(g, t_final, dt);
        }
        return py::make_tuple(r.t, r.y);
      },
      "g"_a, "t_final"_a = 0.0, "dt"_a = 0.0,
      "Unit step response; returns (t, y). dt = 0 / t_final = 0 choose automatically.");
  m.def(
      "impulse",
      [](const TransferFunction& g, double t_final, double dt) {
        TimeResponse r;
        {
          py::gil_scoped_release release;
          r = Impulse(g, t_final, dt);
        }
        return py::make_tuple(r.t, r.y);
      },
      "g"_a, "t_final"_a = 0.0, "dt"_a = 0.0, "Unit impulse response; returns (t, y).");
  m.def(
      "lsim",
      [](const TransferFunction& g, const Eigen::VectorXd& u, double dt) {
        RequireNonEmpty(u.size(), "lsim", "u");
        py::gil_scoped_release release;
        return Lsim(g, u, dt);
      },
      "g"_a, "u"_a, "dt"_a,
      "Response to samples u[k] held over each interval dt, from rest (dt = Ts for a "
      "discrete model).");
  m.def(
      "lsim",
      [](const StateSpace& g, const Eigen::MatrixXd& u, double dt, const Eigen::VectorXd& x0) {
        RequireNonEmpty(u.size(), "lsim", "u");
        py::gil_scoped_release release;
        return Lsim(g, u, dt, x0);
      },
      "g"_a, "u"_a, "dt"_a, "x0"_a = Eigen::VectorXd(),
      "StateSpace response to u (N x nu, rows held over dt [s]) from initial state x0 (nx "
      "entries, empty: zero); returns the N x ny outputs. Raises InvalidArgument for an empty "
      "u, dt <= 0, a non-finite input, u without nu columns, x0 of another size, or a "
      "discrete model whose Ts differs from dt.");
  m.def(
      "compute_step_info",
      [](const Eigen::VectorXd& t, const Eigen::VectorXd& y, double settling_threshold,
         double y_initial, double y_final) {
        StepInfoOptions o;
        o.settling_threshold = settling_threshold;
        o.y_initial = y_initial;
        o.y_final = y_final;
        return StepInfoToDict(ComputeStepInfo(t, y, o));
      },
      "t"_a, "y"_a, "settling_threshold"_a = 0.02,
      "y_initial"_a = std::numeric_limits<double>::quiet_NaN(),
      "y_final"_a = std::numeric_limits<double>::quiet_NaN(),
      "MATLAB stepinfo metrics of a sampled response (dict; times in s, overshoot in %).");
  m.def(
      "compute_step_info",
      [](const TransferFunction& g) { return StepInfoToDict(ComputeStepInfo(g)); }, "g"_a,
      "stepinfo of the model's unit step response.");
}

}  // namespace pneumid::python
