// Input checks of solve_structure3d (structure3d.hpp): one InputError naming what is wrong.
#include <cmath>
#include <string>
#include <vector>

#include "structure3d_validate.hpp"
#include "wiresculpt/error.hpp"

namespace wiresculpt::detail {

namespace {

bool positive(double v) { return std::isfinite(v) && v > 0; }

std::string wire_label(const Structure3dInput& in, int w) {
  return "wire " + std::to_string(w) + " '" + in.wires[w].name + "'";
}

void check_wire(const Structure3dInput& in, int w) {
  const Structure3dWire& wire = in.wires[w];
  const std::string who = wire_label(in, w);
  if (wire.rest.size() < 2) throw InputError(who + ": a rod needs at least 2 rest points");
  if (wire.start.size() != wire.rest.size())
    throw InputError(who + ": " + std::to_string(wire.start.size()) + " start points for " +
                     std::to_string(wire.rest.size()) + " rest points");
  if (!wire.normal.allFinite() || wire.normal.norm() < 1e-12) throw InputError(who + ": the normal is not a finite non-zero vector");
  for (const Polyline3* line : {&wire.rest, &wire.start}) {
    const char* what = line == &wire.rest ? "rest" : "start";
    for (std::size_t k = 0; k < line->size(); ++k)
      if (!(*line)[k].allFinite()) throw InputError(who + ": " + what + " point " + std::to_string(k) + " is not finite");
    for (std::size_t k = 0; k + 1 < line->size(); ++k)
      if (!(((*line)[k + 1] - (*line)[k]).norm() >= 1e-12))
        throw InputError(who + ": " + what + " edge " + std::to_string(k) + " has zero length");
    const Vec3 t = ((*line)[1] - (*line)[0]).normalized();
    if ((wire.normal.normalized() - wire.normal.normalized().dot(t) * t).norm() < 1e-6)
      throw InputError(who + ": the normal lies along the first " + std::string(what) + " edge");
  }
}

void check_node(const Structure3dInput& in, const NodeRef& n, const std::string& who) {
  if (n.wire < 0 || n.wire >= static_cast<int>(in.wires.size()))
    throw InputError(who + ": wire " + std::to_string(n.wire) + " does not exist (" + std::to_string(in.wires.size()) +
                     " wires)");
  const int size = static_cast<int>(in.wires[n.wire].rest.size());
  if (n.vertex < 0 || n.vertex >= size)
    throw InputError(who + ": vertex " + std::to_string(n.vertex) + " does not exist on " + wire_label(in, n.wire) +
                     " (" + std::to_string(size) + " vertices)");
}

void check_options(const Structure3dOptions& o) {
  if (!positive(o.bending_stiffness)) throw InputError("bending_stiffness must be a finite number of N m^2 > 0");
  if (!positive(o.wire_diameter)) throw InputError("wire_diameter must be a finite number of metres > 0");
  if (!positive(o.shear_modulus)) throw InputError("shear_modulus must be a finite number of Pa > 0");
  if (!std::isfinite(o.linear_density) || o.linear_density < 0)
    throw InputError("linear_density must be a finite number of kg/m >= 0");
  if (!o.gravity.allFinite()) throw InputError("gravity must be a finite vector");
  if (!positive(o.tolerance)) throw InputError("tolerance must be a finite number > 0");
  if (o.max_iterations < 1) throw InputError("max_iterations must be at least 1");
  if (!std::isfinite(o.max_motion) || o.max_motion < 0) throw InputError("max_motion must be a finite number of metres >= 0");
}

/// Every node held by a clamp or pin: 1 in held[wire][vertex].
std::vector<std::vector<char>> held_nodes(const Structure3dInput& in) {
  std::vector<std::vector<char>> held;
  for (const Structure3dWire& w : in.wires) held.emplace_back(w.rest.size(), 0);
  for (std::size_t i = 0; i < in.clamps.size(); ++i) {
    const NodeRef& c = in.clamps[i];
    check_node(in, c, "clamp " + std::to_string(i));
    const int size = static_cast<int>(in.wires[c.wire].rest.size());
    held[c.wire][c.vertex] = 1;
    held[c.wire][c.vertex + 1 < size ? c.vertex + 1 : c.vertex - 1] = 1;
  }
  for (std::size_t i = 0; i < in.pins.size(); ++i) {
    check_node(in, in.pins[i], "pin " + std::to_string(i));
    held[in.pins[i].wire][in.pins[i].vertex] = 1;
  }
  return held;
}

void check_ties(const Structure3dInput& in) {
  const std::vector<std::vector<char>> held = held_nodes(in);
  std::vector<std::vector<int>> tie_of;
  for (const Structure3dWire& w : in.wires) tie_of.emplace_back(w.rest.size(), -1);
  for (std::size_t i = 0; i < in.ties.size(); ++i) {
    const Structure3dTie& t = in.ties[i];
    const std::string who = "tie " + std::to_string(i);
    check_node(in, t.a, who);
    check_node(in, t.b, who);
    if (!t.offset.allFinite()) throw InputError(who + ": the offset is not finite");
    if (t.a.wire == t.b.wire && t.a.vertex == t.b.vertex) throw InputError(who + ": ties a vertex to itself");
    for (const NodeRef* n : {&t.a, &t.b}) {
      const std::string where = "vertex " + std::to_string(n->vertex) + " of " + wire_label(in, n->wire);
      if (held[n->wire][n->vertex]) throw InputError(who + ": " + where + " is held by a clamp or pin");
      int& other = tie_of[n->wire][n->vertex];
      if (other >= 0) throw InputError(who + ": " + where + " is already in tie " + std::to_string(other));
      other = static_cast<int>(i);
    }
  }
}

}  // namespace

void validate(const Structure3dInput& in, const Structure3dOptions& o) {
  check_options(o);
  if (in.wires.empty()) throw InputError("the structure has no wires");
  for (int w = 0; w < static_cast<int>(in.wires.size()); ++w) check_wire(in, w);
  check_ties(in);
  for (std::size_t i = 0; i < in.loads.size(); ++i) {
    check_node(in, in.loads[i].node, "load " + std::to_string(i));
    if (!in.loads[i].force.allFinite()) throw InputError("load " + std::to_string(i) + ": the force is not finite");
  }
  const Structure3dTable& t = in.table;
  if (!t.enabled) return;
  if (!std::isfinite(t.z0)) throw InputError("table: z0 must be finite");
  if (!positive(t.stiffness)) throw InputError("table: stiffness must be a finite number of N/m > 0");
  if (!positive(t.smoothing)) throw InputError("table: smoothing must be a finite number of metres > 0");
  for (std::size_t i = 0; i < t.nodes.size(); ++i) check_node(in, t.nodes[i], "table node " + std::to_string(i));
}

}  // namespace wiresculpt::detail
