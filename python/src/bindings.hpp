// Internal declarations of the pneumid Python module (one Bind* per area).
#pragma once

#include <pybind11/pybind11.h>

#include <nlohmann/json.hpp>

namespace pneumid::python {

void BindData(pybind11::module_& m);
void BindLti(pybind11::module_& m);
void BindIdentify(pybind11::module_& m);
void BindReport(pybind11::module_& m);
/// Plant, control and closed-loop bindings.
void BindExtras(pybind11::module_& m);
void BindUncertainty(pybind11::module_& m);
/// calibrate() and the IPA parameter helpers.
void BindCalibration(pybind11::module_& m);
/// generate_c() and write_c() (embedded C code generation).
void BindCodegen(pybind11::module_& m);
void BindNonlinear(pybind11::module_& m);

/// Throws InvalidArgument (Python: pneumid.InvalidArgument, a ValueError)
/// "function: argument is empty (...)" when an array argument has no elements.
void RequireNonEmpty(long size, const char* function, const char* argument);

/// JSON value <-> Python object (through the json module).
pybind11::object JsonToPython(const nlohmann::json& j);
nlohmann::json PythonToJson(const pybind11::handle& obj);

}  // namespace pneumid::python
