// optimize_target_shape and optimize_target_shapes: convert, release the GIL around the core call,
// convert back.
#include <pybind11/numpy.h>
#include <pybind11/stl.h>

#include <string>
#include <vector>

#include "bindings.hpp"
#include "convert.hpp"
#include "progress.hpp"
#include "wiresculpt/target_shape.hpp"

namespace py = pybind11;

namespace wiresculpt::python {
namespace {

std::vector<TargetCrossing> to_crossings(py::handle items, const std::string& path) {
  std::vector<TargetCrossing> out;
  each_item(items, path, [&](py::handle item, const std::string& where) {
    TargetCrossing x;
    const auto seen = read_fields(
        item, where,
        {field::integer("vertex", x.vertex),
         {"bisector", [&](py::handle v, const std::string& at) { x.bisector = to_vector<2>(v, at); }},
         field::number("contact_angle", x.contact_angle), field::boolean("active", x.active)});
    require_keys(seen, where, {"vertex"});
    out.push_back(x);
  });
  return out;
}

TargetShapeOptions to_options(py::handle d, const std::string& path) {
  TargetShapeOptions o;
  read_fields(d, path,
              {field::number("min_segment", o.min_segment), field::number("max_bend", o.max_bend),
               field::number("spacing", o.spacing), field::number("regularization", o.regularization),
               field::number("friction", o.friction), field::number("ftol_rel", o.ftol_rel),
               field::number("xtol_rel", o.xtol_rel), field::number("constraint_tol", o.constraint_tol),
               field::integer("max_iterations", o.max_iterations), field::integer("window", o.window),
               field::integer("one_block_points", o.one_block_points),
               field::number("sweep_tol", o.sweep_tol), field::number("sweep_ftol", o.sweep_ftol),
               field::integer("max_sweeps", o.max_sweeps),
               field::number("max_seconds", o.max_seconds),
               field::number("model_size", o.model_size), field::number("angle_tolerance", o.angle_tolerance),
               field::number("length_tolerance", o.length_tolerance), field::text("wire_name", o.wire_name),
               {"start", [&](py::handle v, const std::string& at) { o.start = to_points<2>(v, at); }},
               {"vertex_max_bend",
                [&](py::handle v, const std::string& at) {
                  each_item(v, at, [&](py::handle x, const std::string& i) { o.vertex_max_bend.push_back(to_number(x, i)); });
                }},
               field::choice("algorithm", o.algorithm,
                             {{"slsqp", TargetShapeAlgorithm::slsqp},
                              {"sqp", TargetShapeAlgorithm::sqp},
                              {"auglag_lbfgs", TargetShapeAlgorithm::auglag_lbfgs},
                              {"ccsaq", TargetShapeAlgorithm::ccsaq},
                              {"mma", TargetShapeAlgorithm::mma}})});
  return o;
}

py::dict to_dict(const TargetShapeResult& r) {
  py::list statuses;
  for (const TargetCrossingStatus& s : r.crossings)
    statuses.append(make_dict("status", s.status, "realised", s.realised, "vertex", s.vertex, "bisector",
                              py::make_tuple(s.bisector.x(), s.bisector.y()), "contact_angle", s.contact_angle,
                              "contact_violation", s.contact_violation, "scale", s.scale, "message", s.message, "cause",
                              cause_name(s.cause), "words", s.words));
  py::dict d = make_dict(
      "points", to_array(r.points), "crossing_vertices", r.crossing_vertices, "crossings", statuses, "max_distance",
      r.max_distance, "rms_distance", r.rms_distance, "min_segment", r.min_segment, "max_bend", r.max_bend,
      "max_length_violation", r.max_length_violation, "max_angle_violation", r.max_angle_violation, "iterations",
      r.iterations, "sweeps", r.sweeps, "sqp_blocks", r.sqp_blocks, "sqp_fallbacks", r.sqp_fallbacks, "seconds",
      r.seconds, "nlopt_result", r.nlopt_result, "energy", r.energy, "feasible", r.feasible, "warnings", r.warnings);
  if (!r.target.empty()) {  // a problem with a "plane"
    d["target"] = to_lists(r.target);
    d["length"] = r.length;
  }
  return d;
}

// A problem's "plane": {"origin", "u", "v"}, three 3-vectors (the normal is not needed).
Plane to_plane(py::handle d, const std::string& path) {
  Plane plane;
  auto axis = [](Vec3& out) {
    return [&out](py::handle v, const std::string& at) { out = to_vector<3>(v, at); };
  };
  const auto seen = read_fields(d, path, {{"origin", axis(plane.origin)}, {"u", axis(plane.u)}, {"v", axis(plane.v)}});
  require_keys(seen, path, {"origin", "u", "v"});  // each number finite: to_vector says which is not
  return plane;
}

py::dict optimize(const py::object& points, const py::object& closed_arg, const py::object& crossings,
                  const py::object& options, const py::object& progress) {
  const Polyline2 contour = to_points<2>(points, "points");
  const bool closed = to_bool(closed_arg, "closed");
  const std::vector<TargetCrossing> xs = to_crossings(crossings, "crossings");
  const TargetShapeOptions o = to_options(options, "options");
  PythonProgress reporter(progress);
  const ProgressFn fn = reporter.fn();
  return to_dict(reporter.run([&] { return optimize_target_shape(contour, closed, xs, o, fn); }));
}

py::list optimize_all(const py::object& problems, const py::object& progress, const py::object& threads_arg) {
  const int threads = to_integer(threads_arg, "threads");
  // A list of fewer than two problems is solved on this thread alone (the other would only wait).
  const bool iterator = PyIter_Check(problems.ptr());
  const Py_ssize_t size = iterator || !PySequence_Check(problems.ptr()) ? -1 : PySequence_Size(problems.ptr());
  if (size < 0) PyErr_Clear();  // no length: each_item says what is wrong
  const bool few = size >= 0 && size < 2;
  TargetShapeBatch batch(few && threads == 2 ? 1 : threads);
  // Each problem is handed to the batch as soon as it is read: from an iterator (a generator that
  // prepares the next wire), the other thread solves the first while Python makes the next.
  auto add = [&](py::handle item, const std::string& where) {
    TargetShapeJob job;
    const auto seen = read_fields(
        item, where,
        {{"points", [&](py::handle v, const std::string& at) { job.contour = to_points<2>(v, at); }},
         field::boolean("closed", job.closed),
         {"crossings", [&](py::handle v, const std::string& at) { job.crossings = to_crossings(v, at); }},
         {"options", [&](py::handle v, const std::string& at) { job.options = to_options(v, at); }},
         {"plane", [&](py::handle v, const std::string& at) { job.plane = to_plane(v, at); }}});
    require_keys(seen, where, {"points", "closed"});
    batch.add(std::move(job));
  };
  if (iterator) {
    std::size_t k = 0;
    for (py::handle item : problems) add(item, index_path("problems", k++));
  } else {
    each_item(problems, "problems", add);
  }
  PythonProgress reporter(progress);
  const ProgressFn fn = reporter.fn();
  const std::vector<TargetShapeResult> results = reporter.run([&] { return batch.finish(fn); });
  py::list out;
  for (const TargetShapeResult& r : results) out.append(to_dict(r));
  return out;
}

}  // namespace

void bind_target_shape(py::module_& m) {
  m.def("optimize_target_shape", &optimize, py::arg("points"), py::arg("closed"), py::arg("crossings"),
        py::arg("options") = py::dict(), py::arg("progress") = py::none(),
        R"(Target-shape optimisation of one wire in its plane frame (Sec. 4.3, Eq. 3-5).

points: float64 (n, 2), metres; closed: bool; crossings: list of {"vertex": int (index into
points), "bisector": (x, y) desired h*, "contact_angle": radians (default 2π/3), "active": bool
(default True)}; options: dict of TargetShapeOptions fields (min_segment, max_bend, vertex_max_bend (radians per point of the result), start ((m, 2)
points of a previous result to start from), spacing,
regularization, friction, algorithm ("slsqp" | "sqp" | "auglag_lbfgs" | "ccsaq" | "mma"), ftol_rel,
xtol_rel, constraint_tol, max_iterations (1..1e7), window (0 or 4..10000), sweep_tol, sweep_ftol ([0, 1)), max_sweeps
(1..100000), max_seconds (wall-clock budget, (0, 86400], default 120), model_size,
angle_tolerance, length_tolerance, wire_name); progress: optional callable(stage, fraction) ->
bool, False cancels (raises Cancelled).
Returns {"points": (m, 2), "crossing_vertices": [int], "crossings": [{"status", "realised",
"vertex", "bisector", "contact_angle", "contact_violation", "scale", "message", "cause", "words"}],
"max_distance",
"rms_distance", "min_segment", "max_bend", "max_length_violation", "max_angle_violation",
"iterations", "sweeps", "sqp_blocks", "sqp_fallbacks", "seconds", "nlopt_result", "energy", "feasible",
"warnings"}.
Raises ValueError naming the wire and crossing for bad input.)");
  m.def("optimize_target_shapes", &optimize_all, py::arg("problems"), py::arg("progress") = py::none(),
        py::arg("threads") = 2,
        R"(optimize_target_shape of every problem, on this thread and, with threads=2, one more (the
GIL released throughout).

problems: list (or iterator, read one problem at a time: with threads=2 the other thread starts on
the first while the iterator makes the next) of {"points", "closed", "crossings" (default []),
"options" (default {}), "plane" (optional)}, each as optimize_target_shape's arguments of those
names; "plane": {"origin", "u", "v"} (3-vectors, metres and unit axes) adds to the result "target"
(the points in space, origin + x u + y v, as a list of [x, y, z]) and "length" (their polyline's,
metres); progress: optional callable(stage, fraction)
-> bool, called on this thread only, False cancels every problem (raises Cancelled); threads: 1 or 2.
Returns the list of optimize_target_shape's results, in the problems' order: each the same as that
problem solved alone (the problems are taken the dearest first, which changes only how long the
call takes). Raises the error of the first problem (in their order) that has one, after all
stopped: ValueError naming the problem, wire and crossing for bad input.)");
}

}  // namespace wiresculpt::python
