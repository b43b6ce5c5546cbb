#include "wiresculpt/structure3d.hpp"

#include <Eigen/SparseCholesky>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>

#include "structure3d_model.hpp"
#include "structure3d_validate.hpp"
#include "wiresculpt/error.hpp"

namespace wiresculpt {

using detail::Model;
using SpMat = Eigen::SparseMatrix<double>;

namespace {

/// Below this ratio of the smallest LDLᵀ pivot to the largest the stiffness counts as singular:
/// the rounding of an exact null mode (a free turn) stays near 1e-16 of the largest stiffness,
/// the softest real mode of a sculpture (a long wire bending, against a short edge stretching)
/// near 1e-9.
constexpr double singular_pivot = 1e-12;

}  // namespace

namespace detail {

bool factor_positive(const SpMat& h, Eigen::SimplicialLDLT<SpMat>& ldlt) {
  const double diag = std::max(h.diagonal().cwiseAbs().maxCoeff(), 1e-300);
  SpMat identity(h.rows(), h.cols());
  identity.setIdentity();
  double shift = 0.0;
  for (int attempt = 0; attempt < 40; ++attempt) {
    ldlt.compute(shift > 0 ? SpMat(h + shift * identity) : h);
    if (ldlt.info() == Eigen::Success) {
      const Eigen::VectorXd d = ldlt.vectorD();
      if (d.allFinite() && d.minCoeff() > singular_pivot * d.cwiseAbs().maxCoeff()) return true;
    }
    shift = shift > 0 ? 10.0 * shift : 1e-10 * diag;
  }
  return false;
}

}  // namespace detail

namespace {

Eigen::VectorXd reduce(const Model& m, const Eigen::VectorXd& full) {
  Eigen::VectorXd r = Eigen::VectorXd::Zero(m.reduced_dofs);
  for (int i = 0; i < m.full_dofs; ++i)
    if (m.map[i] >= 0) r(m.map[i]) += full(i);
  return r;
}

/// The residual of a reduced gradient: the largest unbalanced force (moments over their edge's
/// length), relative to the load scale.
double residual(const Model& m, const Eigen::VectorXd& g) {
  double r = 0.0;
  for (int i = 0; i < m.reduced_dofs; ++i) r = std::max(r, std::abs(g(i)) / m.reduced_length[i]);
  return r / m.load_scale;
}

SpMat reduced_hessian(const Model& m, const std::vector<Eigen::Triplet<double>>& triplets) {
  SpMat h(m.reduced_dofs, m.reduced_dofs);
  h.setFromTriplets(triplets.begin(), triplets.end());
  return h;
}

/// The Newton direction on the full DOFs, capped to a quarter of the size (nodes) and 1 rad
/// (angles). False when no shift makes the Hessian positive definite.
bool newton_direction(const Model& m, const Eigen::VectorXd& g, const SpMat& h, Eigen::VectorXd& step) {
  Eigen::SimplicialLDLT<SpMat> ldlt;
  if (!detail::factor_positive(h, ldlt)) return false;
  const Eigen::VectorXd reduced = -ldlt.solve(g);
  if (!reduced.allFinite()) return false;
  step = Eigen::VectorXd::Zero(m.full_dofs);
  for (int i = 0; i < m.full_dofs; ++i)
    if (m.map[i] >= 0) step(i) = reduced(m.map[i]);
  double scale = 1.0;
  for (const detail::RodData& rod : m.rods) {
    for (int k = 0; k < rod.nodes; ++k) scale = std::min(scale, 0.25 * m.size / std::max(step.segment<3>(rod.x(k, 0)).norm(), 1e-300));
    for (int e = 0; e + 1 < rod.nodes; ++e) scale = std::min(scale, 1.0 / std::max(std::abs(step(rod.theta(e))), 1e-300));
  }
  step *= scale;
  return true;
}

/// Backtracking (Armijo) on Π from q along `step`; false when no step length descends. A rise
/// within the energy's rounding is accepted (at convergence Π no longer resolves the step).
bool line_search(const Model& m, Eigen::VectorXd& q, const Eigen::VectorXd& step, const Eigen::VectorXd& g_full) {
  const double pi0 = detail::total_energy(m, q), slope = g_full.dot(step);
  const double noise = 1e-13 * (std::abs(pi0) + m.load_scale * m.size);
  for (double alpha = 1.0; alpha > 1e-12; alpha *= 0.5) {
    const Eigen::VectorXd trial = q + alpha * step;
    if (!detail::followable(m, trial)) continue;
    if (detail::total_energy(m, trial) <= pi0 + 1e-4 * alpha * slope + noise) {
      q = trial;
      return true;
    }
  }
  return false;
}

/// The largest distance of a node of q from the input's start shape.
double motion(const Model& m, const Structure3dInput& in, const Eigen::VectorXd& q) {
  double far = 0.0;
  for (std::size_t r = 0; r < m.rods.size(); ++r)
    for (int k = 0; k < m.rods[r].nodes; ++k)
      far = std::max(far, (detail::node(m, q, static_cast<int>(r), k) - in.wires[r].start[k]).norm());
  return far;
}

/// The spin of wire `rod` about itself (every angle turned alike, no node moved): sᵀ H s for the
/// unit s over its angles, from the reduced Hessian h; false for a clamped wire (no free spin).
bool spin_stiffness(const Model& m, const detail::RodData& rod, const SpMat& h, Eigen::VectorXd& s, double& spin) {
  if (rod.clamped) return false;
  s = Eigen::VectorXd::Zero(m.reduced_dofs);
  for (int e = 0; e + 1 < rod.nodes; ++e) s(m.map[rod.theta(e)]) = 1.0;
  s.normalize();
  spin = s.dot(h * s);
  return true;
}

/// The reduced Hessian as the stability checks read it: a wire whose spin about itself is nearly
/// free (stiffness below 1e-9 of the largest diagonal entry: a straight or nearly straight wire,
/// whose spin moves no node and so is no mechanism) has that spin taken out (a penalty on s sᵀ).
/// A curved wire's spin is far stiffer (E I κ² l ≈ 1e-8 of E A / l for a 3 mm wire bent to 8 cm)
/// and is left in, so that no rigid turn of it is hidden.
SpMat checked_hessian(const Model& m, const std::vector<Eigen::Triplet<double>>& triplets) {
  SpMat h = reduced_hessian(m, triplets);
  const double diag = std::max(h.diagonal().cwiseAbs().maxCoeff(), 1e-300);
  for (const detail::RodData& rod : m.rods) {
    Eigen::VectorXd s;
    double spin = 0.0;
    if (!spin_stiffness(m, rod, h, s, spin) || spin > 1e-9 * diag) continue;
    const Eigen::SparseVector<double> sv = s.sparseView();
    h += SpMat(diag * (sv * sv.transpose()));
  }
  return h;
}

/// The ratio of the smallest pivot of checked_hessian to the largest (negative when indefinite).
double stiffness_ratio(const Model& m, const std::vector<Eigen::Triplet<double>>& triplets) {
  Eigen::SimplicialLDLT<SpMat> ldlt(checked_hessian(m, triplets));
  if (ldlt.info() != Eigen::Success || !ldlt.vectorD().allFinite()) return 0.0;
  const Eigen::VectorXd d = ldlt.vectorD();
  return d.minCoeff() / std::max(d.cwiseAbs().maxCoeff(), 1e-300);
}

/// Whether the start's unbalanced forces g drive a motion the structure does not resist: the
/// linear response u = (H + 1e-14 d I)⁻¹ g (H = checked_hessian with every table node at or under
/// the table given the table's full stiffness, d its largest diagonal entry) moves a node more
/// than 100 × size. A resisted motion is at most a few sizes even under an elastica's load
/// (P L² / E I = 5: 5/3 L); an unresisted one is the load over 1e-14 of the stiffness.
bool driven_mechanism(const Model& m, const Eigen::VectorXd& q, const Eigen::VectorXd& g,
                      std::vector<Eigen::Triplet<double>> triplets) {
  for (const int dof : m.table_nodes)
    if (m.map[dof + 2] >= 0 && q(dof + 2) <= m.table_z0 + m.table_w) triplets.emplace_back(m.map[dof + 2], m.map[dof + 2], m.table_k);
  SpMat h = checked_hessian(m, triplets);
  SpMat identity(h.rows(), h.cols());
  identity.setIdentity();
  Eigen::SimplicialLDLT<SpMat> ldlt(SpMat(h + 1e-14 * h.diagonal().cwiseAbs().maxCoeff() * identity));
  if (ldlt.info() != Eigen::Success) return true;
  const Eigen::VectorXd u = ldlt.solve(g);
  if (!u.allFinite()) return true;
  for (const detail::RodData& rod : m.rods)
    for (int k = 0; k < rod.nodes; ++k)
      for (int c = 0; c < 3; ++c)
        if (m.map[rod.x(k, c)] >= 0 && std::abs(u(m.map[rod.x(k, c)])) > 100.0 * m.size) return true;
  return false;
}

/// Per wire, tie, support and table node: shapes and forces at q (g_full = ∂Π/∂q there).
void fill_result(const Model& m, const Structure3dInput& in, const Eigen::VectorXd& q, const Eigen::VectorXd& g,
                 Structure3dResult& out) {
  for (std::size_t r = 0; r < m.rods.size(); ++r) {
    const detail::RodData& rod = m.rods[r];
    Structure3dWireResult w;
    for (int k = 0; k < rod.nodes; ++k) {
      w.points.push_back(detail::node(m, q, static_cast<int>(r), k));
      const double dist = (w.points.back() - in.wires[r].start[k]).norm();
      if (dist > w.max_distance) w.max_distance = dist, w.max_distance_vertex = k;
    }
    for (int e = 0; e + 1 < rod.nodes; ++e) w.angles.push_back(q(rod.theta(e)));
    out.wires.push_back(std::move(w));
  }
  auto force = [&](const NodeRef& n) { return Vec3(g.segment<3>(m.rods[n.wire].x(n.vertex, 0))); };
  for (const Structure3dTie& t : in.ties) out.tie_forces.push_back(force(t.a));
  for (const NodeRef& c : in.clamps) {
    const detail::RodData& rod = m.rods[c.wire];
    const int other = c.vertex + 1 < rod.nodes ? c.vertex + 1 : c.vertex - 1;
    const Vec3 arm = detail::node(m, q, c.wire, other) - detail::node(m, q, c.wire, c.vertex);
    const int e = std::min(c.vertex, other);
    const Vec3 t = (detail::node(m, q, c.wire, e + 1) - detail::node(m, q, c.wire, e)).normalized();
    const NodeRef o{c.wire, other};
    out.clamps.push_back({c, force(c) + force(o), arm.cross(force(o)) + g(rod.theta(e)) * t});
  }
  for (const NodeRef& p : in.pins) out.pins.push_back({p, force(p), Vec3::Zero()});
  for (std::size_t i = 0; i < m.table_nodes.size(); ++i) {
    const int dof = m.table_nodes[i];
    Structure3dReaction r;
    if (in.table.nodes.empty()) {
      for (std::size_t w = 0, base = 0; w < m.rods.size(); base += static_cast<std::size_t>(m.rods[w].nodes), ++w)
        if (i < base + static_cast<std::size_t>(m.rods[w].nodes)) {
          r.node = {static_cast<int>(w), static_cast<int>(i - base)};
          break;
        }
    } else {
      r.node = in.table.nodes[i];
    }
    r.force.z() = detail::table_push(m, q(dof + 2));
    for (const int h : m.table_holds)
      if (h == dof || h == dof + 1) r.force(h - dof) = g(h);
    out.table.push_back(r);
  }
}

}  // namespace

std::string describe(Structure3dCause cause, double figure) {
  char buffer[256];
  switch (cause) {
    case Structure3dCause::none:
      std::snprintf(buffer, sizeof buffer, "the structure stands (residual %.3g of the load scale)", figure);
      break;
    case Structure3dCause::mechanism:
      std::snprintf(buffer, sizeof buffer,
                    "the structure is a mechanism: it can move without resistance where it balances (stiffness ratio "
                    "%.3g); it needs more crossings or supports",
                    figure);
      break;
    case Structure3dCause::no_equilibrium:
      std::snprintf(buffer, sizeof buffer,
                    "no equilibrium was found from the start shape (residual %.3g of the load scale): it would not "
                    "stand as built",
                    figure);
      break;
    case Structure3dCause::moved_away:
      std::snprintf(buffer, sizeof buffer,
                    "the structure does not stand where it is built: a node moved %.1f mm from its start looking for "
                    "a balance",
                    figure * 1e3);
      break;
    case Structure3dCause::iteration_cap:
      std::snprintf(buffer, sizeof buffer,
                    "the 3D equilibrium did not converge within its iterations (residual %.3g of the load scale)",
                    figure);
      break;
  }
  return buffer;
}

Structure3dResult solve_structure3d(const Structure3dInput& input, const Structure3dOptions& options,
                                    const ProgressFn& progress) {
  detail::validate(input, options);
  Model m = detail::build_model(input, options);
  const double max_motion = options.max_motion > 0 ? options.max_motion : m.size;
  Structure3dResult out;
  out.load_scale = m.load_scale;
  Eigen::VectorXd q = m.start, g;
  std::vector<Eigen::Triplet<double>> triplets;
  for (int it = 0;; ++it) {
    detail::assemble(m, q, g, triplets);
    const Eigen::VectorXd gr = reduce(m, g);
    out.residual = residual(m, gr), out.iterations = it;
    if (out.residual * m.load_scale <= std::max(options.tolerance * m.load_scale, m.rounding)) {
      const double ratio = stiffness_ratio(m, triplets);
      out.converged = ratio > singular_pivot;
      out.cause = out.converged ? Structure3dCause::none : Structure3dCause::mechanism;
      out.cause_figure = out.converged ? out.residual : ratio;
      break;
    }
    if (it == options.max_iterations) {
      out.cause = Structure3dCause::iteration_cap, out.cause_figure = out.residual;
      break;
    }
    if (it == 0 && driven_mechanism(m, q, gr, triplets)) {
      out.cause = Structure3dCause::mechanism, out.cause_figure = 0.0;
      break;
    }
    report_progress(progress, "structure3d", static_cast<double>(it) / options.max_iterations);
    Eigen::VectorXd step;
    if (!newton_direction(m, gr, reduced_hessian(m, triplets), step) || !line_search(m, q, step, g)) {
      out.cause = Structure3dCause::no_equilibrium, out.cause_figure = out.residual;
      break;
    }
    detail::rebase_frames(m, q);
    if (const double far = motion(m, input, q); far > max_motion) {
      detail::assemble(m, q, g, triplets);
      out.residual = residual(m, reduce(m, g)), out.iterations = it + 1;
      out.cause = Structure3dCause::moved_away, out.cause_figure = far;
      break;
    }
  }
  fill_result(m, input, q, g, out);
  return out;
}

PyramidFit pyramid_fit(const Vec3& force, const std::array<Vec3, 4>& pyramid, double tolerance) {
  PyramidFit best;
  best.distance = force.norm();  // the empty combination
  // Every nonempty subset of at most three vectors: its unconstrained least squares, kept when
  // every coefficient is >= 0. The nearest point of the cone is one of these (the cone's faces).
  for (int mask = 1; mask < 16; ++mask) {
    const int count = __builtin_popcount(static_cast<unsigned>(mask));
    if (count > 3) continue;
    Eigen::Matrix<double, 3, Eigen::Dynamic> a(3, count);
    for (int i = 0, c = 0; i < 4; ++i)
      if (mask & (1 << i)) a.col(c++) = pyramid[static_cast<std::size_t>(i)];
    const Eigen::VectorXd x = a.colPivHouseholderQr().solve(force);
    if (!x.allFinite() || x.minCoeff() < 0) continue;
    const double dist = (a * x - force).norm();
    if (dist < best.distance) {
      best.distance = dist;
      best.coefficients = {};
      for (int i = 0, c = 0; i < 4; ++i)
        if (mask & (1 << i)) best.coefficients[static_cast<std::size_t>(i)] = x(c++);
    }
  }
  best.inside = best.distance <= tolerance * std::max(force.norm(), 1e-300);
  return best;
}

}  // namespace wiresculpt
