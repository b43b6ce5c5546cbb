// The assembled structure's linear tie response about its start (structure3d.hpp,
// structure3d_tie_response): one factorisation of the tied stiffness, then per load case a solve
// and each tie's share read from its node a's own rod.
#include <Eigen/SparseCholesky>
#include <vector>

#include "structure3d_model.hpp"
#include "structure3d_validate.hpp"
#include "wiresculpt/error.hpp"
#include "wiresculpt/structure3d.hpp"

namespace wiresculpt {

using SpMat = Eigen::SparseMatrix<double>;

namespace detail {

SpMat free_hessian(const Structure3dInput& input, const Structure3dOptions& options) {
  Structure3dInput free = input;
  free.loads.clear(), free.ties.clear(), free.clamps.clear(), free.pins.clear(), free.table = {};
  for (Structure3dWire& w : free.wires) w.rest = w.start;
  validate(free, options);
  const Model f = build_model(free, options);
  Eigen::VectorXd g;
  std::vector<Eigen::Triplet<double>> triplets;
  assemble(f, f.start, g, triplets);
  SpMat h(f.full_dofs, f.full_dofs);
  h.setFromTriplets(triplets.begin(), triplets.end());
  return h;
}

std::vector<std::vector<Vec3>> tie_response(const Structure3dInput& input, const SpMat& h,
                                            const std::vector<std::vector<Structure3dLoad>>& cases,
                                            const Structure3dOptions& options) {
  Structure3dInput tied = input;
  tied.loads.clear();
  for (Structure3dWire& w : tied.wires) w.rest = w.start;
  validate(tied, options);
  const Model m = build_model(tied, options);
  if (h.rows() != m.full_dofs || h.cols() != m.full_dofs)
    throw InputError("tie response: the rods' Hessian does not match the structure");
  // The free rods' Hessian summed through the tied map into K (held DOFs dropped).
  std::vector<Eigen::Triplet<double>> summed;
  for (int c = 0; c < h.outerSize(); ++c)
    for (SpMat::InnerIterator it(h, c); it; ++it)
      if (m.map[it.row()] >= 0 && m.map[it.col()] >= 0) summed.emplace_back(m.map[it.row()], m.map[it.col()], it.value());
  SpMat k(m.reduced_dofs, m.reduced_dofs);
  k.setFromTriplets(summed.begin(), summed.end());
  Eigen::SimplicialLDLT<SpMat> ldlt;
  if (!factor_positive(k, ldlt))
    throw SolverError("the tied structure is a mechanism: no stiffness resists some motion of it");

  std::vector<std::vector<Vec3>> out;
  out.reserve(cases.size());
  for (const std::vector<Structure3dLoad>& loads : cases) {
    Eigen::VectorXd p = Eigen::VectorXd::Zero(m.full_dofs), reduced = Eigen::VectorXd::Zero(m.reduced_dofs);
    for (const Structure3dLoad& l : loads) {
      if (l.node.wire < 0 || l.node.wire >= static_cast<int>(m.rods.size()) || l.node.vertex < 0 ||
          l.node.vertex >= m.rods[static_cast<std::size_t>(l.node.wire)].nodes)
        throw InputError("a load names node (" + std::to_string(l.node.wire) + ", " + std::to_string(l.node.vertex) +
                         "), which is not a node of the structure");
      p.segment<3>(m.rods[static_cast<std::size_t>(l.node.wire)].x(l.node.vertex, 0)) += l.force;
    }
    for (int i = 0; i < m.full_dofs; ++i)
      if (m.map[i] >= 0) reduced(m.map[i]) += p(i);
    const Eigen::VectorXd dq = ldlt.solve(reduced);
    Eigen::VectorXd full = Eigen::VectorXd::Zero(m.full_dofs);
    for (int i = 0; i < m.full_dofs; ++i)
      if (m.map[i] >= 0) full(i) = dq(m.map[i]);
    const Eigen::VectorXd force = h * full - p;  // each rod's elastic force at its own nodes, less the loads
    std::vector<Vec3> ties;
    for (const Structure3dTie& t : tied.ties)
      ties.push_back(force.segment<3>(m.rods[static_cast<std::size_t>(t.a.wire)].x(t.a.vertex, 0)));
    out.push_back(std::move(ties));
  }
  return out;
}

}  // namespace detail

std::vector<std::vector<Vec3>> structure3d_tie_response(const Structure3dInput& input,
                                                        const std::vector<std::vector<Structure3dLoad>>& cases,
                                                        const Structure3dOptions& options) {
  return detail::tie_response(input, detail::free_hessian(input, options), cases, options);
}

}  // namespace wiresculpt
