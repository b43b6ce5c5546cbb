// The forces the assembled structure carries (carried_forces.hpp).
#include "wiresculpt/carried_forces.hpp"

#include "structure3d_model.hpp"

#include <Eigen/Geometry>

#include "wiresculpt/error.hpp"
#include "wiresculpt/rest_shape.hpp"
#include "wiresculpt/structure3d.hpp"

namespace wiresculpt {

namespace {

/// A node to clamp (with its next one) that no tie holds: the clamp only stops the rigid motions.
NodeRef free_clamp(const Structure3dInput& in) {
  for (std::size_t w = 0; w < in.wires.size(); ++w) {
    std::vector<char> tied(in.wires[w].start.size(), 0);
    for (const Structure3dTie& t : in.ties)
      for (const NodeRef& n : {t.a, t.b})
        if (n.wire == static_cast<int>(w)) tied[static_cast<std::size_t>(n.vertex)] = 1;
    for (std::size_t k = 0; k + 1 < tied.size(); ++k)
      if (!tied[k] && !tied[k + 1]) return {static_cast<int>(w), static_cast<int>(k)};
  }
  throw SolverError("every wire is tied at every other node: no node is left to hold the structure still by");
}

/// The free rods' Hessian h of `in`'s rods turned rigidly by `turn`: B h Bᵀ, B turning each
/// node's coordinates (the twist angles are the same in a turned frame).
Eigen::SparseMatrix<double> turned(const Eigen::SparseMatrix<double>& h, const Structure3dInput& in,
                                   const Eigen::Matrix3d& turn) {
  std::vector<Eigen::Triplet<double>> b;
  int base = 0;
  for (const Structure3dWire& w : in.wires) {
    const int n = static_cast<int>(w.start.size());
    for (int k = 0; k < n; ++k)
      for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) b.emplace_back(base + 3 * k + i, base + 3 * k + j, turn(i, j));
    for (int e = 0; e + 1 < n; ++e) b.emplace_back(base + 3 * n + e, base + 3 * n + e, 1.0);
    base += 4 * n - 1;
  }
  Eigen::SparseMatrix<double> B(h.rows(), h.cols());
  B.setFromTriplets(b.begin(), b.end());
  return B * h * B.transpose();
}

}  // namespace

