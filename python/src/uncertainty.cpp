// Bindings of identify/model_uncertainty.hpp: standard deviations of the step
// and Bode responses of identified models, and figures with confidence bands.
#include <memory>

#include <pybind11/eigen.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include "bindings.hpp"
#include "pneumid/common/check.hpp"
#include "pneumid/identify/evaluation/model_uncertainty.hpp"
#include "pneumid/report/figures.hpp"

namespace py = pybind11;
using namespace py::literals;

namespace pneumid::python {

namespace {

UncertaintyOptions Form(bool discrete) {
  UncertaintyOptions o;
  o.discrete = discrete;
  return o;
}

// Each model drawn as `pneumid report` draws it (discrete form when it has
// one, else tf), labelled "method (structure)", with its covariance.
std::vector<NamedModel> Named(const std::vector<IdentifiedModel>& models, bool discrete) {
  std::vector<NamedModel> out;
  for (const IdentifiedModel& m : models) {
    NamedModel nm{m.method + " (" + m.structure + ")", discrete && m.discrete ? *m.discrete : m.tf,
                  m.u0, m.y0};
    nm.identified = std::make_shared<const IdentifiedModel>(m);
    out.push_back(std::move(nm));
  }
  return out;
}

void Save(const Figure& fig, const std::string& path) {
  py::gil_scoped_release release;
  fig.Save(path);
}

}  // namespace

void BindUncertainty(py::module_& m) {
  m.def("has_covariance", &HasCovariance, "model"_a,
        "Whether the identified model has a usable parameter covariance (arx, armax, oe, bj, "
        "iv4: full; fit-*: diagonal).");
  m.def(
      "step_response_std",
      [](const IdentifiedModel& model, const Eigen::VectorXd& t, bool discrete) {
        return StepResponseStd(model, t, Form(discrete));
      },
      "model"_a, "t"_a, "discrete"_a = false,
      "Standard deviation of the unit step response at times t (s) by first-order propagation "
      "of the parameter covariance (Ljung sec. 9.6, MATLAB showConfidence), of the model's tf "
      "or, with discrete=True, of its discrete form. An empty array when the model has no "
      "covariance.");
  m.def(
      "bode_std",
      [](const IdentifiedModel& model, const Eigen::VectorXd& w, bool discrete) {
        const BodeStd s = BodeResponseStd(model, w, Form(discrete));
        return py::dict("magnitude_db"_a = s.magnitude_db, "phase_deg"_a = s.phase_deg);
      },
      "model"_a, "w"_a, "discrete"_a = false,
      "Standard deviations of the Bode magnitude [dB] and phase [deg] at frequencies w "
      "(rad/s): {'magnitude_db', 'phase_deg'} (empty arrays without a covariance).");
  m.def(
      "plot_identified_step",
      [](const std::vector<IdentifiedModel>& models, const std::string& path, double confidence,
         double amplitude, double t_final, bool discrete, const std::string& title) {
        StepFigureOptions o;
        o.amplitude = amplitude;
        o.t_final = t_final;
        o.title = title;
        o.confidence = confidence;
        Save(StepResponseFigure(Named(models, discrete), o), path);
      },
      "models"_a, "path"_a, "confidence"_a = 0.0, "amplitude"_a = 1.0, "t_final"_a = 0.0,
      "discrete"_a = false, "title"_a = "Step response",
      "Step responses of identified models to a PNG or SVG file, with shaded bands of "
      "+-confidence standard deviations around those with a covariance (0 = none).");
  m.def(
      "plot_identified_bode",
      [](const std::vector<IdentifiedModel>& models, const std::string& path, double confidence,
         bool discrete, const std::string& title) {
        Save(BodeFigure(Named(models, discrete), Eigen::VectorXd(), title, confidence), path);
      },
      "models"_a, "path"_a, "confidence"_a = 0.0, "discrete"_a = false, "title"_a = "Bode diagram",
      "Bode diagram of identified models with bands of +-confidence standard deviations.");
}

}  // namespace pneumid::python
