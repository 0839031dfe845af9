// Embedded C code generation (pneumid/codegen/c_codegen.hpp) from Python:
// generate_c() returns the module's texts and sizes, write_c() writes them.
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include "bindings.hpp"
#include "pneumid/codegen/c_codegen.hpp"

namespace py = pybind11;
using namespace py::literals;

namespace pneumid::python {

namespace {

CodegenOptions Options(const std::string& precision, const std::string& prefix, std::size_t max_ram,
                       double cpu_mhz, double period) {
  CodegenOptions o;
  o.precision = CodegenPrecisionFromString(precision);
  o.prefix = prefix;
  o.max_ram_bytes = max_ram;
  o.cpu_mhz = cpu_mhz;
  o.period = period;
  return o;
}

}  // namespace

void BindCodegen(py::module_& m) {
  m.def(
      "generate_c",
      [](const Controller& controller, const std::string& precision, const std::string& prefix,
         std::size_t max_ram, double cpu_mhz, double period) {
        const CodegenResult r =
            GenerateC(controller, Options(precision, prefix, max_ram, cpu_mhz, period));
        py::dict d = JsonToPython(r.ToJson());
        d["header"] = r.header;
        d["source"] = r.source;
        d["readme"] = r.readme;
        return d;
      },
      "controller"_a, "precision"_a = "double", "prefix"_a = "pneumid_ctrl", "max_ram"_a = 0,
      "cpu_mhz"_a = 0.0, "period"_a = 0.0,
      "The controller as an embedded C99 module (pneumid codegen): a dict with header, source, "
      "readme, ram_bytes, const_bytes, constrained, layers, certificate, description, files. "
      "cpu_mhz > 0 certifies the worst step within half the period (0: the controller's Ts). "
      "Raises InvalidArgument for a state above max_ram bytes (0: no budget), a certificate "
      "that cannot be met, or bad options.");
  m.def(
      "write_c",
      [](const Controller& controller, const std::string& directory, const std::string& precision,
         const std::string& prefix, std::size_t max_ram) {
        return WriteCodegenFiles(GenerateC(controller, Options(precision, prefix, max_ram, 0, 0)),
                                 directory);
      },
      "controller"_a, "directory"_a, "precision"_a = "double", "prefix"_a = "pneumid_ctrl",
      "max_ram"_a = 0,
      "Writes PREFIX.h, PREFIX.c and README.md into directory; returns the paths.");
}

}  // namespace pneumid::python
