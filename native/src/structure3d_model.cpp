#include "structure3d_model.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

namespace wiresculpt::detail {

namespace {

/// Frames transported along `points` from m2 = normal (made perpendicular to the first edge).
std::vector<EdgeFrame> transported_frames(const Polyline3& points, const Vec3& normal) {
  std::vector<EdgeFrame> frames(points.size() - 1);
  for (std::size_t e = 0; e + 1 < points.size(); ++e) {
    const Vec3 t = (points[e + 1] - points[e]).normalized();
    if (e == 0) {
      const Vec3 d2 = (normal - normal.dot(t) * t).normalized();
      frames[e] = {t, d2.cross(t)};
    } else {
      const V3<double> d1 = transport(V3<double>{frames[e - 1].t.x(), frames[e - 1].t.y(), frames[e - 1].t.z()},
                                      V3<double>{t.x(), t.y(), t.z()},
                                      V3<double>{frames[e - 1].d1.x(), frames[e - 1].d1.y(), frames[e - 1].d1.z()});
      frames[e] = {t, eigen(d1).normalized()};
    }
  }
  return frames;
}

V3<double> v3(const Vec3& v) { return {v.x(), v.y(), v.z()}; }

/// The rest data of one rod: lengths, Voronoi lengths, natural curvatures in its material frames.
void rest_data(const Structure3dWire& wire, RodData& rod) {
  const int n = rod.nodes;
  const std::vector<EdgeFrame> rest_frames = transported_frames(wire.rest, wire.normal);
  rod.rest_length.resize(static_cast<std::size_t>(n - 1));
  for (int e = 0; e + 1 < n; ++e) rod.rest_length[e] = (wire.rest[e + 1] - wire.rest[e]).norm();
  rod.voronoi.assign(static_cast<std::size_t>(n), 0.0);
  rod.rest0.assign(static_cast<std::size_t>(n), Eigen::Vector2d::Zero());
  rod.rest1.assign(static_cast<std::size_t>(n), Eigen::Vector2d::Zero());
  for (int k = 1; k + 1 < n; ++k) {
    rod.voronoi[k] = rod.rest_length[k - 1] + rod.rest_length[k];
    const Vec3 t0 = rest_frames[k - 1].t, t1 = rest_frames[k].t;
    const Vec3 kb = 2.0 * t0.cross(t1) / (1.0 + t0.dot(t1));
    const Vec3 m1a = rest_frames[k - 1].d1, m2a = t0.cross(m1a);
    const Vec3 m1b = rest_frames[k].d1, m2b = t1.cross(m1b);
    rod.rest0[k] = {kb.dot(m2a), -kb.dot(m1a)};
    rod.rest1[k] = {kb.dot(m2b), -kb.dot(m1b)};
  }
  rod.twist_offset.assign(static_cast<std::size_t>(n), 0.0);
  rod.twist_base.assign(static_cast<std::size_t>(n), 0.0);
}

/// The table's horizontal holds: the lowest free table node in x and y, the farthest one from it
/// (horizontally) along the axis that stops a turn about z. Marks them held in `held`.
void hold_table(Model& m, const std::vector<char>& tied, std::vector<char>& held) {
  int first = -1;
  for (const int dof : m.table_nodes)
    if (!tied[dof] && !held[dof] && (first < 0 || m.start(dof + 2) < m.start(first + 2))) first = dof;
  if (first < 0) return;
  held[first] = held[first + 1] = 1;
  m.table_holds = {first, first + 1};
  int second = -1;
  double far = 1e-9 * m.size;
  for (const int dof : m.table_nodes) {
    const double dist = (m.start.segment<2>(dof) - m.start.segment<2>(first)).norm();
    if (dof != first && !tied[dof] && !held[dof] && dist > far) second = dof, far = dist;
  }
  if (second < 0) return;
  const Eigen::Vector2d d = m.start.segment<2>(second) - m.start.segment<2>(first);
  // A turn about z moves `second` along (-d.y, d.x): hold the larger of those components.
  const int axis = second + (std::abs(d.y()) >= std::abs(d.x()) ? 0 : 1);
  held[axis] = 1;
  m.table_holds.push_back(axis);
}

/// Held DOFs and tie sharing -> Model::map; makes every tie hold in Model::start.
void dof_map(const Structure3dInput& in, Model& m) {
  std::vector<char> held(static_cast<std::size_t>(m.full_dofs), 0), tied(held.size(), 0);
  std::vector<int> share(held.size(), -1);
  for (const NodeRef& c : in.clamps) {
    const RodData& rod = m.rods[c.wire];
    const int other = c.vertex + 1 < rod.nodes ? c.vertex + 1 : c.vertex - 1;
    for (int k = 0; k < 3; ++k) held[rod.x(c.vertex, k)] = held[rod.x(other, k)] = 1;
    held[rod.theta(std::min(c.vertex, other))] = 1;
  }
  for (const NodeRef& p : in.pins)
    for (int k = 0; k < 3; ++k) held[m.rods[p.wire].x(p.vertex, k)] = 1;
  for (const Structure3dTie& t : in.ties) {
    const int a = m.rods[t.a.wire].x(t.a.vertex, 0), b = m.rods[t.b.wire].x(t.b.vertex, 0);
    const Vec3 gap = t.offset - (m.start.segment<3>(a) - m.start.segment<3>(b));
    m.start.segment<3>(a) += 0.5 * gap;
    m.start.segment<3>(b) -= 0.5 * gap;
    for (int k = 0; k < 3; ++k) share[b + k] = a + k, tied[a + k] = tied[b + k] = 1;
  }
  if (in.table.enabled && in.table.hold_vertical) {  // the linear response's supports (structure3d.hpp)
    for (const int dof : m.table_nodes) held[dof + 2] = 1;
    for (const Structure3dTie& t : in.ties) {  // a tied node held: its partner shares the hold
      const int a = m.rods[t.a.wire].x(t.a.vertex, 2), b = m.rods[t.b.wire].x(t.b.vertex, 2);
      held[a] = held[b] = held[a] || held[b];
    }
  }
  if (in.table.enabled && in.table.hold_horizontal) hold_table(m, tied, held);
  m.map.assign(held.size(), -1);
  m.reduced_length.clear();
  for (std::size_t i = 0; i < held.size(); ++i) {
    if (held[i] || share[i] >= 0) continue;
    m.map[i] = m.reduced_dofs++;
    m.reduced_length.push_back(1.0);
  }
  for (std::size_t i = 0; i < held.size(); ++i)
    if (share[i] >= 0) m.map[i] = m.map[share[i]];
  for (const RodData& rod : m.rods)
    for (int e = 0; e + 1 < rod.nodes; ++e)
      if (m.map[rod.theta(e)] >= 0) m.reduced_length[m.map[rod.theta(e)]] = rod.rest_length[e];
}

/// Weight (lumped by half edges) and nodal loads on the full DOFs; the load scale.
void loads(const Structure3dInput& in, const Structure3dOptions& o, Model& m) {
  m.load = Eigen::VectorXd::Zero(m.full_dofs);
  double total = 0.0;
  for (const RodData& rod : m.rods)
    for (int e = 0; e + 1 < rod.nodes; ++e) {
      const Vec3 half = 0.5 * o.linear_density * rod.rest_length[e] * o.gravity;
      m.load.segment<3>(rod.x(e, 0)) += half;
      m.load.segment<3>(rod.x(e + 1, 0)) += half;
      total += 2.0 * half.norm();
    }
  for (const Structure3dLoad& l : in.loads) {
    m.load.segment<3>(m.rods[l.node.wire].x(l.node.vertex, 0)) += l.force;
    total += l.force.norm();
  }
  m.load_scale = total > 0 ? total : m.EI / (m.size * m.size);
  double shortest = m.size;
  for (const RodData& rod : m.rods)
    for (const double l : rod.rest_length) shortest = std::min(shortest, l);
  m.rounding = 8.0 * std::numeric_limits<double>::epsilon() * m.EA / shortest * m.size;
}

}  // namespace

Model build_model(const Structure3dInput& in, const Structure3dOptions& o) {
  Model m;
  const double d = o.wire_diameter, I = std::numbers::pi * d * d * d * d / 64.0;
  m.EI = o.bending_stiffness, m.GJ = o.shear_modulus * 2.0 * I, m.EA = m.EI / I * std::numbers::pi * d * d / 4.0;
  std::vector<Polyline3> starts;
  for (const Structure3dWire& w : in.wires) {
    RodData rod;
    rod.base = m.full_dofs, rod.nodes = static_cast<int>(w.rest.size());
    m.full_dofs += 3 * rod.nodes + rod.nodes - 1;
    rest_data(w, rod);
    rod.frames = transported_frames(w.start, w.normal);
    m.rods.push_back(std::move(rod));
    starts.push_back(w.start);
  }
  for (const NodeRef& c : in.clamps) m.rods[c.wire].clamped = true;
  m.size = std::max(largest_box_side(starts), 1e-300);
  m.start = Eigen::VectorXd::Zero(m.full_dofs);
  for (std::size_t r = 0; r < in.wires.size(); ++r)
    for (int k = 0; k < m.rods[r].nodes; ++k) m.start.segment<3>(m.rods[r].x(k, 0)) = in.wires[r].start[k];
  if (in.table.enabled) {
    m.table_z0 = in.table.z0, m.table_k = in.table.stiffness, m.table_w = in.table.smoothing;
    if (in.table.nodes.empty()) {
      for (const RodData& rod : m.rods)
        for (int k = 0; k < rod.nodes; ++k) m.table_nodes.push_back(rod.x(k, 0));
    } else {
      for (const NodeRef& t : in.table.nodes) m.table_nodes.push_back(m.rods[t.wire].x(t.vertex, 0));
    }
  }
  dof_map(in, m);
  loads(in, o, m);
  return m;
}

double table_push(const Model& m, double z) {
  const double g = m.table_z0 - z, w = m.table_w;
  if (g <= 0.0) return 0.0;
  return m.table_k * (g < w ? g * g / (2.0 * w) : g - 0.5 * w);
}

namespace {

/// The table's energy at height z and its second derivative in z.
double table_energy(const Model& m, double z, double& stiffness) {
  const double g = m.table_z0 - z, w = m.table_w;
  stiffness = 0.0;
  if (g <= 0.0) return 0.0;
  stiffness = m.table_k * (g < w ? g / w : 1.0);
  return m.table_k * (g < w ? g * g * g / (6.0 * w) : 0.5 * g * g - 0.5 * w * g + w * w / 6.0);
}

BendTwistData stencil_data(const Model& m, const RodData& rod, int k) {
  BendTwistData d;
  d.frame0 = rod.frames[k - 1], d.frame1 = rod.frames[k];
  d.rest0 = rod.rest0[k], d.rest1 = rod.rest1[k];
  d.twist_offset = rod.twist_offset[k];
  d.voronoi = rod.voronoi[k];
  d.EI = m.EI, d.GJ = m.GJ;
  return d;
}

/// Scatters a stencil's gradient and Hessian at full DOFs `dofs`.
template <int N>
void scatter(const Model& m, const Dual2<N>& e, const int* dofs, Eigen::VectorXd& gradient,
             std::vector<Eigen::Triplet<double>>& hessian) {
  for (int i = 0; i < N; ++i) {
    gradient(dofs[i]) += e.g(i);
    const int ri = m.map[dofs[i]];
    if (ri < 0) continue;
    for (int j = 0; j < N; ++j) {
      const int rj = m.map[dofs[j]];
      if (rj >= 0 && e.h(i, j) != 0.0) hessian.emplace_back(ri, rj, e.h(i, j));
    }
  }
}

void assemble_rod(const Model& m, const RodData& rod, const Eigen::VectorXd& q, Eigen::VectorXd& gradient,
                  std::vector<Eigen::Triplet<double>>& hessian) {
  using D11 = Dual2<11>;
  for (int k = 1; k + 1 < rod.nodes; ++k) {
    std::array<int, 11> dofs{};
    std::array<D11, 11> v;
    for (int i = 0; i < 9; ++i) dofs[i] = rod.x(k - 1, 0) + i;
    dofs[9] = rod.theta(k - 1), dofs[10] = rod.theta(k);
    for (int i = 0; i < 11; ++i) v[i] = D11::variable(q(dofs[i]), i);
    const D11 e = bend_twist_energy<D11>({v[0], v[1], v[2]}, {v[3], v[4], v[5]}, {v[6], v[7], v[8]}, v[9], v[10],
                                         stencil_data(m, rod, k));
    scatter(m, e, dofs.data(), gradient, hessian);
  }
  using D6 = Dual2<6>;
  for (int k = 0; k + 1 < rod.nodes; ++k) {
    std::array<int, 6> dofs{};
    std::array<D6, 6> v;
    for (int i = 0; i < 6; ++i) dofs[i] = rod.x(k, 0) + i, v[i] = D6::variable(q(dofs[i]), i);
    const D6 e = stretch_energy<D6>({v[0], v[1], v[2]}, {v[3], v[4], v[5]}, rod.rest_length[k], m.EA);
    scatter(m, e, dofs.data(), gradient, hessian);
  }
}

}  // namespace

double total_energy(const Model& m, const Eigen::VectorXd& q) {
  double energy = -m.load.dot(q);
  for (const RodData& rod : m.rods) {
    auto at = [&](int k) { return v3(q.segment<3>(rod.x(k, 0))); };
    for (int k = 1; k + 1 < rod.nodes; ++k)
      energy += bend_twist_energy<double>(at(k - 1), at(k), at(k + 1), q(rod.theta(k - 1)), q(rod.theta(k)),
                                          stencil_data(m, rod, k));
    for (int k = 0; k + 1 < rod.nodes; ++k) energy += stretch_energy<double>(at(k), at(k + 1), rod.rest_length[k], m.EA);
  }
  double unused = 0.0;
  for (const int dof : m.table_nodes) energy += table_energy(m, q(dof + 2), unused);
  return energy;
}

void assemble(const Model& m, const Eigen::VectorXd& q, Eigen::VectorXd& gradient,
              std::vector<Eigen::Triplet<double>>& hessian) {
  gradient = -m.load;
  hessian.clear();
  for (const RodData& rod : m.rods) assemble_rod(m, rod, q, gradient, hessian);
  for (const int dof : m.table_nodes) {
    double stiffness = 0.0;
    table_energy(m, q(dof + 2), stiffness);
    gradient(dof + 2) -= table_push(m, q(dof + 2));
    const int r = m.map[dof + 2];
    if (r >= 0 && stiffness != 0.0) hessian.emplace_back(r, r, stiffness);
  }
}

bool followable(const Model& m, const Eigen::VectorXd& q) {
  if (!q.allFinite()) return false;
  for (const RodData& rod : m.rods)
    for (int e = 0; e + 1 < rod.nodes; ++e) {
      const Vec3 edge = q.segment<3>(rod.x(e + 1, 0)) - q.segment<3>(rod.x(e, 0));
      if (!(edge.dot(rod.frames[e].t) > 1e-3 * edge.norm())) return false;
    }
  return true;
}

void rebase_frames(Model& m, const Eigen::VectorXd& q) {
  for (RodData& rod : m.rods) {
    for (int e = 0; e + 1 < rod.nodes; ++e) {
      const Vec3 t = (q.segment<3>(rod.x(e + 1, 0)) - q.segment<3>(rod.x(e, 0))).normalized();
      const Vec3 d1 = eigen(transport(v3(rod.frames[e].t), v3(t), v3(rod.frames[e].d1)));
      rod.frames[e] = {t, (d1 - d1.dot(t) * t).normalized()};
    }
    for (int k = 1; k + 1 < rod.nodes; ++k) {
      const EdgeFrame &f0 = rod.frames[k - 1], &f1 = rod.frames[k];
      const double raw = reference_twist<double>(v3(f0.t), v3(f1.t), f0, f1);
      const double turns = std::round((rod.twist_base[k] - raw) / (2.0 * std::numbers::pi));
      rod.twist_offset[k] = 2.0 * std::numbers::pi * turns;
      rod.twist_base[k] = raw + rod.twist_offset[k];
    }
  }
}

}  // namespace wiresculpt::detail
