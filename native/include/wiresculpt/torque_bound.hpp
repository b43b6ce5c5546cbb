#pragma once
// The plastic limit |t_v| <= t_max of Sec. 4.4 as linear rows, so that the force LP (GLPK), the
// SLSQP stage after it and the load-capacity LPs all take it unchanged. Method notes:
// docs/method-forces.md, §3 "Torque" and §9.4.
//
// A torque t_v of wire i is written in the wire's frame (n, u, v): n the plane normal (the
// component that bends the wire in its plane, the only bending the planar rest shape stores),
// u and v the plane's in-plane axes (out-of-plane bending and twist). A bound is a finite set of
// rows e_k (frame components) with
//
//     e_k · t_v <= t_max   for every k,
//
// i.e. the polytope {t : e_k·t <= t_max}, and the torque's gauge max_k e_k·t / t_max (<= 1
// inside). TorqueBound::full_3d (the paper's |t_v| <= t_max): a geodesic polytope inscribed in
// the ball of radius t_max, with vertices at ±n t_max, so pure in-plane bending reaches t_max
// exactly, and contained in it by at most `gap` (it contains the ball of radius (1 - gap) t_max).
// TorqueBound::in_plane (before): |n·t_v| <= t_max, the slab of the two rows ±n.
#include <string>
#include <vector>

#include "wiresculpt/geometry.hpp"

namespace wiresculpt {

enum class TorqueBound {
  full_3d,   ///< default: |t_v| <= t_max (in-plane and out-of-plane bending and twist), polytope
  in_plane,  ///< |n·t_v| <= t_max only (in-plane bending; out-of-plane bending and twist free)
};

/// "3d" or "in_plane".
const char* torque_bound_name(TorqueBound bound);
/// Reads "3d" or "in_plane"; anything else is an InputError naming `key`.
TorqueBound parse_torque_bound(const std::string& text, const std::string& key);

struct TorquePolytope {
  /// Rows e_k in frame components (n, u, v): the bound is e_k · t <= t_max for every k.
  /// |e_k| = 1 / (distance of facet k from the centre, relative to t_max).
  std::vector<Vec3> rows;
  /// Per row: the rows of the facets that share a vertex with it (itself excluded).
  std::vector<std::vector<int>> neighbours;
  /// The rows whose facets pass through +n t_max or -n t_max (pure in-plane bending at the
  /// limit). Together they bound every component of t (for the slab: both rows, every row).
  std::vector<int> apex;
  /// 1 - the smallest facet distance: the polytope contains the ball of radius (1 - gap) t_max
  /// and lies inside the ball of radius t_max. 0 for the slab (which is not inside the ball).
  double gap = 0.0;
};

/// The polytope of `bound`: full_3d the geodesic polytope of frequency 3 (180 facets, gap
/// 2.84%), in_plane the slab {±n}. Built once.
const TorquePolytope& torque_polytope(TorqueBound bound);

/// The geodesic polytope of `frequency` >= 1: an icosahedron with vertices at ±n, each face cut
/// into frequency² triangles whose corners are projected onto the unit sphere (20 frequency²
/// facets, all vertices on the sphere, so it lies inside the ball).
TorquePolytope geodesic_polytope(int frequency);

/// max_k e_k · t / t_max: <= 1 when t satisfies every row; `row` receives the maximising k.
double torque_gauge(const TorquePolytope& polytope, const Vec3& t_frame, double t_max, int* row = nullptr);

}  // namespace wiresculpt
