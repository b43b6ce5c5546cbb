#include "wiresculpt/geometry.hpp"

#include <cmath>
#include <limits>

#include "wiresculpt/error.hpp"

namespace wiresculpt {

Plane Plane::make(const Vec3& origin, const Vec3& normal, const std::string& name) {
  if (!origin.allFinite()) throw InputError(name + ": origin has a non-finite coordinate");
  if (!normal.allFinite()) throw InputError(name + ": normal has a non-finite coordinate");
  const double len = normal.norm();
  if (!(len > 1e-12)) throw InputError(name + ": normal is zero; give a direction such as [0, 0, 1]");
  Plane p;
  p.origin = origin;
  p.normal = normal / len;
  // u: the world axis least aligned with the normal, projected into the plane. Deterministic,
  // so the same plane always has the same 2D frame.
  Eigen::Index axis = 0;
  p.normal.cwiseAbs().minCoeff(&axis);
  Vec3 seed = Vec3::Zero();
  seed[axis] = 1.0;
  p.u = (seed - seed.dot(p.normal) * p.normal).normalized();
  p.v = p.normal.cross(p.u);
  return p;
}

namespace {
template <class Points>
double length_of(const Points& points, bool closed) {
  double total = 0.0;
  for (std::size_t i = 1; i < points.size(); ++i) total += (points[i] - points[i - 1]).norm();
  if (closed && points.size() > 1) total += (points.front() - points.back()).norm();
  return total;
}
}  // namespace

double polyline_length(const Polyline3& points, bool closed) { return length_of(points, closed); }
double polyline_length(const Polyline2& points, bool closed) { return length_of(points, closed); }

double largest_box_side(const std::vector<Polyline3>& polylines) {
  Vec3 low = Vec3::Constant(std::numeric_limits<double>::infinity()), high = -low;
  bool any = false;
  for (const Polyline3& points : polylines)
    for (const Vec3& p : points) {
      if (p.hasNaN()) return std::numeric_limits<double>::quiet_NaN();  // numpy's max and min pass NaN on
      low = low.cwiseMin(p), high = high.cwiseMax(p);
      any = true;
    }
  if (!any) return 0.0;
  const Vec3 sides = high - low;  // NaN where a column is all +inf or all -inf, as numpy's
  return sides.hasNaN() ? std::numeric_limits<double>::quiet_NaN() : sides.maxCoeff();
}

double signed_area(const Polyline2& points) {
  double twice = 0.0;
  const std::size_t n = points.size();
  for (std::size_t i = 0; i < n; ++i) {
    const Vec2& a = points[i];
    const Vec2& b = points[(i + 1) % n];
    twice += a.x() * b.y() - b.x() * a.y();
  }
  return 0.5 * twice;
}

}  // namespace wiresculpt
