#pragma once
// The forces the assembled structure carries (beyond the paper; docs/method-forces.md §17). The
// planar model chooses each crossing's force f (on wires[0]) and bends each wire's rest shape so
// that the in-plane parts of its forces hold it at its target. Assembled in 3D, the rest shapes
// load each wire by those in-plane parts only (a planar rest shape stores no out-of-plane
// bending), and the ties at the crossings answer with the forces the whole structure needs to
// hang together: F3 = R f, which equals f only when every f lies in both wires' planes. In the
// linear range about the targets (stress-free stiffness: within about 1 % of the nonlinear 3D
// check on the bench stand-ins), R is a fixed 3H × 3H map of the structure's geometry and
// material (H hooked crossings), from structure3d_tie_response: load case (crossing c, axis k)
// puts P_a e_k on c's node of wires[0] and -P_b e_k on its node of wires[1] (P_w the projection
// onto wire w's plane); the ties' answer, negated, is column 3c + k.
#include <Eigen/Core>
#include <array>
#include <vector>

#include "wiresculpt/network.hpp"

namespace wiresculpt {

struct CarriedForceOptions {
  double bending_stiffness = 0.73;  ///< E·I, N·m² (Table 1: steel 0.73, brass 0.42). Default 0.73.
  double wire_diameter = 0.003;     ///< metres. Default 0.003.
  double shear_modulus = 79.3e9;    ///< G, Pa (steel 79.3e9, brass 39e9). Default 79.3e9.
  double linear_density = 0.0;      ///< kg/m of wire; 0: no weight. Default 0.
  /// m/s² in the network's frame: gravity as the sculpture rests on its table. Default 0.
  Vec3 gravity = Vec3::Zero();
  /// (wire, target vertex) of the points resting on the table: held there under the weight.
  std::vector<std::array<int, 2>> supports;
};

/// The carried forces in the linear range: F3 = R f + weight.
struct CarriedForces {
  /// 3H × 3H, dimensionless: per unit design force at each hooked crossing (in the order of
  /// crossing id, hooks[c] != 0), the forces on wires[0] at all of them.
  Eigen::MatrixXd R;
  /// 3H, N: the weight's share at each hooked crossing, the sculpture held at its supports
  /// (zero without a density, gravity or supports).
  Eigen::VectorXd weight;
};

/// R and the weight's share for `net` with its TARGET points, each wire walked from `cuts[w]`
/// (closed wires' ends tied at the cut); R with one node clamped (its loads balance on each
/// wire), the weight with the supports held. Throws InputError as solve_structure3d (and for a
/// support that is no vertex) and SolverError when the tied structure is a mechanism.
CarriedForces carried_forces(const Network& net, const std::vector<int>& hooks, const std::vector<int>& cuts,
                                   const CarriedForceOptions& options = {});

}  // namespace wiresculpt
