// Where the target shape's solve starts (detail::start_points).
#include <cmath>
#include <string>

#include "target_shape_parts.hpp"
#include "wiresculpt/error.hpp"

namespace wiresculpt::detail {
namespace {

// A previous result of this problem: its free points (the crossings stay the contour's).
void take_warm_start(const TargetShapeProblem& problem, Polyline2& p) {
  const TargetShapeOptions& o = problem.options();
  const std::string& w = o.wire_name;
  const int m = static_cast<int>(p.size());
  if (o.start.size() != p.size())
    throw InputError("target shape of wire " + w + ": start has " + std::to_string(o.start.size()) +
                     " points, but this contour with these crossings and spacing has " + std::to_string(m));
  for (int i = 0; i < m; ++i) {
    if (!o.start[i].allFinite())
      throw InputError("target shape of wire " + w + ": start point " + std::to_string(i) + " is not finite");
    if (!problem.fixed()[i]) p[i] = o.start[i];
  }
}

// Each free neighbour of an active crossing that lies outside the contact cone turned about the
// crossing point onto the cone (keeping its distance and its side of h*). The regulariser still
// measures from initial().
void open_kinks(const TargetShapeProblem& problem, Polyline2& p) {
  const int m = static_cast<int>(p.size());
  for (std::size_t c = 0; c < problem.crossings().size(); ++c) {
    const TargetCrossingStatus& s = problem.statuses()[c];
    if (!problem.crossings()[c].active || !s.realised) continue;
    const Vec2 h = problem.crossings()[c].bisector;
    const double cone = problem.beta(c) * (1.0 - 1e-3);
    const int v = s.vertex;
    int side_used = 0;
    for (int nb : {(v + m - 1) % m, (v + 1) % m}) {
      const Vec2 u = p[nb] - p[v];
      int side = cross2(h, u) >= 0.0 ? 1 : -1;
      if (side == side_used) side = -side;  // both edges on one side would close the kink
      side_used = side;
      const bool inside = angle_between(u, h) <= cone && side == (cross2(h, u) >= 0.0 ? 1 : -1);
      if (problem.fixed()[nb] || inside) continue;
      const double a = side * cone;
      p[nb] = p[v] + u.norm() * Vec2(std::cos(a) * h.x() - std::sin(a) * h.y(), std::sin(a) * h.x() + std::cos(a) * h.y());
    }
  }
}
}  // namespace

Polyline2 start_points(const TargetShapeProblem& problem) {
  Polyline2 p = problem.initial();
  if (!problem.options().start.empty())
    take_warm_start(problem, p);
  else
    open_kinks(problem, p);
  return p;
}

}  // namespace wiresculpt::detail
