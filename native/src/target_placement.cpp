// detail::place_target: a wire's optimised 2D points placed in its plane, and their length.
#include <cmath>
#include <cstddef>
#include <vector>

#include "exact/numpy_sum.hpp"
#include "wiresculpt/target_shape.hpp"

namespace wiresculpt::detail {

void place_target(TargetShapeResult& r, const Plane& plane, bool closed) {
  const std::size_t n = r.points.size();
  r.target.resize(n);
  // origin + x u, then + y v, coordinate by coordinate: numpy's to_3d (core/frames.py) adds them
  // in this order.
  for (std::size_t i = 0; i < n; ++i)
    for (int j = 0; j < 3; ++j) {
      const double along_u = plane.origin[j] + r.points[i].x() * plane.u[j];
      r.target[i][j] = along_u + r.points[i].y() * plane.v[j];
    }
  r.length = 0.0;
  if (n < 2) return;
  // The edges' norms as core/polylines.polyline_length takes them: (dx² + dy²) + dz², its square
  // root, the closing edge (first - last) last; then numpy's sum of them.
  std::vector<double> norms;
  norms.reserve(n);
  auto norm = [](const Vec3& e) { return std::sqrt((e[0] * e[0] + e[1] * e[1]) + e[2] * e[2]); };
  for (std::size_t i = 1; i < n; ++i) norms.push_back(norm(r.target[i] - r.target[i - 1]));
  if (closed) norms.push_back(norm(r.target.front() - r.target.back()));
  r.length = numpy_sum(norms.data(), norms.size());
}

}  // namespace wiresculpt::detail