CarriedForces carried_forces(const Network& net, const std::vector<int>& hooks, const std::vector<int>& cuts,
                             const CarriedForceOptions& options) {
  Structure3dInput in;
  std::vector<std::vector<int>> position(net.wires.size());  // target index -> node
  for (std::size_t w = 0; w < net.wires.size(); ++w) {
    const WireSpec& s = net.wires[w];
    const int n = static_cast<int>(s.points.size());
    const std::vector<int> walk = wire_walk(n, s.closed, cuts[w], s.name);
    Structure3dWire wire;
    wire.name = s.name, wire.normal = s.plane.normal;
    for (int t : walk) wire.start.push_back(s.points[static_cast<std::size_t>(t)]);
    wire.rest = wire.start;
    position[w].assign(static_cast<std::size_t>(n), -1);
    for (int k = static_cast<int>(walk.size()) - 1; k >= 0; --k) position[w][static_cast<std::size_t>(walk[k])] = k;
    if (s.closed) in.ties.push_back({{static_cast<int>(w), 0}, {static_cast<int>(w), static_cast<int>(walk.size()) - 1}, Vec3::Zero()});
    in.wires.push_back(std::move(wire));
  }
  const int closures = static_cast<int>(in.ties.size());
  std::vector<int> hooked;
  for (std::size_t c = 0; c < net.crossings.size(); ++c) {
    if (hooks[c] == 0) continue;
    const Crossing& x = net.crossings[c];
    const NodeRef a{x.wires[0], position[x.wires[0]][x.vertices[0]]}, b{x.wires[1], position[x.wires[1]][x.vertices[1]]};
    in.ties.push_back({a, b, in.wires[a.wire].start[a.vertex] - in.wires[b.wire].start[b.vertex]});
    hooked.push_back(static_cast<int>(c));
  }
  const int H = static_cast<int>(hooked.size());
  CarriedForces out{Eigen::MatrixXd::Zero(3 * H, 3 * H), Eigen::VectorXd::Zero(3 * H)};
  if (H == 0) return out;
  Structure3dInput held = in;  // the weight's structure: on its supports
  in.clamps.push_back(free_clamp(in));
  std::vector<std::vector<Structure3dLoad>> cases;
  for (int h = 0; h < H; ++h) {
    const Structure3dTie& t = in.ties[static_cast<std::size_t>(closures + h)];
    const Vec3 na = in.wires[t.a.wire].normal.normalized(), nb = in.wires[t.b.wire].normal.normalized();
    for (int k = 0; k < 3; ++k) {
      const Vec3 e = Vec3::Unit(k);
      cases.push_back({{t.a, e - e.dot(na) * na}, {t.b, -(e - e.dot(nb) * nb)}});
    }
  }
  Structure3dOptions o;
  o.bending_stiffness = options.bending_stiffness, o.wire_diameter = options.wire_diameter;
  o.shear_modulus = options.shear_modulus, o.linear_density = 0.0;
  const Eigen::SparseMatrix<double> h = detail::free_hessian(in, o);  // one assembly for both systems
  const std::vector<std::vector<Vec3>> answer = detail::tie_response(in, h, cases, o);
  for (int col = 0; col < 3 * H; ++col)
    for (int h = 0; h < H; ++h)
      out.R.block<3, 1>(3 * h, col) = -answer[static_cast<std::size_t>(col)][static_cast<std::size_t>(closures + h)];
  const Vec3 g = options.linear_density * options.gravity;
  if (g.norm() == 0.0 || options.supports.empty()) return out;
  std::vector<Structure3dLoad> weight;
  for (std::size_t w = 0; w < held.wires.size(); ++w) {
    const Polyline3& x = held.wires[w].start;
    for (std::size_t e = 0; e + 1 < x.size(); ++e) {  // each edge's weight, half on either end
      const Vec3 half = 0.5 * (x[e + 1] - x[e]).norm() * g;
      weight.push_back({{static_cast<int>(w), static_cast<int>(e)}, half});
      weight.push_back({{static_cast<int>(w), static_cast<int>(e + 1)}, half});
    }
  }
  // The sculpture turned to rest on its table (gravity along -z), held at its supports vertically
  // and, as the 3D check's table, at two of them horizontally.
  const Eigen::Matrix3d turn = Eigen::Quaterniond::FromTwoVectors(g.normalized(), -Vec3::UnitZ()).toRotationMatrix();
  held.table.enabled = true, held.table.hold_vertical = true;
  for (Structure3dWire& w : held.wires) {
    for (Vec3& p : w.start) p = turn * p;
    w.rest = w.start, w.normal = turn * w.normal;
  }
  for (Structure3dTie& t : held.ties) t.offset = turn * t.offset;
  for (Structure3dLoad& l : weight) l.force = turn * l.force;
  for (const std::array<int, 2>& s : options.supports) {
    if (s[0] < 0 || s[0] >= static_cast<int>(net.wires.size()) || s[1] < 0 ||
        s[1] >= static_cast<int>(position[static_cast<std::size_t>(s[0])].size()))
      throw InputError("carried_supports: (" + std::to_string(s[0]) + ", " + std::to_string(s[1]) +
                       ") is not a wire's target vertex");
    held.table.nodes.push_back({s[0], position[static_cast<std::size_t>(s[0])][static_cast<std::size_t>(s[1])]});
  }
  const std::vector<Vec3> share = detail::tie_response(held, turned(h, held, turn), {weight}, o)[0];
  // The tie answers the weight itself (not a design force standing for it): its force, as it is.
  for (int h = 0; h < H; ++h)
    out.weight.segment<3>(3 * h) = turn.transpose() * share[static_cast<std::size_t>(closures + h)];
  return out;
}

}  // namespace wiresculpt
