#pragma once
// Out-of-plane deflection, beyond the paper (whose rest shape, Sec. 4.4 and 7, keeps every wire in
// its plane): a 3D check of one wire under its contact forces. Method notes:
// docs/method-forces.md §11.
//
// The target polyline, walked from its cut (rest_shape.hpp's wire_walk), is a linear frame of
// straight rod elements (Euler-Bernoulli bending about both section axes, Saint-Venant torsion,
// axial stretch), 6 degrees of freedom per node (displacement, small rotation), assembled into
// an Eigen sparse matrix and solved by a sparse LDLᵀ factorisation. The first node of the walk
// (the cut) is clamped; the contact forces act at their vertices. Round wire of diameter d:
//   I = π d⁴ / 64 (both axes), J = π d⁴ / 32, A = π d² / 4,
//   E·I = bending_stiffness (k_b of Table 1, the same stiffness as the rest shape),
//   G·J = shear_modulus × J,   E·A = (k_b / I) × A.
// A wire's contact forces are self-equilibrated (M a = 0, forces.hpp), so the clamp carries no
// reaction and only fixes the rigid motion: the deflection is measured from the cut. Linear: for
// a planar round-wire frame, in-plane forces only move it in its plane, so the out-of-plane
// displacement comes from the forces' out-of-plane parts f·n alone.
#include <vector>

#include "wiresculpt/network.hpp"
#include "wiresculpt/rest_shape.hpp"

namespace wiresculpt {

struct DeflectionOptions {
  double bending_stiffness = 0.73;  ///< E·I, N·m² (Table 1 steel 0.73, brass 0.42). Default 0.73.
  double wire_diameter = 0.003;     ///< metres. Default 0.003.
  /// G, Pa (steel 79.3e9, brass 39e9: core/materials.py, docs/method-forces.md §11). Default 79.3e9.
  double shear_modulus = 79.3e9;
};

struct DeflectionResult {
  std::vector<int> walk;               ///< target index of each node (wire_walk)
  std::vector<Vec3> displacement;      ///< per node, metres (0 at the clamped cut)
  std::vector<Vec3> rotation;          ///< per node, small rotation vector, radians
  /// max over nodes of |displacement · n| (n the plane's unit normal), metres, and the target
  /// index where it occurs (-1 when every displacement is 0).
  double max_out_of_plane = 0.0;
  int max_out_of_plane_vertex = -1;
};

/// The linear 3D deflection of `wire` (target points, plane, closed) cut at `cut` (wire_walk)
/// under `loads` (forces at target vertices; a load at a closed wire's cut acts on the clamped
/// node and so moves nothing). Throws InputError naming the wire for bad options, a degenerate
/// edge or a load on a vertex that does not exist.
DeflectionResult wire_deflection(const WireSpec& wire, int cut, const std::vector<WireLoad>& loads,
                                 const DeflectionOptions& options = {});

/// The same with end moments too: `moments` (N·m, 3D) acting at target vertices (for tests
/// against closed forms; the contact model has no moments).
DeflectionResult wire_deflection(const WireSpec& wire, int cut, const std::vector<WireLoad>& loads,
                                 const std::vector<WireLoad>& moments, const DeflectionOptions& options);

}  // namespace wiresculpt
