#pragma once
// Small geometric vocabulary shared by every stage: points, planes with an in-plane frame,
// polyline measures. SI units throughout (metres, radians).
#include <Eigen/Core>
#include <Eigen/Geometry>
#include <string>
#include <vector>

namespace wiresculpt {

using Vec2 = Eigen::Vector2d;
using Vec3 = Eigen::Vector3d;
using Polyline2 = std::vector<Vec2>;
using Polyline3 = std::vector<Vec3>;

/// A plane through `origin` with unit `normal`, and an orthonormal in-plane frame (u, v) with
/// u × v = normal, so 2D coordinates in the plane are right-handed about the normal.
struct Plane {
  Vec3 origin = Vec3::Zero();
  Vec3 normal = Vec3::UnitZ();
  Vec3 u = Vec3::UnitX();
  Vec3 v = Vec3::UnitY();

  /// Builds a plane from any non-zero normal (normalised here). Throws InputError naming
  /// `name` when the origin or normal is not finite or the normal is (nearly) zero.
  static Plane make(const Vec3& origin, const Vec3& normal, const std::string& name = "plane");

  double signed_distance(const Vec3& p) const { return normal.dot(p - origin); }
  Vec2 to_2d(const Vec3& p) const { return {u.dot(p - origin), v.dot(p - origin)}; }
  Vec3 to_3d(const Vec2& q) const { return origin + q.x() * u + q.y() * v; }
};

/// Sum of edge lengths; `closed` adds the edge from the last point back to the first.
double polyline_length(const Polyline3& points, bool closed);
double polyline_length(const Polyline2& points, bool closed);

/// The largest side of the bounding box of every point of `polylines` (metres; 0 without points,
/// NaN when a coordinate is NaN or a side is inf - inf): the add-on's model size (core/design.py
/// model_size, the same extremes and differences, so the same number; that one raises without
/// points).
double largest_box_side(const std::vector<Polyline3>& polylines);

/// Signed area of a closed 2D polygon (positive when counter-clockwise).
double signed_area(const Polyline2& points);

}  // namespace wiresculpt
