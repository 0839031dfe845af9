// Bindings of the plant, control and closed-loop APIs.
#include <pybind11/eigen.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include "bindings.hpp"

namespace py = pybind11;

namespace pneumid::python {

void BindExtras(py::module_& /*m*/) {}

}  // namespace pneumid::python
