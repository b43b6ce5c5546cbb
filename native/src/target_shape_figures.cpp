// The figures of a solved target shape (detail::measure_result): distances to the contour, the
// machine limits it keeps or breaks, and each crossing's achieved kink.
#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <string>
#include <vector>

#include "target_shape_messages.hpp"
#include "target_shape_parts.hpp"

namespace wiresculpt::detail {
namespace {

// Distances to the contour, segments and bends: the points of segments under min_segment and of
// bends over their limits (beyond the tolerances) into `short_edges` and `sharp_bends`.
void measure_points(const TargetShapeProblem& problem, const Polyline2& p, TargetShapeResult& result,
                    std::vector<int>& short_edges, std::vector<int>& sharp_bends) {
  const TargetShapeOptions& o = problem.options();
  const bool closed = problem.closed();
  const int m = static_cast<int>(p.size());
  double sum2 = 0.0;
  for (const Vec2& q : p) {
    const double d = problem.distance_to_contour(q);
    result.max_distance = std::max(result.max_distance, d);
    sum2 += d * d;
  }
  result.rms_distance = std::sqrt(sum2 / std::max(m, 1));
  const int edges = closed ? m : m - 1;
  result.min_segment = std::numeric_limits<double>::infinity();
  for (int i = 0; i < edges; ++i) {
    const double len = (p[(i + 1) % m] - p[i]).norm();
    result.min_segment = std::min(result.min_segment, len);
    const double v = o.min_segment - len;
    if (v > 0.0) result.max_length_violation = std::max(result.max_length_violation, v);
    if (v > o.length_tolerance) short_edges.push_back(i);
  }
  if (edges == 0) result.min_segment = 0.0;
  for (int i = 0; i < m; ++i) {
    if ((!closed && (i == 0 || i == m - 1)) || m < 3) continue;
    const Vec2 u = p[i] - p[(i + m - 1) % m], v = p[(i + 1) % m] - p[i];
    const double bend = angle_between(u, v);
    result.max_bend = std::max(result.max_bend, bend);
    const double limit = bend_limit(o, i);
    if (bend - limit > 0.0) result.max_angle_violation = std::max(result.max_angle_violation, bend - limit);
    if (bend - limit > o.angle_tolerance) sharp_bends.push_back(i);
  }
}

// Each crossing's achieved bisector and contact angle; an active realised one whose kink is
// outside its cone is not realised (cone_missed).
void measure_kinks(const TargetShapeProblem& problem, const std::vector<TargetCrossing>& crossings, const Polyline2& p,
                   TargetShapeResult& result) {
  const TargetShapeOptions& o = problem.options();
  const bool closed = problem.closed();
  const int m = static_cast<int>(p.size());
  const double friction_angle = std::atan(o.friction);
  for (std::size_t c = 0; c < crossings.size(); ++c) {
    TargetCrossingStatus& s = result.crossings[c];
    const int v = s.vertex;
    const bool has_prev = closed || v > 0, has_next = closed || v < m - 1;
    if (has_prev && has_next) {
      const Vec2 en = (p[(v + 1) % m] - p[v]).normalized(), ep = (p[v] - p[(v + m - 1) % m]).normalized();
      const Vec2 b = en - ep;
      s.bisector = b.norm() > 1e-12 ? Vec2(b.normalized()) : Vec2::Zero();
      s.contact_angle = angle_between(en, -ep);
    }
    if (!crossings[c].active) continue;
    const Vec2 h = crossings[c].bisector.normalized();
    double worst = -std::numeric_limits<double>::infinity();
    for (int nb : {v - 1, v + 1}) {
      if (!closed && (nb < 0 || nb >= m)) continue;
      const double a = angle_between(p[(nb + m) % m] - p[v], h) + friction_angle - crossings[c].contact_angle / 2.0;
      worst = std::max(worst, a);
    }
    s.contact_violation = std::isfinite(worst) ? worst : 0.0;
    if (!s.realised) continue;
    result.max_angle_violation = std::max(result.max_angle_violation, s.contact_violation);
    if (s.contact_violation > o.angle_tolerance) {
      result.feasible = false;
      CrossingFigures f;
      f.violation = s.contact_violation;
      set_cause(s, static_cast<int>(c), o.wire_name, CrossingCause::cone_missed, f);
    }
  }
}

// A kink whose neighbours break a machine limit is not made either: the solver met the contact
// constraints at the expense of a bend or segment next to the crossing (the kink, l_min and the
// bend limit conflict there). Blaming the crossing lets the caller null it (or choose the other
// hook) instead of passing on a wire the bender cannot make.
void check_neighbours(const TargetShapeProblem& problem, const std::vector<TargetCrossing>& crossings,
                      const Polyline2& p, TargetShapeResult& result) {
  const TargetShapeOptions& o = problem.options();
  const bool closed = problem.closed();
  const int m = static_cast<int>(p.size());
  std::vector<char> is_fixed(static_cast<std::size_t>(m), 0);
  for (const auto& st : result.crossings) is_fixed[static_cast<std::size_t>(st.vertex)] = 1;
  auto over_at = [&](int i) {  // the bend at point i beyond its limit (radians), 0 when within or an end
    if (m < 3 || (!closed && (i <= 0 || i >= m - 1))) return 0.0;
    const int k = (i + m) % m;
    const double bend = angle_between(p[k] - p[(k + m - 1) % m], p[(k + 1) % m] - p[k]);
    return bend - bend_limit(o, k) > o.angle_tolerance ? bend : 0.0;
  };
  for (std::size_t c = 0; c < crossings.size(); ++c) {
    TargetCrossingStatus& s = result.crossings[c];
    if (!crossings[c].active || !s.realised) continue;
    const int v = s.vertex;
    for (int nb : {v - 1, v + 1}) {
      if (!closed && (nb < 0 || nb >= m)) continue;
      const int k = (nb + m) % m;
      if (is_fixed[static_cast<std::size_t>(k)]) continue;  // between fixed points: too_close's case
      const double bend = over_at(nb);
      const double len = (p[k] - p[v]).norm();
      if (bend <= 0.0 && o.min_segment - len <= o.length_tolerance) continue;
      result.feasible = false;
      CrossingFigures f;
      f.point = k;
      if (bend > 0.0) {
        f.bend = bend;
        f.limit = bend_limit(o, k);
      } else {
        f.length = len;
        f.limit = o.min_segment;
      }
      set_cause(s, static_cast<int>(c), o.wire_name,
                bend > 0.0 ? CrossingCause::neighbour_bend : CrossingCause::neighbour_segment, f);
      break;
    }
  }
}

// The first eight of the points, "3, 5, 9, ...".
std::string point_list(const std::vector<int>& v) {
  std::string s;
  for (std::size_t k = 0; k < v.size() && k < 8; ++k) s += (k ? ", " : "") + std::to_string(v[k]);
  if (v.size() > 8) s += ", ...";
  return s;
}
}  // namespace

void measure_result(const TargetShapeProblem& problem, const std::vector<TargetCrossing>& crossings,
                    const Polyline2& p, TargetShapeResult& result) {
  const TargetShapeOptions& o = problem.options();
  const std::string& w = o.wire_name;
  result.points = p;
  result.crossing_vertices = problem.crossing_vertices();
  result.crossings = problem.statuses();
  result.energy = problem.energy(p);
  std::vector<int> short_edges, sharp_bends;
  measure_points(problem, p, result, short_edges, sharp_bends);
  measure_kinks(problem, crossings, p, result);
  check_neighbours(problem, crossings, p, result);
  if (!short_edges.empty())
    result.warnings.push_back("wire " + w + ": segments starting at points " + point_list(short_edges) +
                              " are shorter than " + mm(o.min_segment) + " (by up to " + mm(result.max_length_violation) +
                              ")");
  if (!sharp_bends.empty())
    result.warnings.push_back("wire " + w + ": bends at points " + point_list(sharp_bends) + " exceed " + deg(o.max_bend) +
                              (o.vertex_max_bend.empty() ? "" : " or their own limits (vertex_max_bend)"));
  result.feasible = result.feasible && short_edges.empty() && sharp_bends.empty();
}

}  // namespace wiresculpt::detail
