// Layering (Sec. 4.2): wires -> network -> hooks, assembly order and verdict. Converts, releases
// the GIL around the core work, converts back. SI units and radians, as the core.
#include <pybind11/functional.h>
#include <pybind11/numpy.h>
#include <pybind11/stl.h>

#include <exception>
#include <optional>
#include <string>
#include <vector>

#include "bindings.hpp"
#include "progress.hpp"
#include "wiresculpt/error.hpp"
#include "wiresculpt/layering.hpp"
#include "wiresculpt/network.hpp"
#include "wiresculpt/stability.hpp"

namespace py = pybind11;

namespace wiresculpt::python {
namespace {

using Points3 = py::array_t<double, py::array::c_style | py::array::forcecast>;

Vec3 to_vec3(const py::handle& v, const std::string& what) {
  const Points3 a = py::cast<Points3>(v);
  if (a.ndim() != 1 || a.shape(0) != 3) throw InputError(what + " must be 3 numbers");
  return {a.at(0), a.at(1), a.at(2)};
}

py::array_t<double> to_array(const Polyline3& points) {
  py::array_t<double> out({static_cast<py::ssize_t>(points.size()), py::ssize_t{3}});
  auto w = out.mutable_unchecked<2>();
  for (py::ssize_t i = 0; i < w.shape(0); ++i)
    for (py::ssize_t k = 0; k < 3; ++k) w(i, k) = points[static_cast<std::size_t>(i)][k];
  return out;
}

py::list to_list(const Vec3& v) { return py::cast(std::vector<double>{v.x(), v.y(), v.z()}); }

WireSpec to_wire(const py::handle& item, std::size_t index) {
  const py::dict d = py::cast<py::dict>(item);
  const std::string who = "wire " + std::to_string(index);
  WireSpec w;
  std::optional<Vec3> origin, normal;
  bool have_points = false;
  for (const auto& [k, v] : d) {
    const std::string key = py::cast<std::string>(k);
    if (key == "name") w.name = py::cast<std::string>(v);
    else if (key == "origin") origin = to_vec3(v, who + ": origin");
    else if (key == "normal") normal = to_vec3(v, who + ": normal");
    else if (key == "closed") w.closed = py::cast<bool>(v);
    else if (key == "points") {
      const Points3 a = py::cast<Points3>(v);
      if (a.ndim() != 2 || a.shape(1) != 3) throw InputError(who + ": points must be an (n, 3) array");
      const auto r = a.unchecked<2>();
      for (py::ssize_t i = 0; i < r.shape(0); ++i) w.points.emplace_back(r(i, 0), r(i, 1), r(i, 2));
      have_points = true;
    } else {
      throw InputError(who + ": unknown key '" + key + "'");
    }
  }
  if (w.name.empty()) w.name = std::to_string(index);
  if (!origin || !normal || !have_points)
    throw InputError("wire '" + w.name + "' needs 'origin', 'normal' and 'points'");
  w.plane = Plane::make(*origin, *normal, "wire '" + w.name + "'");
  return w;
}

void read_settings(const py::dict& d, NetworkOptions& net, LayeringOptions& lay) {
  for (const auto& [k, v] : d) {
    const std::string key = py::cast<std::string>(k);
    if (key == "tolerance") net.tolerance = py::cast<double>(v);
    else if (key == "min_segment") net.min_segment = py::cast<double>(v);
    else if (key == "friction") lay.contact.friction = py::cast<double>(v);
    else if (key == "contact_angle") lay.contact.contact_angle = py::cast<double>(v);
    else if (key == "bisector_span") lay.contact.bisector_span = py::cast<double>(v);
    else if (key == "straight_angle") lay.contact.straight_angle = py::cast<double>(v);
    else if (key == "two_wire_steps") lay.two_wire_steps = py::cast<bool>(v);
    else if (key == "max_nodes") lay.max_nodes = py::cast<long>(v);
    else if (key == "max_step_crossings") lay.max_step_crossings = py::cast<int>(v);
    else if (key == "in_plane_tiebreak") lay.in_plane_tiebreak = py::cast<bool>(v);
    else if (key == "in_plane_nodes") lay.in_plane_nodes = py::cast<long>(v);
    else throw InputError("layering settings: unknown key '" + key + "'");
  }
}

py::dict network_dict(const Network& net, const std::vector<int>& hooks) {
  py::list wires, crossings, close;
  for (std::size_t w = 0; w < net.wires.size(); ++w) {
    const WireSpec& s = net.wires[w];
    wires.append(py::dict(py::arg("id") = w, py::arg("name") = s.name, py::arg("origin") = to_list(s.plane.origin),
                          py::arg("normal") = to_list(s.plane.normal), py::arg("closed") = s.closed,
                          py::arg("points") = to_array(s.points)));
  }
  for (std::size_t c = 0; c < net.crossings.size(); ++c) {
    const Crossing& x = net.crossings[c];
    crossings.append(py::dict(py::arg("id") = c, py::arg("wires") = py::make_tuple(x.wires[0], x.wires[1]),
                              py::arg("vertices") = py::make_tuple(x.vertices[0], x.vertices[1]),
                              py::arg("point") = to_list(x.point), py::arg("hook") = hooks[c]));
  }
  for (const CrossingGap& g : net.close_crossings)
    close.append(py::dict(py::arg("wire") = g.wire, py::arg("crossings") = py::make_tuple(g.crossings[0], g.crossings[1]),
                          py::arg("distance") = g.distance, py::arg("scale") = g.scale,
                          py::arg("message") = g.message));
  return py::dict(py::arg("wires") = wires, py::arg("crossings") = crossings, py::arg("close_crossings") = close,
                  py::arg("min_scale") = net.min_scale, py::arg("size") = net.size,
                  py::arg("required_size") = net.required_size);
}

py::dict layering_py(const py::list& wire_list, const py::dict& settings, const py::object& progress) {
  std::vector<WireSpec> wires;
  for (std::size_t i = 0; i < wire_list.size(); ++i) wires.push_back(to_wire(wire_list[i], i));
  NetworkOptions net_options;
  LayeringOptions options;
  read_settings(settings, net_options, options);

  PythonProgress reporter(progress);
  const ProgressFn fn = reporter.fn();
  Network net;
  const LayeringResult r = reporter.run([&] {
    net = build_network(wires, net_options);
    return layering(net, options, fn);
  });

  py::list warnings;
  for (const auto& w : net.warnings) warnings.append(w);
  for (const auto& g : net.close_crossings) warnings.append(g.message);
  for (const auto& w : r.warnings) warnings.append(w);
  return py::dict(
      py::arg("network") = network_dict(net, r.hooks), py::arg("hook") = r.hooks, py::arg("metric") = r.metric,
      py::arg("assembly_order") = r.assembly_order, py::arg("steps") = r.steps,
      py::arg("two_hand_steps") = r.two_hand_steps, py::arg("stable") = r.stable, py::arg("reason") = r.reason,
      py::arg("warnings") = warnings,
      py::arg("objective") = py::dict(py::arg("max_metric") = r.max_metric, py::arg("null_crossings") = r.null_crossings,
                                      py::arg("sum_metric") = r.sum_metric,
                                      py::arg("unbalanced_in_plane") = r.unbalanced_in_plane),
      py::arg("complete_search") = r.complete_search, py::arg("in_plane_complete") = r.in_plane_complete,
      py::arg("stats") = py::dict(py::arg("seconds") = r.stats.seconds, py::arg("lp_solves") = r.stats.lp_solves,
                                  py::arg("nodes") = r.stats.nodes));
}

// Eq. 1 for every prefix of a given assembly: the check after a later stage changed hooks.
py::dict check_assembly_py(const py::list& wire_list, const std::vector<int>& hooks,
                           const std::vector<std::vector<int>>& steps, const py::dict& settings) {
  std::vector<WireSpec> wires;
  for (std::size_t i = 0; i < wire_list.size(); ++i) wires.push_back(to_wire(wire_list[i], i));
  NetworkOptions net_options;
  LayeringOptions options;
  read_settings(settings, net_options, options);
  int failed_step = -1, failed_wire = -1, lp_solves = 0;
  std::size_t crossings = 0;
  {
    py::gil_scoped_release release;
    const Network net = build_network(wires, net_options);
    crossings = net.crossings.size();
    if (hooks.size() != crossings)
      throw InputError("check_assembly: " + std::to_string(hooks.size()) + " hooks given for " +
                       std::to_string(crossings) + " crossings");
    std::vector<int> prefix;
    for (std::size_t k = 0; k < steps.size() && failed_step < 0; ++k) {
      prefix.insert(prefix.end(), steps[k].begin(), steps[k].end());
      StabilityOptions check;
      check.forces_only = k == 0 && prefix.size() == 2;  // the first pair: forces only (Sec. 4.2)
      const StabilityResult r = check_stability(net, prefix, hooks, options.contact, check);
      lp_solves += r.lp_solves;
      if (!r.stable) {
        failed_step = static_cast<int>(k);
        failed_wire = r.failed_wire;
      }
    }
  }
  return py::dict(py::arg("stable") = failed_step < 0, py::arg("failed_step") = failed_step,
                  py::arg("failed_wire") = failed_wire, py::arg("lp_solves") = lp_solves,
                  py::arg("crossings") = crossings);
}

}  // namespace

void bind_layering(py::module_& m) {
  m.def("check_assembly", &check_assembly_py, py::arg("wires"), py::arg("hooks"), py::arg("steps"),
        py::arg("settings") = py::dict(),
        R"(Stability (Eq. 1) of every prefix of an assembly with the given hooks.

wires and settings as for layering(); hooks: -1, 0 or 1 per crossing of the network those wires
form; steps: lists of wire ids added together (the first pair is judged under forces only).
Returns {"stable", "failed_step" (-1 when stable), "failed_wire" (the wire whose unit load could
not be balanced, -1 for the negative-sum load), "lp_solves", "crossings"}.)");

  m.def("layering", &layering_py, py::arg("wires"), py::arg("settings") = py::dict(),
        py::arg("progress") = py::none(),
        R"(Crossings, layering and assembly order of planar wires (Sec. 4.1-4.2).

wires: list of {"name": str, "origin": 3 floats, "normal": 3 floats, "points": float64 (n, 3) in
metres on the plane, "closed": bool (default True)}.
settings (all optional): tolerance (m, 1e-5), min_segment (m, 0.015), friction (0.32),
contact_angle (rad, 2pi/3), bisector_span (m, 0.005), straight_angle (rad, 1 degree),
two_wire_steps (True), max_nodes (200000), max_step_crossings (20), in_plane_tiebreak (True), in_plane_nodes (300);
unknown keys raise ValueError.
progress(stage, fraction) -> False cancels (raises _wiresculpt.Cancelled).
Returns {"network": {"wires": [{id, name, origin, normal, closed, points (n, 3)}], "crossings":
[{id, wires, vertices, point, hook}], "close_crossings": [...], "min_scale", "size",
"required_size"}, "hook": [-1|0|1 per crossing], "metric": [e_c], "assembly_order": [wire ids],
"steps": [[ids]], "two_hand_steps": [step indices], "stable": bool, "reason": str,
"warnings": [str], "objective": {max_metric, null_crossings, sum_metric, unbalanced_in_plane},
"complete_search": bool, "in_plane_complete": bool,
"stats": {seconds, lp_solves, nodes}}. Bad input raises ValueError naming the wire or key.)");
}

}  // namespace wiresculpt::python
