// The sculpture as it would stand (structure3d.hpp): converts, releases the GIL around the core
// call, converts back. SI units, as the core. Nodes are [wire, vertex] pairs.
#include <pybind11/numpy.h>
#include <pybind11/stl.h>

#include <string>
#include <vector>

#include "bindings.hpp"
#include "convert.hpp"
#include "progress.hpp"
#include "wiresculpt/structure3d.hpp"

namespace py = pybind11;

namespace wiresculpt::python {
namespace {

NodeRef to_node(py::handle v, const std::string& where) {
  const std::vector<int> ids = to_integers<int>(v, where);
  if (ids.size() != 2) throw InputError(where + ": expected [wire, vertex], got " + std::to_string(ids.size()) + " numbers");
  return {ids[0], ids[1]};
}

std::vector<NodeRef> to_nodes(py::handle v, const std::string& where) {
  std::vector<NodeRef> out;
  if (!v.is_none()) each_item(v, where, [&](py::handle item, const std::string& at) { out.push_back(to_node(item, at)); });
  return out;
}

Field node_field(const char* key, NodeRef& out) {
  return {key, [&out](py::handle v, const std::string& at) { out = to_node(v, at); }};
}
Field vector_field(const char* key, Vec3& out) {
  return {key, [&out](py::handle v, const std::string& at) { out = to_vector<3>(v, at); }};
}

Structure3dInput read_input(py::handle wires, py::handle ties, py::handle loads, py::handle clamps, py::handle pins,
                            py::handle table) {
  Structure3dInput in;
  each_item(wires, "wires", [&](py::handle item, const std::string& at) {
    Structure3dWire w;
    const auto seen = read_fields(item, at,
                                  {field::text("name", w.name),
                                   {"rest", [&](py::handle v, const std::string& p) { w.rest = to_points<3>(v, p); }},
                                   {"start", [&](py::handle v, const std::string& p) { w.start = to_points<3>(v, p); }},
                                   vector_field("normal", w.normal)});
    require_keys(seen, at, {"rest", "start", "normal"});
    in.wires.push_back(std::move(w));
  });
  if (!ties.is_none())
    each_item(ties, "ties", [&](py::handle item, const std::string& at) {
      Structure3dTie t;
      require_keys(read_fields(item, at, {node_field("a", t.a), node_field("b", t.b), vector_field("offset", t.offset)}), at,
                   {"a", "b"});
      in.ties.push_back(t);
    });
  if (!loads.is_none())
    each_item(loads, "loads", [&](py::handle item, const std::string& at) {
      Structure3dLoad l;
      require_keys(read_fields(item, at, {node_field("node", l.node), vector_field("force", l.force)}), at, {"node", "force"});
      in.loads.push_back(l);
    });
  in.clamps = to_nodes(clamps, "clamps");
  in.pins = to_nodes(pins, "pins");
  if (!table.is_none()) {
    Structure3dTable& t = in.table;
    t.enabled = true;
    read_fields(table, "table",
                {field::number("z0", t.z0), field::number("stiffness", t.stiffness), field::number("smoothing", t.smoothing),
                 field::boolean("hold_horizontal", t.hold_horizontal),
                 {"nodes", [&](py::handle v, const std::string& at) { t.nodes = to_nodes(v, at); }}});
  }
  return in;
}

Structure3dOptions read_options(py::handle options) {
  Structure3dOptions o;
  if (options.is_none()) return o;
  read_fields(options, "options",
              {field::number("bending_stiffness", o.bending_stiffness), field::number("wire_diameter", o.wire_diameter),
               field::number("shear_modulus", o.shear_modulus), field::number("linear_density", o.linear_density),
               vector_field("gravity", o.gravity), field::number("tolerance", o.tolerance),
               field::integer("max_iterations", o.max_iterations), field::number("max_motion", o.max_motion)});
  return o;
}

const char* cause_name(Structure3dCause c) {
  switch (c) {
    case Structure3dCause::none: return "none";
    case Structure3dCause::mechanism: return "mechanism";
    case Structure3dCause::no_equilibrium: return "no_equilibrium";
    case Structure3dCause::moved_away: return "moved_away";
    case Structure3dCause::iteration_cap: return "iteration_cap";
  }
  return "none";
}

py::list vec(const Vec3& v) { return py::cast(std::vector<double>{v.x(), v.y(), v.z()}); }

py::list reactions(const std::vector<Structure3dReaction>& list) {
  py::list out;
  for (const Structure3dReaction& r : list) {
    py::dict d;
    d["node"] = py::cast(std::vector<int>{r.node.wire, r.node.vertex});
    d["force"] = vec(r.force);
    d["moment"] = vec(r.moment);
    out.append(d);
  }
  return out;
}

py::dict result_dict(const Structure3dResult& r) {
  py::dict d;
  d["converged"] = r.converged;
  d["cause"] = cause_name(r.cause);
  d["message"] = describe(r.cause, r.cause_figure);
  d["cause_figure"] = r.cause_figure;
  d["residual"] = r.residual;
  d["load_scale"] = r.load_scale;
  d["iterations"] = r.iterations;
  py::list wires;
  for (const Structure3dWireResult& w : r.wires) {
    py::array_t<double> points({static_cast<py::ssize_t>(w.points.size()), py::ssize_t{3}});
    auto p = points.mutable_unchecked<2>();
    for (py::ssize_t i = 0; i < p.shape(0); ++i)
      for (py::ssize_t k = 0; k < 3; ++k) p(i, k) = w.points[static_cast<std::size_t>(i)][k];
    py::dict wd;
    wd["points"] = points;
    wd["angles"] = py::cast(w.angles);
    wd["max_distance"] = w.max_distance;
    wd["max_distance_vertex"] = w.max_distance_vertex;
    wires.append(wd);
  }
  d["wires"] = wires;
  py::list ties;
  for (const Vec3& f : r.tie_forces) ties.append(vec(f));
  d["tie_forces"] = ties;
  d["clamps"] = reactions(r.clamps);
  d["pins"] = reactions(r.pins);
  d["table"] = reactions(r.table);
  return d;
}

py::dict structure3d_py(const py::object& wires, const py::object& ties, const py::object& loads, const py::object& clamps,
                        const py::object& pins, const py::object& table, const py::object& options,
                        const py::object& progress) {
  const Structure3dInput in = read_input(wires, ties, loads, clamps, pins, table);
  const Structure3dOptions o = read_options(options);
  PythonProgress p(progress);
  const Structure3dResult r = p.run([&] { return solve_structure3d(in, o, p.fn()); });
  return result_dict(r);
}

py::list tie_response_py(const py::object& wires, const py::object& ties, const py::object& clamps,
                         const py::object& cases, const py::object& options) {
  const Structure3dInput in = read_input(wires, ties, py::none(), clamps, py::none(), py::none());
  std::vector<std::vector<Structure3dLoad>> list;
  each_item(cases, "cases", [&](py::handle item, const std::string& at) {
    list.push_back(read_input(wires, py::none(), py::reinterpret_borrow<py::object>(item), py::none(), py::none(),
                              py::none()).loads);
    (void)at;
  });
  const Structure3dOptions o = read_options(options);
  std::vector<std::vector<Vec3>> r;
  {
    py::gil_scoped_release release;
    r = structure3d_tie_response(in, list, o);
  }
  py::list out;
  for (const std::vector<Vec3>& one : r) {
    py::list forces;
    for (const Vec3& v : one) forces.append(vec(v));
    out.append(forces);
  }
  return out;
}

py::dict pyramid_fit_py(const py::object& force, const py::object& pyramid) {
  const std::vector<Vec3> rows = to_points<3>(pyramid, "pyramid");
  if (rows.size() != 4) throw InputError("pyramid: expected 4 vectors, got " + std::to_string(rows.size()));
  const PyramidFit fit = pyramid_fit(to_vector<3>(force, "force"), {rows[0], rows[1], rows[2], rows[3]});
  py::dict d;
  d["coefficients"] = py::cast(std::vector<double>(fit.coefficients.begin(), fit.coefficients.end()));
  d["distance"] = fit.distance;
  d["inside"] = fit.inside;
  return d;
}

}  // namespace

void bind_structure3d(py::module_& m) {
  m.def("structure3d", &structure3d_py, py::arg("wires"), py::arg("ties") = py::none(), py::arg("loads") = py::none(),
        py::arg("clamps") = py::none(), py::arg("pins") = py::none(), py::arg("table") = py::none(),
        py::arg("options") = py::none(), py::arg("progress") = py::none(),
        "The 3D equilibrium of an assembled structure of discrete elastic rods (structure3d.hpp).");
  m.def("structure3d_tie_response", &tie_response_py, py::arg("wires"), py::arg("ties"), py::arg("clamps"),
        py::arg("cases"), py::arg("options") = py::none(),
        "Per load case, the tie forces of the stress-free structure's linear response (structure3d.hpp).");
  m.def("pyramid_fit", &pyramid_fit_py, py::arg("force"), py::arg("pyramid"),
        "Whether a force lies in the cone of four vectors, and its nearest nonnegative combination.");
}

}  // namespace wiresculpt::python
