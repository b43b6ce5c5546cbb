#include "wiresculpt/slicing.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <unordered_map>
#include <vector>

namespace wiresculpt {
namespace {

// The cut graph: one node per mesh edge the plane crosses, one segment per crossed triangle.
struct CutGraph {
  std::vector<Vec3> points;                  // node -> point on the plane
  std::vector<std::array<int, 2>> segments;  // segment -> its two nodes
  std::vector<std::vector<int>> incident;    // node -> segments
};

CutGraph build_cut_graph(const TriMesh& mesh, const Plane& plane) {
  const Eigen::Index nv = mesh.V.rows();
  std::vector<double> d(static_cast<std::size_t>(nv));
  for (Eigen::Index i = 0; i < nv; ++i) d[static_cast<std::size_t>(i)] = plane.signed_distance(mesh.V.row(i).transpose());
  // Symbolic perturbation: a vertex on the plane counts as positive.
  auto positive = [&](int i) { return d[static_cast<std::size_t>(i)] >= 0.0; };

  CutGraph g;
  std::unordered_map<std::uint64_t, int> node_of_edge;
  auto node = [&](int a, int b) {
    if (a > b) std::swap(a, b);  // canonical order: both triangles compute the same point
    const std::uint64_t key = (static_cast<std::uint64_t>(a) << 32) | static_cast<std::uint32_t>(b);
    auto [it, inserted] = node_of_edge.try_emplace(key, static_cast<int>(g.points.size()));
    if (inserted) {
      const double da = d[static_cast<std::size_t>(a)], db = d[static_cast<std::size_t>(b)];
      const double t = da / (da - db);
      const Vec3 pa = mesh.V.row(a).transpose(), pb = mesh.V.row(b).transpose();
      g.points.push_back(pa + t * (pb - pa));
      g.incident.emplace_back();
    }
    return it->second;
  };

  for (Eigen::Index t = 0; t < mesh.F.rows(); ++t) {
    const int v[3] = {mesh.F(t, 0), mesh.F(t, 1), mesh.F(t, 2)};
    int crossing[2];
    int found = 0;
    for (int k = 0; k < 3; ++k) {
      const int a = v[k], b = v[(k + 1) % 3];
      if (positive(a) != positive(b)) crossing[found++] = node(a, b);
    }
    if (found != 2) continue;  // all on one side (a sign change always crosses exactly two edges)
    const int s = static_cast<int>(g.segments.size());
    g.segments.push_back({crossing[0], crossing[1]});
    g.incident[static_cast<std::size_t>(crossing[0])].push_back(s);
    g.incident[static_cast<std::size_t>(crossing[1])].push_back(s);
  }
  return g;
}

// Walks the cut graph into chains: open chains between nodes whose degree is not 2 (mesh
// boundaries, non-manifold edges), then the remaining cycles.
std::vector<std::pair<std::vector<int>, bool>> walk(const CutGraph& g) {
  std::vector<std::pair<std::vector<int>, bool>> chains;
  std::vector<char> used(g.segments.size(), 0);
  auto degree = [&](int n) { return g.incident[static_cast<std::size_t>(n)].size(); };
  auto follow = [&](int start, int first_segment) {
    std::vector<int> nodes{start};
    int at = start, seg = first_segment;
    while (seg >= 0) {
      used[static_cast<std::size_t>(seg)] = 1;
      const auto& s = g.segments[static_cast<std::size_t>(seg)];
      at = s[0] == at ? s[1] : s[0];
      nodes.push_back(at);
      seg = -1;
      if (degree(at) != 2) break;
      for (int next : g.incident[static_cast<std::size_t>(at)])
        if (!used[static_cast<std::size_t>(next)]) seg = next;
    }
    return nodes;
  };
  for (int n = 0; n < static_cast<int>(g.points.size()); ++n) {
    if (degree(n) == 2) continue;
    for (int seg : g.incident[static_cast<std::size_t>(n)])
      if (!used[static_cast<std::size_t>(seg)]) chains.emplace_back(follow(n, seg), false);
  }
  for (int seg = 0; seg < static_cast<int>(g.segments.size()); ++seg) {
    if (used[static_cast<std::size_t>(seg)]) continue;
    std::vector<int> nodes = follow(g.segments[static_cast<std::size_t>(seg)][0], seg);
    nodes.pop_back();  // the walk came back to its start
    chains.emplace_back(std::move(nodes), true);
  }
  return chains;
}

bool lexicographic_less(const Vec3& a, const Vec3& b) {
  return std::lexicographical_compare(a.data(), a.data() + 3, b.data(), b.data() + 3);
}

}  // namespace

std::vector<Contour> slice(const TriMesh& mesh, const Plane& plane) {
  const CutGraph g = build_cut_graph(mesh, plane);
  const double tol = mesh.weld_tolerance;
  std::vector<Contour> contours;
  for (auto& [nodes, closed] : walk(g)) {
    Contour c;
    c.closed = closed;
    for (int n : nodes) {
      const Vec3& p = g.points[static_cast<std::size_t>(n)];
      if (c.points.empty() || (c.points.back() - p).norm() > tol) c.points.push_back(p);
    }
    if (closed) {
      while (c.points.size() > 1 && (c.points.back() - c.points.front()).norm() <= tol) c.points.pop_back();
      if (c.points.size() < 3) continue;
    } else if (c.points.size() < 2) {
      continue;
    }
    c.length = polyline_length(c.points, c.closed);
    if (closed) {
      Polyline2 flat;
      flat.reserve(c.points.size());
      for (const Vec3& p : c.points) flat.push_back(plane.to_2d(p));
      const double area = signed_area(flat);
      if (std::abs(area) <= tol * c.length) continue;  // a touch, not a cut: no width
      if (area < 0) std::reverse(c.points.begin(), c.points.end());
      // Start at the lexicographically smallest point so equal inputs give equal outputs.
      auto first = std::min_element(c.points.begin(), c.points.end(), lexicographic_less);
      std::rotate(c.points.begin(), first, c.points.end());
    } else if (lexicographic_less(c.points.back(), c.points.front())) {
      std::reverse(c.points.begin(), c.points.end());
    }
    contours.push_back(std::move(c));
  }
  std::sort(contours.begin(), contours.end(), [](const Contour& a, const Contour& b) {
    if (a.length != b.length) return a.length > b.length;
    return lexicographic_less(a.points.front(), b.points.front());
  });
  return contours;
}

}  // namespace wiresculpt
