// Bindings of the nonlinear identification: StaticMap (models/static_map.hpp),
// fit_static_map, the nonlinear method names and the nonlinear parts of an
// IdentifiedModel (identify(method, data, ...) runs the methods themselves).
#include <pybind11/eigen.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include "bindings.hpp"
#include "pneumid/identify/identified_model.hpp"
#include "pneumid/identify/nonlinear/nonlinear.hpp"
#include "pneumid/identify/nonlinear/static_map_fit.hpp"
#include "pneumid/models/static_map.hpp"

namespace py = pybind11;
using namespace py::literals;

namespace pneumid::python {

namespace {

py::object FlatToPython(const std::optional<FlatSegment>& f) {
  if (!f) return py::none();
  return py::dict("u_from"_a = f->u_from, "u_to"_a = f->u_to, "y"_a = f->y);
}

}  // namespace

void BindNonlinear(py::module_& m) {
  py::class_<StaticMap>(m, "StaticMap",
                        "Piecewise-linear static map y = f(u) through knots (u strictly "
                        "increasing); extrapolation 'clamp' (default) or 'linear'.")
      .def(py::init(
               [](std::vector<double> u, std::vector<double> y, const std::string& extrapolation) {
                 return StaticMap(std::move(u), std::move(y),
                                  StaticMapExtrapolationFromString(extrapolation));
               }),
           "u"_a, "y"_a, "extrapolation"_a = "clamp",
           "Map through the knots (u[i], y[i]). Raises InvalidArgument for lengths that "
           "differ, fewer than 2 knots, non-finite values, u not strictly increasing or an "
           "unknown extrapolation.")
      .def_property_readonly("u", &StaticMap::u, "Knot inputs, strictly increasing (list).")
      .def_property_readonly("y", &StaticMap::y, "Values at the knots (list).")
      .def_property_readonly(
          "extrapolation", [](const StaticMap& f) { return ToString(f.extrapolation()); },
          "Beyond the first and last knot: 'clamp' (the end values) or 'linear' (the end "
          "segments continued).")
      .def("evaluate", py::overload_cast<double>(&StaticMap::Evaluate, py::const_), "u"_a,
           "f(u) for a number.")
      .def("evaluate", py::overload_cast<const Eigen::VectorXd&>(&StaticMap::Evaluate, py::const_),
           "u"_a, "f(u) for an array.")
      .def("inverse", &StaticMap::Inverse, "y"_a,
           "The input giving output y: the upper edge of a dead zone, the start of a "
           "saturation, clamped to the knots. Raises ValueError for a map that is not monotone.")
      .def("is_monotone", &StaticMap::IsMonotone,
           "True when y is non-decreasing or non-increasing in u and not constant (inverse is "
           "defined).")
      .def(
          "direction", [](const StaticMap& f) { return ToString(f.Direction()); },
          "'increasing', 'decreasing' (flat segments allowed), 'constant' or 'not monotone'.")
      .def(
          "dead_zone", [](const StaticMap& f, double tol) { return FlatToPython(f.DeadZone(tol)); },
          "tolerance"_a = 0.0,
          "{'u_from', 'u_to', 'y'} of the flat run at the low input end, or None.")
      .def(
          "saturation",
          [](const StaticMap& f, double tol) { return FlatToPython(f.Saturation(tol)); },
          "tolerance"_a = 0.0, "The flat run at the high input end, or None.")
      .def("describe", &StaticMap::Describe, "tolerance"_a = 0.0,
           "One line: direction, knots, ranges, dead zone and saturation (flat runs within "
           "`tolerance`, output units), e.g. 'monotone increasing, 3 knots on u in [0, 2], y in "
           "[0, 1], dead zone u in [0, 1] (y = 0)'.")
      .def(
          "to_dict", [](const StaticMap& f) { return JsonToPython(ToJson(f)); },
          "{'u': [...], 'y': [...], 'extrapolation'} as in pneumid's model files.")
      .def("__repr__", [](const StaticMap& f) { return "<StaticMap " + f.Describe() + ">"; });

  m.def("nonlinear_methods", &NonlinearMethodNames,
        "Names of the nonlinear identification methods (not part of 'all'): static-map, "
        "hammerstein, wiener, narx; run them with identify(method, data, na=, nb=, nk=).");
  m.def(
      "fit_static_map",
      [](const Dataset& data, int input, int output, double settle_fraction,
         double min_segment_duration, bool monotone, int smoothing_passes,
         const std::string& source) {
        StaticMapFitOptions o;
        o.settle_fraction = settle_fraction;
        o.min_segment_duration = min_segment_duration;
        o.monotone = monotone;
        o.smoothing_passes = smoothing_passes;
        o.source = StaticMapSourceFromString(source);
        const StaticMapFitResult r = FitStaticMap(data, input, output, o);
        return py::make_tuple(
            r.map, py::dict("level_u"_a = r.level_u, "level_y"_a = r.level_y, "weight"_a = r.weight,
                            "message"_a = r.summary.message, "brief"_a = r.summary.BriefReport()));
      },
      "data"_a, "input"_a = 0, "output"_a = 0, "settle_fraction"_a = 0.5,
      "min_segment_duration"_a = 1.0, "monotone"_a = true, "smoothing_passes"_a = 0,
      "source"_a = "auto",
      "Steady-state map from a staircase (or slow ramp, source='ramp'): returns "
      "(StaticMap, {'level_u', 'level_y', 'weight', 'message', 'brief'}).");
}

}  // namespace pneumid::python
