#include "wiresculpt/mesh.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <string>
#include <unordered_map>
#include <unordered_set>
#include <vector>

#include "wiresculpt/error.hpp"

namespace wiresculpt {
namespace {

struct CellHash {
  std::size_t operator()(const std::array<std::int64_t, 3>& c) const noexcept {
    std::uint64_t h = 1469598103934665603ull;
    for (std::int64_t x : c) h = (h ^ static_cast<std::uint64_t>(x)) * 1099511628211ull;
    return static_cast<std::size_t>(h);
  }
};

struct TriangleHash {
  std::size_t operator()(const std::array<int, 3>& t) const noexcept {
    std::uint64_t h = 1469598103934665603ull;
    for (int x : t) h = (h ^ static_cast<std::uint64_t>(x)) * 1099511628211ull;
    return static_cast<std::size_t>(h);
  }
};

// Welds vertices within `tol` of an earlier representative (grid hashing with cells of size tol,
// searching the 27 neighbouring cells). Returns the new index of every input vertex.
std::vector<int> weld(const MatrixX3d& V, double tol, MatrixX3d& out) {
  const Eigen::Index n = V.rows();
  std::vector<int> remap(static_cast<std::size_t>(n));
  std::unordered_map<std::array<std::int64_t, 3>, std::vector<int>, CellHash> grid;
  grid.reserve(static_cast<std::size_t>(n));
  std::vector<Eigen::Index> kept;
  kept.reserve(static_cast<std::size_t>(n));
  const double tol2 = tol * tol;
  for (Eigen::Index i = 0; i < n; ++i) {
    std::array<std::int64_t, 3> cell{};
    for (int k = 0; k < 3; ++k) cell[k] = static_cast<std::int64_t>(std::floor(V(i, k) / tol));
    int found = -1;
    for (int dx = -1; dx <= 1 && found < 0; ++dx)
      for (int dy = -1; dy <= 1 && found < 0; ++dy)
        for (int dz = -1; dz <= 1 && found < 0; ++dz) {
          auto it = grid.find({cell[0] + dx, cell[1] + dy, cell[2] + dz});
          if (it == grid.end()) continue;
          for (int rep : it->second)
            if ((V.row(kept[static_cast<std::size_t>(rep)]) - V.row(i)).squaredNorm() <= tol2) {
              found = rep;
              break;
            }
        }
    if (found < 0) {
      found = static_cast<int>(kept.size());
      kept.push_back(i);
      grid[cell].push_back(found);
    }
    remap[static_cast<std::size_t>(i)] = found;
  }
  out.resize(static_cast<Eigen::Index>(kept.size()), 3);
  for (std::size_t k = 0; k < kept.size(); ++k) out.row(static_cast<Eigen::Index>(k)) = V.row(kept[k]);
  return remap;
}

}  // namespace

TriMesh prepare_mesh(const MatrixX3d& V, const MatrixX3i& F, const MeshOptions& options) {
  if (V.rows() == 0) throw InputError("mesh has no vertices");
  for (Eigen::Index i = 0; i < V.rows(); ++i)
    if (!V.row(i).allFinite())
      throw InputError("mesh vertex " + std::to_string(i) + " has a non-finite coordinate (NaN or Inf)");
  for (Eigen::Index t = 0; t < F.rows(); ++t)
    for (int k = 0; k < 3; ++k)
      if (F(t, k) < 0 || F(t, k) >= V.rows())
        throw InputError("mesh triangle " + std::to_string(t) + " refers to vertex " +
                         std::to_string(F(t, k)) + ", but the mesh has " + std::to_string(V.rows()) +
                         " vertices");

  TriMesh mesh;
  const double diagonal = (V.colwise().maxCoeff() - V.colwise().minCoeff()).norm();
  double tol = options.weld_tolerance;
  if (!std::isfinite(tol)) throw InputError("weld tolerance must be a finite number of metres");
  if (tol < 0.0) tol = 1e-7 * diagonal;
  if (tol <= 0.0) tol = 1e-12;  // a mesh that is a single point
  mesh.weld_tolerance = tol;

  const std::vector<int> remap = weld(V, tol, mesh.V);
  mesh.welded_vertices = static_cast<std::size_t>(V.rows() - mesh.V.rows());

  std::vector<std::array<int, 3>> tris;
  tris.reserve(static_cast<std::size_t>(F.rows()));
  std::unordered_set<std::array<int, 3>, TriangleHash> seen;
  seen.reserve(static_cast<std::size_t>(F.rows()));
  for (Eigen::Index t = 0; t < F.rows(); ++t) {
    std::array<int, 3> tri{remap[static_cast<std::size_t>(F(t, 0))], remap[static_cast<std::size_t>(F(t, 1))],
                           remap[static_cast<std::size_t>(F(t, 2))]};
    if (tri[0] == tri[1] || tri[1] == tri[2] || tri[0] == tri[2]) {
      ++mesh.dropped_degenerate;
      continue;
    }
    std::array<int, 3> key = tri;
    std::sort(key.begin(), key.end());
    if (!seen.insert(key).second) {
      ++mesh.dropped_duplicate;
      continue;
    }
    tris.push_back(tri);
  }
  mesh.F.resize(static_cast<Eigen::Index>(tris.size()), 3);
  for (std::size_t t = 0; t < tris.size(); ++t)
    for (int k = 0; k < 3; ++k) mesh.F(static_cast<Eigen::Index>(t), k) = tris[t][static_cast<std::size_t>(k)];
  return mesh;
}

}  // namespace wiresculpt
