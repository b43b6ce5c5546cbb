#pragma once
// Plane-mesh slicing: the contours a plane cuts from a triangle mesh (Sec. 3, Fig. 2 of the
// paper: "computing their intersection with the input shape surface").
#include <vector>

#include "wiresculpt/geometry.hpp"
#include "wiresculpt/mesh.hpp"

namespace wiresculpt {

/// One contour: points on the plane, in order. For a closed contour the first point is not
/// repeated at the end; closed contours run counter-clockwise about the plane normal.
struct Contour {
  Polyline3 points;
  bool closed = true;
  double length = 0.0;  ///< metres, including the closing edge of a closed contour
};

/// The contours of `mesh` on `plane`, longest first. Closed where the surface is closed, open
/// where the cut runs into a boundary or non-manifold edge.
///
/// Vertices exactly on the plane are treated as lying infinitesimally on its positive side
/// (symbolic perturbation: the cut is the limit of cuts just below the plane), so a plane through
/// vertices or along edges still gives simple, well-formed loops. A plane that only touches the
/// surface at a vertex or along edges gives no contour (loops narrower than the weld tolerance
/// are dropped); a face lying in the plane gives the outline of the surface just below it. A
/// plane that misses gives an empty list, which is not an error.
std::vector<Contour> slice(const TriMesh& mesh, const Plane& plane);

}  // namespace wiresculpt
