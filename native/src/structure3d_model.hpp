#pragma once
// The assembled structure of structure3d.hpp as one vector of unknowns: its DOF map (held DOFs
// dropped, tied nodes sharing DOFs), energy, exact gradient and sparse Hessian. Private to the
// core.
#include <Eigen/Core>
#include <Eigen/SparseCholesky>
#include <Eigen/SparseCore>
#include <vector>

#include "structure3d_rod.hpp"
#include "wiresculpt/structure3d.hpp"

namespace wiresculpt::detail {

struct RodData {
  int base = 0;   ///< full DOF of node 0's x; node k's coordinate c is base + 3k + c
  int nodes = 0;  ///< n; edge e's angle is base + 3n + e
  bool clamped = false;
  std::vector<double> rest_length;          ///< #n-1
  std::vector<double> voronoi;              ///< #n (0 at the ends)
  std::vector<Eigen::Vector2d> rest0, rest1;  ///< #n: ω̄_k^{k-1}, ω̄_k^k (0 at the ends)
  std::vector<EdgeFrame> frames;            ///< #n-1, the reference frames' base
  std::vector<double> twist_offset;         ///< #n
  std::vector<double> twist_base;           ///< #n: the reference twist at the base

  int x(int k, int c) const { return base + 3 * k + c; }
  int theta(int e) const { return base + 3 * nodes + e; }
};

struct Model {
  std::vector<RodData> rods;
  int full_dofs = 0;
  std::vector<int> map;  ///< full DOF -> reduced DOF, or -1 when held
  int reduced_dofs = 0;
  std::vector<double> reduced_length;  ///< per reduced DOF: 1 (a coordinate) or the edge's length
  Eigen::VectorXd start;  ///< the full state at the start (ties made to hold)
  Eigen::VectorXd load;   ///< external forces on the full DOFs (weight and loads), N
  double EI = 1.0, GJ = 1.0, EA = 1.0;
  std::vector<int> table_nodes;  ///< full DOF of each table node's x
  std::vector<int> table_holds;  ///< full DOFs the table holds horizontally
  double table_z0 = 0.0, table_k = 0.0, table_w = 1.0;
  double size = 0.0;        ///< the largest side of the start's box, metres
  double load_scale = 1.0;  ///< N
  /// N: the rounding of the stretch forces, 8 ε (E A / shortest rest edge) × size, below which no
  /// residual can fall (coordinates carry ε × size).
  double rounding = 0.0;
};

/// The model of a validated input (frames and natural curvatures from the rest and start shapes).
Model build_model(const Structure3dInput& input, const Structure3dOptions& options);

/// Π at full state q (elastic + table - load·x), with the reference frames at their base.
double total_energy(const Model& model, const Eigen::VectorXd& q);

/// ∂Π/∂q on the full DOFs, and the reduced Hessian's triplets (pairs of free DOFs only).
void assemble(const Model& model, const Eigen::VectorXd& q, Eigen::VectorXd& gradient,
              std::vector<Eigen::Triplet<double>>& hessian);

/// The table's upward push on a node at height z (N).
double table_push(const Model& model, double z);

/// Whether q is a state the frames can follow (finite, no edge turned by 90° or more from its
/// reference tangent).
bool followable(const Model& model, const Eigen::VectorXd& q);

/// Re-bases every reference frame on the tangents of q (time-parallel transport).
void rebase_frames(Model& model, const Eigen::VectorXd& q);

/// Factorises H + shift·I with the smallest shift in {0, 1e-10·d, 1e-9·d, ...} (d the largest
/// diagonal entry) whose every pivot exceeds singular_pivot (structure3d.cpp) of the largest.
/// False if none does.
bool factor_positive(const Eigen::SparseMatrix<double>& h, Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>>& ldlt);

/// The rods' elastic Hessian on the full DOFs, each rod free and stress-free (rest = start):
/// structure3d_tie_response's stiffness, before its ties and supports.
Eigen::SparseMatrix<double> free_hessian(const Structure3dInput& input, const Structure3dOptions& options);

/// structure3d_tie_response with the free rods' Hessian `h` given (free_hessian of the same rods,
/// or of them turned rigidly, turned with them).
std::vector<std::vector<Vec3>> tie_response(const Structure3dInput& input, const Eigen::SparseMatrix<double>& h,
                                            const std::vector<std::vector<Structure3dLoad>>& cases,
                                            const Structure3dOptions& options);

/// Node k's position of rod r in q.
inline Vec3 node(const Model& model, const Eigen::VectorXd& q, int r, int k) {
  return q.segment<3>(model.rods[static_cast<std::size_t>(r)].x(k, 0));
}

}  // namespace wiresculpt::detail
