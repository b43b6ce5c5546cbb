// Layering (Sec. 4.2): wires -> network -> hooks, assembly order and verdict. Converts, releases
// the GIL around the core work, converts back. SI units and radians, as the core.
#include <pybind11/numpy.h>
#include <pybind11/stl.h>

#include <array>
#include <string>
#include <vector>

#include "bindings.hpp"
#include "convert.hpp"
#include "progress.hpp"
#include "wiresculpt/error.hpp"
#include "wiresculpt/layering.hpp"
#include "wiresculpt/network.hpp"
#include "wiresculpt/stability.hpp"

namespace py = pybind11;

namespace wiresculpt::python {
namespace {

WireSpec to_wire(py::handle item, const std::string& where, std::size_t index) {
  WireSpec w;
  Vec3 origin, normal;
  const auto seen = read_fields(item, where,
                                {field::text("name", w.name),
                                 {"origin", [&](py::handle v, const std::string& at) { origin = to_vector<3>(v, at); }},
                                 {"normal", [&](py::handle v, const std::string& at) { normal = to_vector<3>(v, at); }},
                                 field::boolean("closed", w.closed),
                                 {"points", [&](py::handle v, const std::string& at) { w.points = to_points<3>(v, at); }}});
  require_keys(seen, where, {"origin", "normal", "points"});
  if (w.name.empty()) w.name = std::to_string(index);
  w.plane = Plane::make(origin, normal, "wire '" + w.name + "'");
  return w;
}

std::vector<WireSpec> to_wires(py::handle list) {
  std::vector<WireSpec> wires;
  each_item(list, "wires", [&](py::handle item, const std::string& at) { wires.push_back(to_wire(item, at, wires.size())); });
  return wires;
}

/// settings['forbidden_hooks']: [[crossing id, hook (-1 or 1)], ...], read before the network
/// (and so the number of crossings) is known; settings['contour_arrays'] with it (how the
/// network's contours come back, not an option of the core).
struct Forbidden {
  std::vector<std::vector<int>> pairs;
  bool contour_arrays = false;
  bool arrays_too = false;  // settings['arrays_too']: the result's `arrays`

