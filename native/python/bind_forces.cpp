// Forces, rest shapes, cuts and load capacity (Sec. 4.4 and beyond): converts, releases the GIL
// around the core work, converts back. SI units and radians, as the core.
#include <pybind11/functional.h>
#include <pybind11/numpy.h>
#include <pybind11/stl.h>

#include <chrono>
#include <cmath>
#include <exception>
#include <optional>
#include <string>
#include <vector>

#include "bindings.hpp"
#include "progress.hpp"
#include "wiresculpt/error.hpp"
#include "wiresculpt/forces.hpp"
#include "wiresculpt/load_capacity.hpp"
#include "wiresculpt/rest_shape.hpp"

namespace py = pybind11;

namespace wiresculpt::python {
namespace {

using Array = py::array_t<double, py::array::c_style | py::array::forcecast>;

Vec3 to_vec3(const py::handle& v, const std::string& what) {
  const Array a = py::cast<Array>(v);
  if (a.ndim() != 1 || a.shape(0) != 3) throw InputError(what + " must be 3 numbers");
  return {a.at(0), a.at(1), a.at(2)};
}

py::list to_list(const Vec3& v) { return py::cast(std::vector<double>{v.x(), v.y(), v.z()}); }

struct Input {
  Network net;
  std::vector<int> hooks;
  std::vector<int> requested_cuts;
};

Input read_input(const py::list& wire_list, const py::list& crossing_list) {
  Input in;
  for (std::size_t i = 0; i < wire_list.size(); ++i) {
    const py::dict d = py::cast<py::dict>(wire_list[i]);
    const std::string who = "wire " + std::to_string(i);
    WireSpec w;
    std::optional<Vec3> origin, normal;
    bool have_points = false;
    int cut = -1;
    for (const auto& [k, v] : d) {
      const std::string key = py::cast<std::string>(k);
      if (key == "name") w.name = py::cast<std::string>(v);
      else if (key == "origin") origin = to_vec3(v, who + ": origin");
      else if (key == "normal") normal = to_vec3(v, who + ": normal");
      else if (key == "closed") w.closed = py::cast<bool>(v);
      else if (key == "cut") cut = v.is_none() ? -1 : py::cast<int>(v);
      else if (key == "target") {
        const Array a = py::cast<Array>(v);
        if (a.ndim() != 2 || a.shape(1) != 3) throw InputError(who + ": target must be an (n, 3) array");
        const auto r = a.unchecked<2>();
        for (py::ssize_t p = 0; p < r.shape(0); ++p) w.points.emplace_back(r(p, 0), r(p, 1), r(p, 2));
        have_points = true;
      } else {
        throw InputError(who + ": unknown key '" + key + "' (expected name, origin, normal, target, closed, cut)");
      }
    }
    if (w.name.empty()) w.name = std::to_string(i);
    if (!origin || !normal || !have_points) throw InputError("wire '" + w.name + "' needs 'origin', 'normal' and 'target'");
    if (w.points.size() < (w.closed ? 3u : 2u)) throw InputError("wire '" + w.name + "' has too few target points");
    w.plane = Plane::make(*origin, *normal, "wire '" + w.name + "'");
    in.net.wires.push_back(std::move(w));
    in.requested_cuts.push_back(cut);
  }
  const int P = static_cast<int>(in.net.wires.size());
  for (std::size_t c = 0; c < crossing_list.size(); ++c) {
    const py::dict d = py::cast<py::dict>(crossing_list[c]);
    const std::string who = "crossing " + std::to_string(c);
    Crossing x;
    int hook = 0;
    bool have_w = false, have_v = false;
    for (const auto& [k, v] : d) {
      const std::string key = py::cast<std::string>(k);
      if (key == "wires") {
        const auto ids = py::cast<std::vector<int>>(v);
        if (ids.size() != 2) throw InputError(who + ": 'wires' must be two wire ids");
        x.wires = {ids[0], ids[1]};
        have_w = true;
      } else if (key == "vertices") {
        const auto ids = py::cast<std::vector<int>>(v);
        if (ids.size() != 2) throw InputError(who + ": 'vertices' must be two target indices");
        x.vertices = {ids[0], ids[1]};
        have_v = true;
      } else if (key == "hook") {
        hook = py::cast<int>(v);
      } else {
        throw InputError(who + ": unknown key '" + key + "' (expected wires, vertices, hook)");
      }
    }
    if (!have_w || !have_v) throw InputError(who + " needs 'wires' and 'vertices'");
    for (int k = 0; k < 2; ++k) {
      if (x.wires[k] < 0 || x.wires[k] >= P) throw InputError(who + ": wire id " + std::to_string(x.wires[k]) + " does not exist");
      const auto& pts = in.net.wires[x.wires[k]].points;
      if (x.vertices[k] < 0 || x.vertices[k] >= static_cast<int>(pts.size()))
        throw InputError(who + ": vertex " + std::to_string(x.vertices[k]) + " is outside wire '" +
                         in.net.wires[x.wires[k]].name + "''s " + std::to_string(pts.size()) + " target points");
    }
    if (x.wires[0] == x.wires[1]) throw InputError(who + " joins a wire to itself");
    const Vec3 p0 = in.net.wires[x.wires[0]].points[x.vertices[0]];
    const Vec3 p1 = in.net.wires[x.wires[1]].points[x.vertices[1]];
    if ((p0 - p1).norm() > 1e-6)
      throw InputError(who + ": its points on wire '" + in.net.wires[x.wires[0]].name + "' and wire '" +
                       in.net.wires[x.wires[1]].name + "' are " + std::to_string((p0 - p1).norm() * 1000) +
                       " mm apart; they must coincide");
    x.point = 0.5 * (p0 + p1);
    in.net.crossings.push_back(x);
    in.hooks.push_back(hook);
  }
  return in;
}

py::dict forces_and_rest_py(const py::list& wire_list, const py::list& crossing_list,
                            const std::vector<std::vector<int>>& steps, const py::dict& material,
                            const py::dict& settings, const py::object& progress) {
  Input in = read_input(wire_list, crossing_list);
  ForceOptions fo;
  RestShapeOptions ro;
  LoadCapacityOptions lo;
  bool have_density = false;
  for (const auto& [k, v] : material) {
    const std::string key = py::cast<std::string>(k);
    if (key == "bending_stiffness") ro.bending_stiffness = py::cast<double>(v);
    else if (key == "max_torque") fo.max_torque = py::cast<double>(v);
    else if (key == "friction") fo.friction = py::cast<double>(v);
    else if (key == "wire_diameter") lo.wire_diameter = py::cast<double>(v);
    else if (key == "density") {
      lo.density = py::cast<double>(v);
      have_density = true;
    } else if (key == "name") {
      // shown by the caller only
    } else {
      throw InputError("material: unknown key '" + key + "'");
    }
  }
  for (const auto& [k, v] : settings) {
    const std::string key = py::cast<std::string>(k);
    if (key == "torque_fraction") fo.torque_fraction = py::cast<double>(v);
    else if (key == "max_bend") ro.max_bend = py::cast<double>(v);
    else if (key == "assembly_weight") fo.assembly_weight = py::cast<double>(v);
    else if (key == "gravity") lo.gravity = py::cast<double>(v);
    else if (key == "max_iterations") fo.max_iterations = py::cast<int>(v);
    else if (key == "torque_bound") fo.torque_bound = lo.torque_bound = parse_torque_bound(py::cast<std::string>(v), "settings: torque_bound");
    else if (key == "algorithm") {
      const auto a = py::cast<std::string>(v);
      if (a == "lp_then_slsqp") fo.algorithm = ForceAlgorithm::lp_then_slsqp;
      else if (a == "lp") fo.algorithm = ForceAlgorithm::lp;
      else if (a == "slsqp") fo.algorithm = ForceAlgorithm::slsqp;
      else throw InputError("settings: algorithm must be lp_then_slsqp, lp or slsqp, not '" + a + "'");
    } else {
      throw InputError("settings: unknown key '" + key + "'");
    }
  }

  PythonProgress reporter(progress);
  const ProgressFn fn = reporter.fn();
  std::vector<int> cuts;
  ForceResult fr;
  std::vector<RestShapeResult> rests;
  std::optional<LoadCapacityResult> lc;
  double rest_seconds = 0.0;
  reporter.run([&] {
    cuts = choose_cuts(in.net, in.requested_cuts);
    fr = optimize_forces(in.net, in.hooks, steps, cuts, fo, fn);
    const auto t0 = std::chrono::steady_clock::now();
    for (int w = 0; w < static_cast<int>(in.net.wires.size()); ++w)
      rests.push_back(rest_shape(in.net.wires[w], cuts[w], wire_loads(in.net, in.hooks, fr.forces, w), ro));
    rest_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    report_progress(fn, "rest_shape", 1.0);
    if (have_density) {
      const ForceProblem problem(in.net, in.hooks, steps, cuts, fo);
      lc = load_capacity(in.net, cuts, problem, fr.coefficients, lo);
    }
    return true;
  });

  py::list crossings;
  for (std::size_t c = 0; c < in.net.crossings.size(); ++c)
    crossings.append(py::dict(py::arg("force") = to_list(fr.forces[c]), py::arg("normal") = fr.normal[c],
                              py::arg("out_of_plane") = py::make_tuple(fr.out_of_plane[c][0], fr.out_of_plane[c][1])));
  py::list wires;
  for (std::size_t w = 0; w < rests.size(); ++w) {
    const RestShapeResult& r = rests[w];
    py::array_t<double> rest({static_cast<py::ssize_t>(r.rest.size()), py::ssize_t{2}});
    auto a = rest.mutable_unchecked<2>();
    for (py::ssize_t i = 0; i < a.shape(0); ++i)
      for (py::ssize_t k = 0; k < 2; ++k) a(i, k) = r.rest[static_cast<std::size_t>(i)][k];
    py::list over;
    for (std::size_t i = 0; i < r.over_bend.size(); ++i)
      over.append(py::dict(py::arg("vertex") = r.over_bend[i], py::arg("angle") = r.over_bend_angle[i]));
    wires.append(py::dict(py::arg("cut") = cuts[w], py::arg("rest") = rest, py::arg("walk") = r.walk,
                          py::arg("rest_angles") = r.rest_angles, py::arg("target_angles") = r.target_angles,
                          py::arg("closure_gap") = r.closure_gap, py::arg("max_torque") = fr.wires[w].max_torque,
                          py::arg("max_torque_vertex") = fr.wires[w].max_torque_vertex,
                          py::arg("max_out_of_plane_torque") = fr.wires[w].max_out_of_plane,
                          py::arg("max_torque_3d") = fr.wires[w].max_torque_3d,
                          py::arg("over_bend") = over));
  }
  py::object load = py::none();
  if (lc) {
    py::dict d;
    d["weight_N"] = lc->weight;
    d["length"] = lc->length;
    py::dict base, status;
    for (const LoadDirection& ld : lc->directions) {
      d[py::str(ld.name)] = std::isfinite(ld.multiple) ? py::object(py::float_(ld.multiple)) : py::object(py::none());
      base[py::str(ld.name)] = ld.base;
      status[py::str(ld.name)] = ld.status;
    }
    d["base"] = base;
    d["status"] = status;
    d["seconds"] = lc->seconds;
    int rounds = 0;
    for (const LoadDirection& ld : lc->directions) rounds += ld.lp_rounds;
    d["lp_rounds"] = rounds;
    load = d;
  }
  py::dict summary(py::arg("g_stb") = fr.g_stb, py::arg("g_asm") = fr.g_asm,
                   py::arg("assembly_residual") = fr.assembly_residual,
                   py::arg("equilibrium_residual") = fr.equilibrium_residual, py::arg("t_max") = fr.t_max,
                   py::arg("torque_active") = fr.torque_active,
                   py::arg("torque_bound") = torque_bound_name(fr.torque_bound), py::arg("method") = fr.method,
                   py::arg("nlopt_result") = fr.nlopt_result, py::arg("mean_out_of_plane") = fr.mean_out_of_plane,
                   py::arg("max_out_of_plane") = fr.max_out_of_plane,
                   py::arg("mean_out_of_plane_to_max_force") = fr.mean_out_of_plane_to_max_force,
                   py::arg("max_out_of_plane_to_max_force") = fr.max_out_of_plane_to_max_force);
  py::dict stats(py::arg("forces_seconds") = fr.seconds, py::arg("lp_seconds") = fr.lp_seconds,
                 py::arg("nlp_seconds") = fr.nlp_seconds, py::arg("rest_seconds") = rest_seconds,
                 py::arg("lp_iterations") = fr.lp_iterations, py::arg("lp_rounds") = fr.lp_rounds,
                 py::arg("iterations") = fr.iterations,
                 py::arg("working_set_rounds") = fr.working_set_rounds,
                 py::arg("working_set_rows") = fr.working_set_rows);
  return py::dict(py::arg("crossings") = crossings, py::arg("wires") = wires, py::arg("forces") = summary,
                  py::arg("load_capacity") = load, py::arg("stats") = stats, py::arg("warnings") = fr.warnings);
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
"density" kg/m^3 (without it no load capacity), "name" (ignored)};
settings: {"torque_fraction" (1), "max_bend" rad (2pi/3), "assembly_weight" (0.05),
"algorithm" ("lp_then_slsqp" | "lp" | "slsqp"), "gravity" m/s^2 (9.81), "max_iterations",
"torque_bound" ("3d": |t_v| <= t_max, default | "in_plane": its plane-normal part only)}.
progress(stage, fraction) -> False cancels (raises Cancelled).
Returns {"crossings": [{"force": [3] N on wires[0] by wires[1], "normal": N, "out_of_plane":
(share on wires[0], on wires[1])}], "wires": [{"cut", "rest": (m, 2) metres in the plane frame,
"walk", "rest_angles", "target_angles" (rad, per rest point), "closure_gap" m, "max_torque" N m,
"max_torque_vertex", "max_out_of_plane_torque" N m, "max_torque_3d" N m, "over_bend": [{"vertex", "angle"}]}],
"forces": {g_stb, g_asm, assembly_residual, equilibrium_residual, t_max, torque_active, method,
torque_bound, nlopt_result, mean_out_of_plane, max_out_of_plane, mean_out_of_plane_to_max_force,
max_out_of_plane_to_max_force}, "load_capacity": {"weight_N", "length",
"+x", "-x", "+y", "-y", "+z", "-z" (multiples of the weight; None when unbounded), "base",
"status", "seconds", "lp_rounds"} or None, "stats": {forces_seconds, lp_seconds, nlp_seconds,
rest_seconds, lp_iterations, lp_rounds, iterations, working_set_rounds, working_set_rows}, "warnings": [str]}.
Bad input raises ValueError naming the wire or crossing.)");
}

}  // namespace wiresculpt::python
