#include "wiresculpt/deflection.hpp"

#include <Eigen/Dense>
#include <Eigen/Sparse>
#include <cmath>
#include <numbers>
#include <string>

#include "wiresculpt/error.hpp"

namespace wiresculpt {

namespace {

using Matrix12 = Eigen::Matrix<double, 12, 12>;

/// The local stiffness of a straight round rod element of length L along local x
/// (DOFs u, v, w, θx, θy, θz at each end): axial EA, torsion GJ, bending EI about y and z.
Matrix12 local_stiffness(double L, double EA, double GJ, double EI) {
  Matrix12 k = Matrix12::Zero();
  auto sym = [&](int i, int j, double v) {
    k(i, j) += v;
    if (i != j) k(j, i) += v;
  };
  sym(0, 0, EA / L), sym(6, 6, EA / L), sym(0, 6, -EA / L);
  sym(3, 3, GJ / L), sym(9, 9, GJ / L), sym(3, 9, -GJ / L);
  const double a = 12 * EI / (L * L * L), b = 6 * EI / (L * L), c = 4 * EI / L, d = 2 * EI / L;
  // Bending in the local x-y plane: v and θz.
  sym(1, 1, a), sym(7, 7, a), sym(1, 7, -a);
  sym(1, 5, b), sym(1, 11, b), sym(5, 7, -b), sym(7, 11, -b);
  sym(5, 5, c), sym(11, 11, c), sym(5, 11, d);
  // Bending in the local x-z plane: w and θy (the coupling signs flip: θy = -dw/dx).
  sym(2, 2, a), sym(8, 8, a), sym(2, 8, -a);
  sym(2, 4, -b), sym(2, 10, -b), sym(4, 8, b), sym(8, 10, b);
  sym(4, 4, c), sym(10, 10, c), sym(4, 10, d);
  return k;
}

}  // namespace

DeflectionResult wire_deflection(const WireSpec& wire, int cut, const std::vector<WireLoad>& loads,
                                 const DeflectionOptions& options) {
  return wire_deflection(wire, cut, loads, {}, options);
}

DeflectionResult wire_deflection(const WireSpec& wire, int cut, const std::vector<WireLoad>& loads,
                                 const std::vector<WireLoad>& moments, const DeflectionOptions& options) {
  auto positive = [](double v) { return std::isfinite(v) && v > 0; };
  const std::string who = "wire '" + wire.name + "'";
  if (!positive(options.bending_stiffness)) throw InputError(who + ": bending_stiffness must be a finite number of N m^2 > 0");
  if (!positive(options.wire_diameter)) throw InputError(who + ": wire_diameter must be a finite number of metres > 0");
  if (!positive(options.shear_modulus)) throw InputError(who + ": shear_modulus must be a finite number of Pa > 0");
  DeflectionResult out;
  out.walk = wire_walk(static_cast<int>(wire.points.size()), wire.closed, cut, wire.name);
  const int nodes = static_cast<int>(out.walk.size());
  const double d = options.wire_diameter;
  const double I = std::numbers::pi * d * d * d * d / 64.0;
  const double J = 2.0 * I;
  const double A = std::numbers::pi * d * d / 4.0;
  const double EI = options.bending_stiffness;
  const double GJ = options.shear_modulus * J;
  const double EA = EI / I * A;
  const Vec3 n = wire.plane.normal;

  // Free DOFs: every node but the first (the clamped cut), 6 each.
  const int dofs = 6 * (nodes - 1);
  std::vector<Eigen::Triplet<double>> triplets;
  triplets.reserve(static_cast<std::size_t>(nodes) * 144);
  for (int e = 0; e + 1 < nodes; ++e) {
    const Vec3 p = wire.points[out.walk[e]], q = wire.points[out.walk[e + 1]];
    const double L = (q - p).norm();
    if (!(L > 0)) throw InputError(who + ": edge " + std::to_string(out.walk[e]) + " has zero length");
    const Vec3 e1 = (q - p) / L;
    Vec3 e2 = n - n.dot(e1) * e1;  // the plane normal, made exactly perpendicular to the edge
    if (e2.norm() < 1e-9) e2 = e1.unitOrthogonal();
    e2.normalize();
    const Vec3 e3 = e1.cross(e2);
    Eigen::Matrix3d R;
    R.row(0) = e1.transpose(), R.row(1) = e2.transpose(), R.row(2) = e3.transpose();
    Matrix12 T = Matrix12::Zero();
    for (int b = 0; b < 4; ++b) T.block<3, 3>(3 * b, 3 * b) = R;
    const Matrix12 k = T.transpose() * local_stiffness(L, EA, GJ, EI) * T;
    for (int i = 0; i < 12; ++i) {
      const int gi = 6 * (e + i / 6) + i % 6 - 6;  // node e + i/6, minus the clamped node
      if (gi < 0) continue;
      for (int j = 0; j < 12; ++j) {
        const int gj = 6 * (e + j / 6) + j % 6 - 6;
        if (gj < 0 || k(i, j) == 0.0) continue;
        triplets.emplace_back(gi, gj, k(i, j));
      }
    }
  }
  // Node of each target vertex: its first position in the walk (a closed wire's cut vertex is
  // the clamped first node).
  std::vector<int> node_of(wire.points.size(), -1);
  for (int i = nodes - 1; i >= 0; --i) node_of[out.walk[i]] = i;
  Eigen::VectorXd f = Eigen::VectorXd::Zero(dofs);
  auto apply = [&](const std::vector<WireLoad>& list, int offset, const char* what) {
    for (const WireLoad& l : list) {
      if (l.vertex < 0 || l.vertex >= static_cast<int>(wire.points.size()))
        throw InputError(who + ": a " + what + " acts at vertex " + std::to_string(l.vertex) + ", which does not exist");
      if (!l.force.allFinite()) throw InputError(who + ": a " + what + " is not finite");
      const int node = node_of[l.vertex];
      if (node == 0) continue;  // on the clamp
      f.segment<3>(6 * (node - 1) + offset) += l.force;
    }
  };
  apply(loads, 0, "force");
  apply(moments, 3, "moment");

  out.displacement.assign(nodes, Vec3::Zero());
  out.rotation.assign(nodes, Vec3::Zero());
  if (dofs > 0 && f.cwiseAbs().maxCoeff() > 0) {
    Eigen::SparseMatrix<double> K(dofs, dofs);
    K.setFromTriplets(triplets.begin(), triplets.end());
    Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> solver(K);
    if (solver.info() != Eigen::Success) throw SolverError(who + ": the frame's stiffness matrix could not be factorised");
    const Eigen::VectorXd x = solver.solve(f);
    if (solver.info() != Eigen::Success || !x.allFinite()) throw SolverError(who + ": the frame could not be solved");
    for (int i = 1; i < nodes; ++i) {
      out.displacement[i] = x.segment<3>(6 * (i - 1));
      out.rotation[i] = x.segment<3>(6 * (i - 1) + 3);
    }
  }
  for (int i = 0; i < nodes; ++i) {
    const double w = std::abs(out.displacement[i].dot(n));
    if (w > out.max_out_of_plane) {
      out.max_out_of_plane = w;
      out.max_out_of_plane_vertex = out.walk[i];
    }
  }
  return out;
}

}  // namespace wiresculpt
