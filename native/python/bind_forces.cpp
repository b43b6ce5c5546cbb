// Forces, rest shapes, cuts and load capacity (Sec. 4.4 and beyond; forces_and_rest.hpp composes
// them): converts, releases the GIL around the core call, converts back to the design's own keys.
// SI units and radians, as the core; degrees where the design's key says so (angle_deg).
#include <pybind11/numpy.h>
#include <pybind11/stl.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <string>
#include <vector>

#include "bindings.hpp"
#include "convert.hpp"
#include "progress.hpp"
#include "wiresculpt/error.hpp"
#include "wiresculpt/forces.hpp"
#include "wiresculpt/forces_and_rest.hpp"

namespace py = pybind11;

namespace wiresculpt::python {
namespace {

struct Input {
  Network net;
  std::vector<int> hooks;
  std::vector<int> requested_cuts;
};

WireSpec to_wire(py::handle item, const std::string& where, std::size_t index, int& cut) {
  WireSpec w;
  Vec3 origin, normal;
  cut = -1;
  const auto seen = read_fields(
      item, where,
      {field::text("name", w.name),
       {"origin", [&](py::handle v, const std::string& at) { origin = to_vector<3>(v, at); }},
       {"normal", [&](py::handle v, const std::string& at) { normal = to_vector<3>(v, at); }},
       {"target", [&](py::handle v, const std::string& at) { w.points = to_points<3>(v, at); }},
       field::boolean("closed", w.closed),
       {"cut", [&](py::handle v, const std::string& at) { cut = v.is_none() ? -1 : to_integer<int>(v, at); }}});
  require_keys(seen, where, {"origin", "normal", "target"});
  if (w.name.empty()) w.name = std::to_string(index);
  if (w.points.size() < (w.closed ? 3u : 2u)) throw InputError("wire '" + w.name + "' has too few target points");
  w.plane = Plane::make(origin, normal, "wire '" + w.name + "'");
  return w;
}

Crossing to_crossing(py::handle item, const std::string& where, const Network& net, int& hook) {
  Crossing x;
  hook = 0;
  auto pair = [](py::handle v, const std::string& at, const char* what) {
    const std::vector<int> ids = to_integers<int>(v, at);
    if (ids.size() != 2) throw InputError(at + ": expected two " + what + ", got " + std::to_string(ids.size()));
    return std::array<int, 2>{ids[0], ids[1]};
  };
  const auto seen = read_fields(
      item, where,
      {{"wires", [&](py::handle v, const std::string& at) { x.wires = pair(v, at, "wire ids"); }},
       {"vertices", [&](py::handle v, const std::string& at) { x.vertices = pair(v, at, "target indices"); }},
       field::integer("hook", hook)});
  require_keys(seen, where, {"wires", "vertices"});
  const int P = static_cast<int>(net.wires.size());
  for (int k = 0; k < 2; ++k) {
    if (x.wires[k] < 0 || x.wires[k] >= P) throw InputError(where + ": wire id " + std::to_string(x.wires[k]) + " does not exist");
    const auto& pts = net.wires[x.wires[k]].points;
    if (x.vertices[k] < 0 || x.vertices[k] >= static_cast<int>(pts.size()))
      throw InputError(where + ": vertex " + std::to_string(x.vertices[k]) + " is outside wire '" +
                       net.wires[x.wires[k]].name + "''s " + std::to_string(pts.size()) + " target points");
  }
  if (x.wires[0] == x.wires[1]) throw InputError(where + " joins a wire to itself");
  const Vec3 p0 = net.wires[x.wires[0]].points[x.vertices[0]];
  const Vec3 p1 = net.wires[x.wires[1]].points[x.vertices[1]];
  if ((p0 - p1).norm() > 1e-6)
    throw InputError(where + ": its points on wire '" + net.wires[x.wires[0]].name + "' and wire '" +
                     net.wires[x.wires[1]].name + "' are " + std::to_string((p0 - p1).norm() * 1000) +
                     " mm apart; they must coincide");
  x.point = 0.5 * (p0 + p1);
  return x;
}

Input read_input(py::handle wire_list, py::handle crossing_list) {
  Input in;
  each_item(wire_list, "wires", [&](py::handle item, const std::string& at) {
    int cut = -1;
    in.net.wires.push_back(to_wire(item, at, in.net.wires.size(), cut));
    in.requested_cuts.push_back(cut);
  });
  each_item(crossing_list, "crossings", [&](py::handle item, const std::string& at) {
    int hook = 0;
    in.net.crossings.push_back(to_crossing(item, at, in.net, hook));
    in.hooks.push_back(hook);
  });
  return in;
}

/// Radians to degrees as Python's math.degrees computes it (the design stores degrees).
double degrees(double radians) { return radians / (3.14159265358979323846 / 180.0); }

py::dict load_capacity_dict(const LoadCapacityResult& lc, const Network& net) {
  py::dict d;
  d["weight_N"] = lc.weight;
  d["length"] = lc.length;
  py::dict base, status;
  for (const LoadDirection& ld : lc.directions) {
    d[py::str(ld.name)] = std::isfinite(ld.multiple) ? py::object(py::float_(ld.multiple)) : py::object(py::none());
    py::list names;
    for (int w : ld.base) names.append(net.wires[w].name);
    base[py::str(ld.name)] = names;
    status[py::str(ld.name)] = ld.status;
  }
  d["base"] = base;
  d["status"] = status;
  return d;
}

py::dict forces_and_rest_py(const py::object& wire_list, const py::object& crossing_list, const py::object& step_list,
                            const py::object& material, const py::object& settings, const py::object& progress) {
  Input in = read_input(wire_list, crossing_list);
  const std::vector<std::vector<int>> steps = to_integer_lists(step_list, "steps");
  ForcesAndRestOptions o;
  std::string material_name;  // shown by the caller only
  const auto given = read_fields(material, "material",
                                 {field::number("bending_stiffness", o.rest.bending_stiffness),
                                  field::number("max_torque", o.forces.max_torque),
                                  field::number("friction", o.forces.friction),
                                  field::number("wire_diameter", o.load.wire_diameter),
                                  field::number("density", o.load.density),
                                  field::number("shear_modulus", o.deflection_options.shear_modulus),
                                  field::text("name", material_name)});
  o.load_capacity = std::find(given.begin(), given.end(), "density") != given.end();
  o.deflection = std::find(given.begin(), given.end(), "shear_modulus") != given.end();
  o.deflection_options.wire_diameter = o.load.wire_diameter;
  read_fields(settings, "settings",
              {field::number("torque_fraction", o.forces.torque_fraction), field::number("max_bend", o.rest.max_bend),
               field::number("assembly_weight", o.forces.assembly_weight), field::number("gravity", o.load.gravity),
               field::number("load_factor", o.load_factor), field::number("tie_tolerance", o.forces.tie_tolerance),
               field::number("load_capacity_within", o.load_capacity_within),
               field::boolean("least_out_of_plane", o.forces.least_out_of_plane), field::number("deflection_limit", o.deflection_limit),
               field::boolean("carried_3d", o.forces.carried_3d), field::number("carried_margin", o.forces.carried_margin),
               field::number("carried_share", o.forces.carried_share),
               {"carried_gravity", [&](py::handle v, const std::string& at) { o.forces.carried.gravity = to_vector<3>(v, at); }},
               {"carried_supports", [&](py::handle v, const std::string& at) {
                  for (const std::vector<int>& s : to_integer_lists(v, at)) {
                    if (s.size() != 2) throw InputError(at + ": each support is [wire, target vertex]");
                    o.forces.carried.supports.push_back({s[0], s[1]});
                  }
                }},
               field::integer("max_iterations", o.forces.max_iterations),
               field::choice("torque_bound", o.forces.torque_bound,
                             {{"3d", TorqueBound::full_3d}, {"in_plane", TorqueBound::in_plane}}),
               field::choice("algorithm", o.forces.algorithm,
                             {{"lp_then_slsqp", ForceAlgorithm::lp_then_slsqp},
                              {"lp", ForceAlgorithm::lp},
                              {"slsqp", ForceAlgorithm::slsqp}})});

  PythonProgress reporter(progress);
  const ProgressFn fn = reporter.fn();
  const ForcesAndRestResult r =
      reporter.run([&] { return forces_and_rest(in.net, in.hooks, steps, in.requested_cuts, o, fn); });
  const ForceResult& fr = r.forces;

  // Every key below is the design document's own (docs/formats.md): the forces stage copies them.
  py::list crossings;
  for (std::size_t c = 0; c < in.net.crossings.size(); ++c) {
    py::list share;
    share.append(fr.out_of_plane[c][0]);
    share.append(fr.out_of_plane[c][1]);
    py::dict crossing(py::arg("force") = to_list(fr.forces[c]), py::arg("normal_force") = fr.normal[c],
                      py::arg("out_of_plane") = share);
    if (in.hooks[c] != 0) {  // the four unit forces on wires[0] its force was chosen among
      py::list pyramid;
      for (const Vec3& q : target_pyramid(in.net, static_cast<int>(c), in.hooks[c], o.forces.friction))
        pyramid.append(to_list(q));
      crossing["pyramid"] = pyramid;
      if (!fr.carried_forces.empty()) {
        crossing["carried_force"] = to_list(fr.carried_forces[c]);
        crossing["carried_weight"] = to_list(fr.carried_weights[c]);
      }
    }
    crossings.append(crossing);
  }
  py::list wires;
  for (std::size_t w = 0; w < r.rests.size(); ++w) {
    const RestShapeResult& rest = r.rests[w];
    py::list over;
    for (std::size_t i = 0; i < rest.over_bend.size(); ++i)
      over.append(py::dict(py::arg("vertex") = rest.over_bend[i], py::arg("angle_deg") = degrees(rest.over_bend_angle[i])));
    py::dict wire;
    if (!r.deflections.empty()) {
      wire["out_of_plane_deflection"] = r.deflections[w].max_out_of_plane;
      wire["out_of_plane_deflection_vertex"] = r.deflections[w].max_out_of_plane_vertex;
    }
    wire.attr("update")(py::dict(py::arg("cut") = r.cuts[w], py::arg("rest") = to_lists(rest.rest),
                          py::arg("rest_angles") = rest.rest_angles, py::arg("target_angles") = rest.target_angles,
                          py::arg("closure_gap") = rest.closure_gap, py::arg("max_torque") = fr.wires[w].max_torque,
                          py::arg("max_torque_vertex") = fr.wires[w].max_torque_vertex,
                          py::arg("max_out_of_plane_torque") = fr.wires[w].max_out_of_plane,
                          py::arg("max_torque_3d") = fr.wires[w].max_torque_3d, py::arg("rest_over_bend") = over));
    wires.append(wire);
  }
  const py::object load_seconds = r.load_capacity ? py::object(py::float_(r.load_capacity->seconds)) : py::none();
  py::dict forces_stage(
      py::arg("seconds") = fr.seconds, py::arg("lp_seconds") = fr.lp_seconds, py::arg("nlp_seconds") = fr.nlp_seconds,
      py::arg("lp_iterations") = fr.lp_iterations, py::arg("lp_rounds") = fr.lp_rounds,
      py::arg("iterations") = fr.iterations, py::arg("working_set_rounds") = fr.working_set_rounds,
      py::arg("working_set_rows") = fr.working_set_rows, py::arg("method") = fr.method,
      py::arg("nlopt_result") = fr.nlopt_result, py::arg("g_stb") = fr.g_stb, py::arg("g_asm") = fr.g_asm,
      py::arg("assembly_residual") = fr.assembly_residual, py::arg("equilibrium_residual") = fr.equilibrium_residual,
      py::arg("t_max") = fr.t_max, py::arg("torque_active") = fr.torque_active,
      py::arg("torque_bound") = torque_bound_name(fr.torque_bound), py::arg("load_capacity_seconds") = load_seconds,
      py::arg("carried_3d") = fr.carried_3d);
  py::dict rest_stage(py::arg("seconds") = r.rest_seconds, py::arg("max_closure_gap") = r.max_closure_gap,
                      py::arg("over_bend") = r.over_bend);
  if (o.deflection) rest_stage["deflection_seconds"] = r.deflection_seconds;
  std::vector<std::string> warnings = fr.warnings;
  warnings.insert(warnings.end(), r.warnings.begin(), r.warnings.end());
  py::dict out_of_plane(py::arg("mean") = fr.mean_out_of_plane, py::arg("max") = fr.max_out_of_plane,
                        py::arg("mean_to_max_force") = fr.mean_out_of_plane_to_max_force,
                        py::arg("max_to_max_force") = fr.max_out_of_plane_to_max_force,
                        py::arg("crossings") = r.hooked_crossings);
  // +inf (every direction holds any load) is None: JSON has no infinity.
  auto multiple = [](double m) { return std::isfinite(m) ? py::object(py::float_(m)) : py::object(py::none()); };
  py::object load_factor = py::none();
  if (r.load_factor)
    load_factor = py::dict(py::arg("asked") = r.load_factor->asked, py::arg("reached") = multiple(r.load_factor->reached),
                           py::arg("at_plastic_limit") = multiple(r.load_factor->at_plastic_limit),
                           py::arg("weakest") = r.load_factor->weakest, py::arg("limited") = r.load_factor->limited);
  return py::dict(py::arg("crossings") = crossings, py::arg("wires") = wires, py::arg("out_of_plane") = out_of_plane,
                  py::arg("torque_fraction") = r.torque_fraction, py::arg("load_factor") = load_factor,
                  py::arg("load_capacity") = r.load_capacity ? py::object(load_capacity_dict(*r.load_capacity, in.net))
                                                             : py::object(py::none()),
                  py::arg("stages") = py::dict(py::arg("forces") = forces_stage, py::arg("rest_shape") = rest_stage),
                  py::arg("warnings") = warnings);
}

}  // namespace

void bind_forces(py::module_& m) {
  m.def("forces_and_rest", &forces_and_rest_py, py::arg("wires"), py::arg("crossings"), py::arg("steps"),
        py::arg("material"), py::arg("settings") = py::dict(), py::arg("progress") = py::none(),
        R"(Internal contact forces (Eq. 6-8), cuts, rest shapes (Eq. 9-12) and load capacity.

wires: [{"name", "origin": 3 floats, "normal": 3 floats, "target": float64 (n, 3) metres,
"closed": bool, "cut": int (index into target; -1 or None: automatic)}];
crossings: [{"wires": (i, j), "vertices": (r, s) into the targets, "hook": -1 | 0 | 1}];
steps: the assembly, lists of wire ids (G_asm; may be empty);
material: {"bending_stiffness" N m^2, "max_torque" N m, "friction", "wire_diameter" m,
"density" kg/m^3 (without it no load capacity), "shear_modulus" Pa (without it no out-of-plane
deflection), "name" (ignored)};
settings: {"torque_fraction" (1), "load_factor" (0: off; > 0: the torque fraction is the least
whose load capacity holds this multiple of the weight in all six directions, capped at 1; needs
a density; forces_and_rest.hpp), "max_bend" rad (2pi/3), "assembly_weight" (0.05),
"algorithm" ("lp_then_slsqp" | "lp" | "slsqp"), "gravity" m/s^2 (9.81), "max_iterations",
"torque_bound" ("3d": |t_v| <= t_max, default | "in_plane": its plane-normal part only),
"least_out_of_plane" (True), "tie_tolerance" (relative loss of G_stb allowed for it; forces.hpp) and
"load_capacity_within" (rad, 0: off; > 0: no load capacity, None, when a rest angle is beyond it)}.
progress(stage, fraction) -> False cancels (raises Cancelled).
Returns the design document's own keys (docs/formats.md), for the forces stage to copy:
{"crossings": [{"force": [3] N on wires[0] by wires[1], "normal_force": N, "out_of_plane":
[share on wires[0], on wires[1]], "pyramid" (hooked crossings): [4][3] the unit forces on
wires[0] the force is a nonnegative combination of (forces.hpp, target_pyramid)}], "wires": [{"cut", "rest": [[x, y]] metres in the plane frame,
"rest_angles", "target_angles" (rad, per rest point), "closure_gap" m, "max_torque" N m,
"max_torque_vertex", "max_out_of_plane_torque" N m, "max_torque_3d" N m, "rest_over_bend":
[{"vertex", "angle_deg"}], with a shear modulus "out_of_plane_deflection" m (the 3D frame,
deflection.hpp; warnings name wires over settings "deflection_limit", m, 0.002) and
"out_of_plane_deflection_vertex"}], "out_of_plane": {mean, max, mean_to_max_force, max_to_max_force,
crossings}, "torque_fraction": the fraction used, "load_factor": {"asked", "reached" (the
weakest multiple held at that fraction), "at_plastic_limit" (at fraction 1; None: unbounded),
"weakest", "limited" (the plastic limit falls short)} or None, "load_capacity": {"weight_N", "length", "+x", "-x", "+y", "-y", "+z", "-z"
(multiples of the weight; None when unbounded), "base" (wire names per direction), "status"} or
None, "stages": {"forces": {seconds, lp_seconds, nlp_seconds, lp_iterations, lp_rounds,
iterations, working_set_rounds, working_set_rows, method, nlopt_result, g_stb, g_asm,
assembly_residual, equilibrium_residual, t_max, torque_active, torque_bound,
load_capacity_seconds}, "rest_shape": {seconds, max_closure_gap, over_bend}}, "warnings": [str]}.
Bad input raises ValueError naming the wire, crossing or key, e.g. "material['friction']:
expected a number, got str"; unknown keys are named too.)");
}

}  // namespace wiresculpt::python
