// optimize_target_shape: convert, release the GIL around the core call, convert back.
#include <pybind11/numpy.h>
#include <pybind11/stl.h>

#include <string>
#include <vector>

#include "bindings.hpp"
#include "progress.hpp"
#include "wiresculpt/target_shape.hpp"

namespace py = pybind11;

namespace wiresculpt::python {
namespace {

Polyline2 to_points(const py::array_t<double, py::array::c_style | py::array::forcecast>& a) {
  if (a.ndim() != 2 || a.shape(1) != 2)
    throw py::value_error("optimize_target_shape: points must be a float array of shape (n, 2)");
  auto r = a.unchecked<2>();
  Polyline2 out(static_cast<std::size_t>(r.shape(0)));
  for (py::ssize_t i = 0; i < r.shape(0); ++i) out[static_cast<std::size_t>(i)] = Vec2(r(i, 0), r(i, 1));
  return out;
}

Vec2 to_vec2(const py::handle& h, const std::string& what) {
  const auto v = py::cast<std::vector<double>>(h);
  if (v.size() != 2) throw py::value_error("optimize_target_shape: " + what + " must have 2 components");
  return {v[0], v[1]};
}

std::vector<TargetCrossing> to_crossings(const py::list& items) {
  std::vector<TargetCrossing> out;
  for (std::size_t c = 0; c < items.size(); ++c) {
    const std::string name = "crossing " + std::to_string(c);
    const auto d = py::cast<py::dict>(items[c]);
    TargetCrossing x;
    for (auto [key, value] : d) {
      const auto k = py::cast<std::string>(key);
      if (k == "vertex") x.vertex = py::cast<int>(value);
      else if (k == "bisector") x.bisector = to_vec2(value, name + " bisector");
      else if (k == "contact_angle") x.contact_angle = py::cast<double>(value);
      else if (k == "active") x.active = py::cast<bool>(value);
      else throw py::value_error("optimize_target_shape: " + name + " has unknown key '" + k +
                                 "' (expected vertex, bisector, contact_angle, active)");
    }
    if (!d.contains("vertex")) throw py::value_error("optimize_target_shape: " + name + " has no 'vertex'");
    out.push_back(x);
  }
  return out;
}

TargetShapeOptions to_options(const py::dict& d) {
  TargetShapeOptions o;
  for (auto [key, value] : d) {
    const auto k = py::cast<std::string>(key);
    if (k == "min_segment") o.min_segment = py::cast<double>(value);
    else if (k == "max_bend") o.max_bend = py::cast<double>(value);
    else if (k == "spacing") o.spacing = py::cast<double>(value);
    else if (k == "regularization") o.regularization = py::cast<double>(value);
    else if (k == "friction") o.friction = py::cast<double>(value);
    else if (k == "ftol_rel") o.ftol_rel = py::cast<double>(value);
    else if (k == "xtol_rel") o.xtol_rel = py::cast<double>(value);
    else if (k == "constraint_tol") o.constraint_tol = py::cast<double>(value);
    else if (k == "max_iterations") o.max_iterations = py::cast<int>(value);
    else if (k == "window") o.window = py::cast<int>(value);
    else if (k == "sweep_tol") o.sweep_tol = py::cast<double>(value);
    else if (k == "max_sweeps") o.max_sweeps = py::cast<int>(value);
    else if (k == "model_size") o.model_size = py::cast<double>(value);
    else if (k == "angle_tolerance") o.angle_tolerance = py::cast<double>(value);
    else if (k == "length_tolerance") o.length_tolerance = py::cast<double>(value);
    else if (k == "wire_name") o.wire_name = py::cast<std::string>(value);
    else if (k == "algorithm") {
      const auto a = py::cast<std::string>(value);
      if (a == "slsqp") o.algorithm = TargetShapeAlgorithm::slsqp;
      else if (a == "auglag_lbfgs") o.algorithm = TargetShapeAlgorithm::auglag_lbfgs;
      else if (a == "ccsaq") o.algorithm = TargetShapeAlgorithm::ccsaq;
      else if (a == "mma") o.algorithm = TargetShapeAlgorithm::mma;
      else throw py::value_error("optimize_target_shape: algorithm must be slsqp, auglag_lbfgs, ccsaq or mma, not '" + a + "'");
    } else
      throw py::value_error("optimize_target_shape: unknown option '" + k + "'");
  }
  return o;
}

py::dict optimize(const py::array_t<double, py::array::c_style | py::array::forcecast>& points, bool closed,
                  const py::list& crossings, const py::dict& options, const py::object& progress) {
  const Polyline2 contour = to_points(points);
  const std::vector<TargetCrossing> xs = to_crossings(crossings);
  const TargetShapeOptions o = to_options(options);
  PythonProgress reporter(progress);
  const ProgressFn fn = reporter.fn();
  const TargetShapeResult r = reporter.run([&] { return optimize_target_shape(contour, closed, xs, o, fn); });
  py::array_t<double> pts({static_cast<py::ssize_t>(r.points.size()), py::ssize_t{2}});
  auto w = pts.mutable_unchecked<2>();
  for (py::ssize_t i = 0; i < w.shape(0); ++i)
    for (py::ssize_t k = 0; k < 2; ++k) w(i, k) = r.points[static_cast<std::size_t>(i)][k];
  py::list statuses;
  for (const TargetCrossingStatus& s : r.crossings)
    statuses.append(py::dict(py::arg("status") = s.status, py::arg("realised") = s.realised,
                             py::arg("vertex") = s.vertex,
                             py::arg("bisector") = py::make_tuple(s.bisector.x(), s.bisector.y()),
                             py::arg("contact_angle") = s.contact_angle,
                             py::arg("contact_violation") = s.contact_violation, py::arg("scale") = s.scale,
                             py::arg("message") = s.message));
  return py::dict(py::arg("points") = pts, py::arg("crossing_vertices") = r.crossing_vertices,
                  py::arg("crossings") = statuses, py::arg("max_distance") = r.max_distance,
                  py::arg("rms_distance") = r.rms_distance, py::arg("min_segment") = r.min_segment,
                  py::arg("max_bend") = r.max_bend, py::arg("max_length_violation") = r.max_length_violation,
                  py::arg("max_angle_violation") = r.max_angle_violation, py::arg("iterations") = r.iterations,
                  py::arg("sweeps") = r.sweeps, py::arg("seconds") = r.seconds,
                  py::arg("nlopt_result") = r.nlopt_result, py::arg("energy") = r.energy,
                  py::arg("feasible") = r.feasible, py::arg("warnings") = r.warnings);
}

}  // namespace

void bind_target_shape(py::module_& m) {
  m.def("optimize_target_shape", &optimize, py::arg("points"), py::arg("closed"), py::arg("crossings"),
        py::arg("options") = py::dict(), py::arg("progress") = py::none(),
        R"(Target-shape optimisation of one wire in its plane frame (Sec. 4.3, Eq. 3-5).

points: float64 (n, 2), metres; closed: bool; crossings: list of {"vertex": int (index into
points), "bisector": (x, y) desired h*, "contact_angle": radians (default 2π/3), "active": bool
(default True)}; options: dict of TargetShapeOptions fields (min_segment, max_bend, spacing,
regularization, friction, algorithm ("slsqp" | "auglag_lbfgs" | "ccsaq" | "mma"), ftol_rel,
xtol_rel, constraint_tol, max_iterations, window, sweep_tol, max_sweeps, model_size,
angle_tolerance, length_tolerance, wire_name); progress: optional callable(stage, fraction) ->
bool, False cancels (raises Cancelled).
Returns {"points": (m, 2), "crossing_vertices": [int], "crossings": [{"status", "realised",
"vertex", "bisector", "contact_angle", "contact_violation", "scale", "message"}], "max_distance",
"rms_distance", "min_segment", "max_bend", "max_length_violation", "max_angle_violation",
"iterations", "sweeps", "seconds", "nlopt_result", "energy", "feasible", "warnings"}.
Raises ValueError naming the wire and crossing for bad input.)");
}

}  // namespace wiresculpt::python
