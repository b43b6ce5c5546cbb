#include "wiresculpt/mesh.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <string>
#include <utility>
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

// Open addressing from grid cell to the last kept vertex in it: one allocation, linear probing.
class CellTable {
 public:
  explicit CellTable(std::size_t expected) {
    std::size_t size = 16;
    while (size < 2 * expected) size *= 2;
    keys_.resize(size);
    values_.assign(size, -1);
  }
  // The slot of `cell`: values_[slot] is -1 when the cell is empty.
  std::size_t slot(const std::array<std::int64_t, 3>& cell) const {
    std::size_t i = CellHash{}(cell) & (keys_.size() - 1);
    while (values_[i] >= 0 && keys_[i] != cell) i = (i + 1) & (keys_.size() - 1);
    return i;
  }
  int get(const std::array<std::int64_t, 3>& cell) const { return values_[slot(cell)]; }
  // Stores `value` for `cell`, returning the value it had (-1 if none).
  int put(const std::array<std::int64_t, 3>& cell, int value) {
    const std::size_t i = slot(cell);
    keys_[i] = cell;
    return std::exchange(values_[i], value);
  }

 private:
  std::vector<std::array<std::int64_t, 3>> keys_;
  std::vector<int> values_;
};

// Welds vertices within `tol` of an earlier kept vertex. Grid hashing with cells of 64 tol: a
// vertex probes a neighbouring cell only along the axes where it lies within tol of its own
// cell's face, so most vertices probe one cell. Returns the new index of every input vertex.
std::vector<int> weld(const MatrixX3d& V, double tol, MatrixX3d& out) {
  const Eigen::Index n = V.rows();
  const double h = 64.0 * tol;
  std::vector<int> remap(static_cast<std::size_t>(n));
  CellTable head(static_cast<std::size_t>(n));  // cell -> last kept vertex in it
  std::vector<int> next;             // kept vertex -> previous kept vertex of the same cell
  std::vector<Eigen::Index> kept;    // kept vertex -> input row
  next.reserve(static_cast<std::size_t>(n));
  kept.reserve(static_cast<std::size_t>(n));
  const double tol2 = tol * tol;
  for (Eigen::Index i = 0; i < n; ++i) {
    std::array<std::int64_t, 3> cell{};
    int lo[3], hi[3];
    for (int k = 0; k < 3; ++k) {
      const double q = V(i, k) / h;
      const double f = std::floor(q);
      cell[static_cast<std::size_t>(k)] = static_cast<std::int64_t>(f);
      lo[k] = (q - f) * h <= tol ? -1 : 0;
      hi[k] = (f + 1 - q) * h <= tol ? 1 : 0;
    }
    int found = -1;
    for (int dx = lo[0]; dx <= hi[0] && found < 0; ++dx)
      for (int dy = lo[1]; dy <= hi[1] && found < 0; ++dy)
        for (int dz = lo[2]; dz <= hi[2] && found < 0; ++dz) {
          for (int rep = head.get({cell[0] + dx, cell[1] + dy, cell[2] + dz}); rep >= 0;
               rep = next[static_cast<std::size_t>(rep)])
            if ((V.row(kept[static_cast<std::size_t>(rep)]) - V.row(i)).squaredNorm() <= tol2) {
              found = rep;
              break;
            }
        }
    if (found < 0) {
      found = static_cast<int>(kept.size());
      kept.push_back(i);
      next.push_back(head.put(cell, found));
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
  // Grid cells must stay representable as 64-bit integers: tol at least 1e-15 of the largest
  // coordinate (and positive for a mesh that is a single point).
  tol = std::max({tol, 1e-15 * V.cwiseAbs().maxCoeff(), 1e-300});
  mesh.weld_tolerance = tol;

  const std::vector<int> remap = weld(V, tol, mesh.V);
  mesh.welded_vertices = static_cast<std::size_t>(V.rows() - mesh.V.rows());

  // Drop triangles that collapsed under welding, then duplicates (the same three vertices in any
  // order). Duplicates share their smallest vertex, so triangles are bucketed by it (counting
  // sort) and compared only within a bucket.
  std::vector<std::array<int, 3>> tris;
  tris.reserve(static_cast<std::size_t>(F.rows()));
  for (Eigen::Index t = 0; t < F.rows(); ++t) {
    std::array<int, 3> tri{remap[static_cast<std::size_t>(F(t, 0))], remap[static_cast<std::size_t>(F(t, 1))],
                           remap[static_cast<std::size_t>(F(t, 2))]};
    if (tri[0] == tri[1] || tri[1] == tri[2] || tri[0] == tri[2])
      ++mesh.dropped_degenerate;
    else
      tris.push_back(tri);
  }
  const std::size_t nv = static_cast<std::size_t>(mesh.V.rows());
  auto sorted = [](std::array<int, 3> t) { std::sort(t.begin(), t.end()); return t; };
  std::vector<int> start(nv + 1, 0), order(tris.size());
  for (const auto& t : tris) ++start[static_cast<std::size_t>(sorted(t)[0]) + 1];
  for (std::size_t v = 0; v < nv; ++v) start[v + 1] += start[v];
  std::vector<int> fill(start.begin(), start.end() - 1);
  for (std::size_t t = 0; t < tris.size(); ++t) order[static_cast<std::size_t>(fill[static_cast<std::size_t>(sorted(tris[t])[0])]++)] = static_cast<int>(t);
  std::vector<char> duplicate(tris.size(), 0);
  for (std::size_t v = 0; v < nv; ++v)
    for (int a = start[v]; a < start[v + 1]; ++a)
      for (int b = start[v]; b < a; ++b) {
        const std::size_t ta = static_cast<std::size_t>(order[static_cast<std::size_t>(a)]);
        const std::size_t tb = static_cast<std::size_t>(order[static_cast<std::size_t>(b)]);
        if (!duplicate[tb] && sorted(tris[ta]) == sorted(tris[tb])) {
          duplicate[std::max(ta, tb)] = 1;  // keep the first in input order
          break;
        }
      }
  std::size_t kept = 0;
  for (std::size_t t = 0; t < tris.size(); ++t)
    if (!duplicate[t]) tris[kept++] = tris[t];
  mesh.dropped_duplicate = tris.size() - kept;
  tris.resize(kept);
  mesh.F.resize(static_cast<Eigen::Index>(tris.size()), 3);
  for (std::size_t t = 0; t < tris.size(); ++t)
    for (int k = 0; k < 3; ++k) mesh.F(static_cast<Eigen::Index>(t), k) = tris[t][static_cast<std::size_t>(k)];
  return mesh;
}

}  // namespace wiresculpt
