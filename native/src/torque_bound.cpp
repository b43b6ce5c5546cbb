#include "wiresculpt/torque_bound.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <set>

#include "wiresculpt/error.hpp"

namespace wiresculpt {

const char* torque_bound_name(TorqueBound bound) { return bound == TorqueBound::in_plane ? "in_plane" : "3d"; }

TorqueBound parse_torque_bound(const std::string& text, const std::string& key) {
  if (text == "3d") return TorqueBound::full_3d;
  if (text == "in_plane") return TorqueBound::in_plane;
  throw InputError(key + " must be \"3d\" or \"in_plane\", not '" + text + "'");
}

TorquePolytope geodesic_polytope(int frequency) {
  if (frequency < 1) throw InputError("geodesic polytope: frequency must be at least 1");
  // Icosahedron with poles on the first axis (n): rings of five at ±1/√5, the lower one turned
  // by 36°. Frame components (n, u, v).
  const double pi = std::acos(-1.0);
  const double h = 1.0 / std::sqrt(5.0), rho = 2.0 / std::sqrt(5.0);
  std::array<Vec3, 12> ico;
  ico[0] = Vec3(1, 0, 0);
  ico[11] = Vec3(-1, 0, 0);
  for (int k = 0; k < 5; ++k) {
    const double up = 2.0 * pi * k / 5.0, down = up + pi / 5.0;
    ico[1 + k] = Vec3(h, rho * std::cos(up), rho * std::sin(up));
    ico[6 + k] = Vec3(-h, rho * std::cos(down), rho * std::sin(down));
  }
  std::vector<std::array<int, 3>> faces;
  for (int k = 0; k < 5; ++k) {
    const int u0 = 1 + k, u1 = 1 + (k + 1) % 5, l0 = 6 + k, l1 = 6 + (k + 1) % 5;
    faces.push_back({0, u0, u1});
    faces.push_back({u0, l0, u1});
    faces.push_back({u1, l0, l1});
    faces.push_back({11, l1, l0});
  }
  // Subdivide; shared points are merged by position (they are computed from the same corners).
  std::vector<Vec3> points;
  auto point = [&](const Vec3& p) {
    const Vec3 q = p.normalized();
    for (std::size_t i = 0; i < points.size(); ++i)
      if ((points[i] - q).norm() < 1e-9) return static_cast<int>(i);
    points.push_back(q);
    return static_cast<int>(points.size()) - 1;
  };
  const int f = frequency;
  std::vector<std::array<int, 3>> tris;
  for (const auto& [a, b, c] : faces) {
    std::vector<std::vector<int>> grid(f + 1);
    for (int i = 0; i <= f; ++i)
      for (int j = 0; j <= f - i; ++j)
        grid[i].push_back(point((ico[a] * (f - i - j) + ico[b] * i + ico[c] * j) / static_cast<double>(f)));
    for (int i = 0; i < f; ++i)
      for (int j = 0; j < f - i; ++j) {
        tris.push_back({grid[i][j], grid[i + 1][j], grid[i][j + 1]});
        if (i + j < f - 1) tris.push_back({grid[i + 1][j], grid[i + 1][j + 1], grid[i][j + 1]});
      }
  }
  TorquePolytope out;
  double nearest = 1.0;
  std::vector<std::vector<int>> at_point(points.size());
  for (std::size_t t = 0; t < tris.size(); ++t) {
    const auto& [a, b, c] = tris[t];
    Vec3 d = (points[b] - points[a]).cross(points[c] - points[a]).normalized();
    if (d.dot(points[a] + points[b] + points[c]) < 0) d = -d;
    // The facet's distance: the largest of its corners', so that every corner (±n among them)
    // satisfies its row to rounding.
    const double r = std::max({d.dot(points[a]), d.dot(points[b]), d.dot(points[c])});
    for (int p : tris[t])
      if (std::abs(points[p].x()) > 1.0 - 1e-12) out.apex.push_back(static_cast<int>(t));
    out.rows.push_back(d / r);
    nearest = std::min(nearest, r);
    for (int p : tris[t]) at_point[p].push_back(static_cast<int>(t));
  }
  out.gap = 1.0 - nearest;
  out.neighbours.resize(tris.size());
  for (std::size_t t = 0; t < tris.size(); ++t) {
    std::set<int> near;
    for (int p : tris[t])
      for (int other : at_point[p])
        if (other != static_cast<int>(t)) near.insert(other);
    out.neighbours[t].assign(near.begin(), near.end());
  }
  return out;
}

const TorquePolytope& torque_polytope(TorqueBound bound) {
  static const TorquePolytope slab{{Vec3(1, 0, 0), Vec3(-1, 0, 0)}, {{}, {}}, {0, 1}, 0.0};
  static const TorquePolytope ball = geodesic_polytope(3);
  return bound == TorqueBound::in_plane ? slab : ball;
}

double torque_gauge(const TorquePolytope& polytope, const Vec3& t_frame, double t_max, int* row) {
  double best = -std::numeric_limits<double>::infinity();
  int arg = -1;
  for (std::size_t k = 0; k < polytope.rows.size(); ++k) {
    const double g = polytope.rows[k].dot(t_frame);
    if (g > best) {
      best = g;
      arg = static_cast<int>(k);
    }
  }
  if (row) *row = arg;
  return best / t_max;
}

}  // namespace wiresculpt
