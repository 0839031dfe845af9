// The Python module `pneumid`: bindings of the C++ library with pybind11.
//
// Naming: every function and class keeps its C++ name in Python's snake_case
// (C2D -> c2d, ComputeStepInfo -> compute_step_info, TransferFunction ->
// TransferFunction); enums are passed as the strings of their ToString /
// XxxFromString converters ("zoh", "tustin", ...), the same strings the CLI takes.
// Arrays are numpy float64 arrays; results are returned without a copy (the
// Eigen result is moved into the array). Long computations (identification,
// simulation, reports, plots) release the GIL.
// Errors: pneumid.InvalidArgument (a ValueError) and pneumid.DataError (an
// OSError subclass would be misleading for bad content, so it is a RuntimeError).
#include <pybind11/eigen.h>
#include <pybind11/functional.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include "bindings.hpp"
#include "pneumid/common/check.hpp"
#include "pneumid/common/version.hpp"

namespace py = pybind11;

namespace pneumid::python {

py::object JsonToPython(const nlohmann::json& j) {
  return py::module_::import("json").attr("loads")(j.dump());
}

nlohmann::json PythonToJson(const py::handle& obj) {
  const std::string s = py::module_::import("json").attr("dumps")(obj).cast<std::string>();
  return nlohmann::json::parse(s);
}

void RequireNonEmpty(long size, const char* function, const char* argument) {
  PNEUMID_CHECK(size > 0, "{}: {} is empty (an array of at least one sample is needed)", function,
                argument);
}

}  // namespace pneumid::python

PYBIND11_MODULE(pneumid, m) {
  m.doc() =
      "pneumid: identify models of a plant from a step test, compare them, and tune,\n"
      "simulate and run predictive controllers against it (Python bindings of the C++\n"
      "library; names follow the C++ API in snake_case, enums are strings).";
  m.attr("__version__") = pneumid::Version();

  static py::exception<pneumid::InvalidArgument> invalid_argument(m, "InvalidArgument",
                                                                  PyExc_ValueError);
  static py::exception<pneumid::DataError> data_error(m, "DataError", PyExc_RuntimeError);
  invalid_argument.attr("__doc__") =
      "An argument or option violates its documented precondition (a ValueError); the message "
      "states the violated condition and the offending values.";
  data_error.attr("__doc__") =
      "Input data (a file, a column, a sample) cannot be used (a RuntimeError); the message "
      "names where the problem is, e.g. \"data.csv:12: column 'y': not a number: 'abc'\".";
  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const pneumid::InvalidArgument& e) {
      invalid_argument(e.what());
    } catch (const pneumid::DataError& e) {
      data_error(e.what());
    }
  });

  pneumid::python::BindData(m);
  pneumid::python::BindLti(m);
  pneumid::python::BindIdentify(m);
  pneumid::python::BindReport(m);
  pneumid::python::BindExtras(m);
  pneumid::python::BindUncertainty(m);
  pneumid::python::BindCalibration(m);
  pneumid::python::BindCodegen(m);
  pneumid::python::BindNonlinear(m);
}