  /// LayeringOptions::allowed_hooks for a network of `crossings` crossings; InputError names the
  /// entry at fault.
  std::vector<std::array<bool, 2>> mask(std::size_t crossings) const {
    if (pairs.empty()) return {};
    std::vector<std::array<bool, 2>> allowed(crossings, {true, true});
    for (std::size_t k = 0; k < pairs.size(); ++k) {
      const std::string at = "settings['forbidden_hooks'][" + std::to_string(k) + "]";
      const auto& p = pairs[k];
      if (p.size() != 2) throw InputError(at + ": expected [crossing id, hook]");
      if (p[0] < 0 || static_cast<std::size_t>(p[0]) >= crossings)
        throw InputError(at + ": crossing " + std::to_string(p[0]) + " does not exist (the network has " +
                         std::to_string(crossings) + " crossings)");
      if (p[1] != -1 && p[1] != 1)
        throw InputError(at + ": the hook must be -1 or 1 (null is always allowed), got " + std::to_string(p[1]));
      allowed[p[0]][p[1] > 0 ? 1 : 0] = false;
    }
    return allowed;
  }
};

void read_settings(py::handle d, NetworkOptions& net, LayeringOptions& lay, Forbidden* forbidden = nullptr) {
  read_fields(d, "settings",
              {field::number("tolerance", net.tolerance), field::number("min_segment", net.min_segment),
               field::number("friction", lay.contact.friction), field::number("contact_angle", lay.contact.contact_angle),
               field::number("bisector_span", lay.contact.bisector_span),
               field::number("straight_angle", lay.contact.straight_angle),
               field::boolean("two_wire_steps", lay.two_wire_steps), field::integer("max_nodes", lay.max_nodes),
               field::integer("max_step_crossings", lay.max_step_crossings),
               field::boolean("in_plane_tiebreak", lay.in_plane_tiebreak),
               field::integer("in_plane_nodes", lay.in_plane_nodes),
               field::boolean("forbid_too_close", lay.forbid_too_close),
               field::number("too_close_angle_tolerance", lay.too_close_angle_tolerance),
               {"forbidden_hooks", [&](py::handle v, const std::string& at) {
                  if (forbidden == nullptr) throw InputError(at + ": only layering() takes forbidden hooks");
                  forbidden->pairs = to_integer_lists(v, at);
                }},
               {"contour_arrays", [&](py::handle v, const std::string& at) {
                  if (forbidden == nullptr) throw InputError(at + ": only layering() returns contours");
                  forbidden->contour_arrays = to_bool(v, at);
                }},
               {"arrays_too", [&](py::handle v, const std::string& at) {
                  if (forbidden == nullptr) throw InputError(at + ": only layering() returns contours");
                  forbidden->arrays_too = to_bool(v, at);
                }}});
}

/// The network in the design document's own keys (docs/formats.md): a wire's points are its
/// `contour` (with the crossing points inserted); a crossing's indices into those contours are
/// its `contour_vertices` (`vertices` always indexes the target, set by the target shape).
/// `hook_metrics`: e_c (Eq. 2) of hook -1 and of hook +1 (the choices a later stage may weigh
/// against each other among equal costs, pipeline.hooks_by_forces).
py::dict network_dict(const Network& net, const std::vector<int>& hooks, const std::vector<double>& metric,
                      const ContactOptions& contact, bool contour_arrays = false) {
  py::list wires, crossings, close;
  for (std::size_t w = 0; w < net.wires.size(); ++w) {
    const WireSpec& s = net.wires[w];
    wires.append(py::dict(py::arg("id") = w, py::arg("name") = s.name, py::arg("origin") = to_list(s.plane.origin),
                          py::arg("normal") = to_list(s.plane.normal), py::arg("closed") = s.closed,
                          py::arg("contour") = contour_arrays ? py::object(to_array(s.points)) : py::object(to_lists(s.points))));
  }
  for (std::size_t c = 0; c < net.crossings.size(); ++c) {
    const Crossing& x = net.crossings[c];
    py::list pair_wires, pair_vertices;
    for (int k = 0; k < 2; ++k) {
      pair_wires.append(x.wires[k]);
      pair_vertices.append(x.vertices[k]);
    }
    crossings.append(py::dict(py::arg("id") = c, py::arg("wires") = pair_wires,
                              py::arg("contour_vertices") = pair_vertices, py::arg("point") = to_list(x.point),
                              py::arg("hook") = hooks[c], py::arg("metric") = metric[c],
                              py::arg("hook_metrics") = py::make_tuple(hook_metric(net, static_cast<int>(c), -1, contact),
                                                                       hook_metric(net, static_cast<int>(c), 1, contact))));
  }
  for (const CrossingGap& g : net.close_crossings)
    close.append(py::dict(py::arg("wire") = g.wire, py::arg("crossings") = py::make_tuple(g.crossings[0], g.crossings[1]),
                          py::arg("distance") = g.distance, py::arg("scale") = g.scale,
                          py::arg("message") = g.message));
  return py::dict(py::arg("wires") = wires, py::arg("crossings") = crossings, py::arg("close_crossings") = close,
                  py::arg("min_scale") = net.min_scale, py::arg("size") = net.size,
                  py::arg("required_size") = net.required_size);
}

py::dict layering_py(const py::object& wire_list, const py::object& settings, const py::object& progress) {
  const std::vector<WireSpec> wires = to_wires(wire_list);
  NetworkOptions net_options;
  LayeringOptions options;
  Forbidden forbidden;
  read_settings(settings, net_options, options, &forbidden);

  PythonProgress reporter(progress);
  const ProgressFn fn = reporter.fn();
  Network net;
  const LayeringResult r = reporter.run([&] {
    net = build_network(wires, net_options, fn);
    options.allowed_hooks = forbidden.mask(net.crossings.size());
    return layering(net, options, fn);
  });

  py::list warnings;
  for (const auto& w : net.warnings) warnings.append(w);
  // the close crossings go in network.close_crossings with their figures; the add-on words them
  // (core/sizes.close_crossing_sentence), with the model's own size
  for (const auto& w : r.warnings) warnings.append(w);
  py::dict out(
      py::arg("network") = network_dict(net, r.hooks, r.metric, options.contact, forbidden.contour_arrays), py::arg("hook") = r.hooks, py::arg("metric") = r.metric,
      py::arg("assembly_order") = r.assembly_order, py::arg("steps") = r.steps,
      py::arg("two_hand_steps") = r.two_hand_steps, py::arg("stable") = r.stable, py::arg("reason") = r.reason,
      py::arg("cause") = cause_name(r.cause), py::arg("forbidden_hooks") = r.forbidden_hooks,
      py::arg("what_moves") = r.what_moves, py::arg("warnings") = warnings,
      py::arg("objective") = py::dict(py::arg("max_metric") = r.max_metric, py::arg("null_crossings") = r.null_crossings,
                                      py::arg("sum_metric") = r.sum_metric,
                                      py::arg("unbalanced_in_plane") = r.unbalanced_in_plane),
      py::arg("complete_search") = r.complete_search, py::arg("in_plane_complete") = r.in_plane_complete,
      py::arg("too_close_forbidden") = r.too_close_forbidden,
      py::arg("stats") = py::dict(py::arg("seconds") = r.stats.seconds, py::arg("lp_solves") = r.stats.lp_solves,
                                  py::arg("nodes") = r.stats.nodes));
  if (forbidden.arrays_too) {
    // The contours again as arrays, for a caller that keeps the network's lists for the design and
    // computes with arrays (converting the lists back costs Python about 0.1 ms per 1,000 points).
    py::list arrays;
    for (const WireSpec& s : net.wires) arrays.append(to_array(s.points));
    out["arrays"] = arrays;
  }
  return out;
}

py::dict check_assembly_py(const py::object& wire_list, const py::object& hook_list, const py::object& step_list,
                           const py::object& settings, const py::object& progress) {
  const std::vector<WireSpec> wires = to_wires(wire_list);
  const std::vector<int> hooks = to_integers<int>(hook_list, "hooks");
  const std::vector<std::vector<int>> steps = to_integer_lists(step_list, "steps");
  NetworkOptions net_options;
  LayeringOptions options;
  read_settings(settings, net_options, options);
  PythonProgress reporter(progress);
  const ProgressFn fn = reporter.fn();
  std::size_t crossings = 0;
  const AssemblyCheck r = reporter.run([&] {
    const Network net = build_network(wires, net_options, fn);
    crossings = net.crossings.size();
    return check_assembly(net, hooks, steps, options.contact, fn);
  });
  return py::dict(py::arg("stable") = r.stable, py::arg("failed_step") = r.failed_step,
                  py::arg("failed_wire") = r.failed_wire, py::arg("lp_solves") = r.lp_solves,
                  py::arg("crossings") = crossings);
}

}  // namespace

void bind_layering(py::module_& m) {
  m.def("check_assembly", &check_assembly_py, py::arg("wires"), py::arg("hooks"), py::arg("steps"),
        py::arg("settings") = py::dict(), py::arg("progress") = py::none(),
        R"(Stability (Eq. 1) of every prefix of an assembly with the given hooks.

wires and settings as for layering(); hooks: -1, 0 or 1 per crossing of the network those wires
form; steps: lists of wire ids added together (the first pair is judged under forces only).
Returns {"stable", "failed_step" (-1 when stable), "failed_wire" (the wire whose unit load could
not be balanced, -1 for the negative-sum load), "lp_solves", "crossings"}. progress(stage,
fraction) -> False cancels (raises Cancelled).)");

  m.def("layering", &layering_py, py::arg("wires"), py::arg("settings") = py::dict(),
        py::arg("progress") = py::none(),
        R"(Crossings, layering and assembly order of planar wires (Sec. 4.1-4.2).

wires: list of {"name": str, "origin": 3 floats, "normal": 3 floats, "points": float64 (n, 3) in
metres on the plane, "closed": bool (default True)}.
settings (all optional): tolerance (m, 1e-5), min_segment (m, 0.015), friction (0.32),
contact_angle (rad, 2pi/3), bisector_span (m, 0.005), straight_angle (rad, 1 degree),
two_wire_steps (True), max_nodes (200000), max_step_crossings (20), in_plane_tiebreak (False), in_plane_nodes (300),
forbidden_hooks ([[crossing id, hook -1 or 1], ...]: hooks the search may not choose; default none),
forbid_too_close (False: when True, also every hook that the target shape cannot realise for want
of a free bending point between two crossings, too_close_hooks), too_close_angle_tolerance (rad, 0.1 deg),
contour_arrays (False: when True the network's contours come back as float64 (n, 3) arrays, not
lists: fewer Python objects for a caller that reads few of them, the plane search's screen),
arrays_too (False: when True the result's "arrays" holds the contours as arrays as well);
unknown keys raise ValueError.
progress(stage, fraction) -> False cancels (raises _wiresculpt.Cancelled).
Returns {"network": {"wires": [{id, name, origin, normal, closed, contour [[x, y, z]] (the points
with the crossing points inserted)}], "crossings": [{id, wires, contour_vertices (indices into
the wires' contours), point, hook, metric, hook_metrics (e_c of hook -1 and of hook +1)}] (the design document's keys, docs/formats.md), "close_crossings": [...], "min_scale", "size",
"required_size"}, "hook": [-1|0|1 per crossing], "metric": [e_c], "assembly_order": [wire ids],
"steps": [[ids]], "two_hand_steps": [step indices], "stable": bool, "reason": str, "cause": str (LayeringCause:
"none" when stable, "alone", "disconnected", "no_crossings", "no_stable_pair", "no_assembly_order", "mechanism",
"search_incomplete"), "forbidden_hooks": int (the hooks the verdict left out), "what_moves": str
(LayeringResult::what_moves, "" unless the hook-relaxed check failed), "warnings": [str], "objective": {max_metric, null_crossings, sum_metric, unbalanced_in_plane},
"complete_search": bool, "in_plane_complete": bool, "too_close_forbidden": [[crossing id, hook]] (the hooks
forbid_too_close forbade), "stats": {seconds, lp_solves, nodes}, "arrays": [the network's
contours as float64 (n, 3) arrays, in its wires' order; only with arrays_too]}. Bad
input raises ValueError naming the wire or key, e.g. wires[1]['points']: expected an (n, 3) array
of numbers, got shape (5, 2).)");
}

}  // namespace wiresculpt::python
