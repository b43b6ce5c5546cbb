#pragma once
// Triangle meshes as the slicer needs them: validated, welded and cleaned once, then sliced by
// any number of planes.
#include <Eigen/Core>
#include <cstddef>

namespace wiresculpt {

using MatrixX3d = Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor>;
using MatrixX3i = Eigen::Matrix<int, Eigen::Dynamic, 3, Eigen::RowMajor>;

struct MeshOptions {
  /// Vertices closer than this (metres) are welded into one. A negative value (default) picks
  /// 1e-7 times the bounding-box diagonal, which merges the duplicated corners of STL files.
  double weld_tolerance = -1.0;
};

/// A cleaned mesh: V (#V by 3) welded vertices, F (#F by 3) triangles indexing V, with no
/// triangle repeating a vertex and no triangle listed twice (in any vertex order).
struct TriMesh {
  MatrixX3d V;
  MatrixX3i F;
  double weld_tolerance = 0.0;       ///< the tolerance actually used (metres)
  std::size_t welded_vertices = 0;   ///< input vertices merged into another
  std::size_t dropped_degenerate = 0;  ///< triangles that collapsed to an edge or point
  std::size_t dropped_duplicate = 0;   ///< triangles repeating another one
};

/// Validates and cleans an input mesh: V (#V by 3) coordinates, F (#F by 3) vertex indices.
/// Throws InputError for a non-finite coordinate (naming the vertex), an index out of range
/// (naming the triangle) or a mesh without vertices. A mesh without faces is valid (it has no
/// contours).
TriMesh prepare_mesh(const MatrixX3d& V, const MatrixX3i& F, const MeshOptions& options = {});

}  // namespace wiresculpt
