#include "wiresculpt/target_shape.hpp"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstring>
#include <exception>
#include <limits>
#include <numbers>
#include <optional>
#include <string>
#include <vector>

#include "figures.hpp"
#include "target_shape_messages.hpp"
#include "target_shape_parts.hpp"
#include "target_shape_sqp.hpp"
#include "wiresculpt/error.hpp"

namespace wiresculpt {
namespace {

constexpr double pi = std::numbers::pi;

using detail::deg;
using detail::fmt;
using detail::mm;

using detail::angle_between;

constexpr int kMaxIterations = 10'000'000, kMaxWindow = 10'000, kMaxSweeps = 100'000;
constexpr double kMaxSeconds = 86'400.0;
constexpr double kMaxTargetPoints = 1e6;  // per wire, after subdividing at spacing/4
}  // namespace

double bend_limit(const TargetShapeOptions& options, int i) {
  const std::size_t k = static_cast<std::size_t>(i);
  return i >= 0 && k < options.vertex_max_bend.size() && options.vertex_max_bend[k] > 0.0
             ? std::min(options.vertex_max_bend[k], options.max_bend)
             : options.max_bend;
}

namespace {

void validate(const Polyline2& contour, bool closed, const std::vector<TargetCrossing>& crossings,
              const TargetShapeOptions& o) {
  const std::string& w = o.wire_name;
  auto bad = [&](const std::string& what) { throw InputError("target shape of wire " + w + ": " + what); };
  auto positive = [](double v) { return std::isfinite(v) && v > 0.0; };
  if (!positive(o.min_segment)) bad("min_segment must be a positive number of metres");
  if (!(positive(o.max_bend) && o.max_bend <= pi)) bad("max_bend must be in (0, π] radians");
  for (std::size_t i = 0; i < o.vertex_max_bend.size(); ++i)
    if (!(std::isfinite(o.vertex_max_bend[i]) && o.vertex_max_bend[i] <= pi))
      bad("vertex_max_bend[" + std::to_string(i) + "] must be a number of radians <= π (0: max_bend)");
  if (!(std::isfinite(o.spacing) && o.spacing >= 0.0)) bad("spacing must be >= 0 metres");
  if (!(std::isfinite(o.regularization) && o.regularization >= 0.0)) bad("regularization must be >= 0");
  if (!(std::isfinite(o.friction) && o.friction >= 0.0)) bad("friction must be >= 0");
  if (!positive(o.ftol_rel) || !positive(o.xtol_rel) || !positive(o.constraint_tol))
    bad("the solver tolerances must be positive");
  if (!positive(o.angle_tolerance) || !positive(o.length_tolerance)) bad("the check tolerances must be positive");
  // The ranges of docs/robustness.md: beyond them a run cannot end in reasonable time or memory.
  if (!(o.min_segment <= 10.0)) bad("min_segment must be at most 10 metres");
  if (!(o.spacing == 0.0 || (o.spacing >= 0.1 * o.min_segment && o.spacing <= 10.0)))
    bad("spacing must be 0 (1.5 x min_segment) or from min_segment/10 (" + mm(0.1 * o.min_segment) + ") to 10 metres");
  if (o.max_iterations <= 0 || o.max_iterations > kMaxIterations)
    bad("max_iterations must be from 1 to " + std::to_string(kMaxIterations));
  if (o.window < 0 || o.window > kMaxWindow || (o.window > 0 && o.window < 4))
    bad("window must be 0 (one block) or from 4 to " + std::to_string(kMaxWindow) + " points");
  if (o.one_block_points < -1 || o.one_block_points > kMaxWindow)
    bad("one_block_points must be -1 (4 x window) or from 0 to " + std::to_string(kMaxWindow) + " points");
  if (o.max_sweeps <= 0 || o.max_sweeps > kMaxSweeps) bad("max_sweeps must be from 1 to " + std::to_string(kMaxSweeps));
  if (!(o.max_seconds > 0.0 && o.max_seconds <= kMaxSeconds))
    bad("max_seconds must be more than 0 and at most " + std::to_string(static_cast<int>(kMaxSeconds)) + " seconds");
  if (!(o.model_size <= 1e6)) bad("model_size must be at most 1e6 metres");
  if (!positive(o.sweep_tol)) bad("sweep_tol must be a positive number of metres");
  if (!(std::isfinite(o.sweep_ftol) && o.sweep_ftol >= 0.0 && o.sweep_ftol < 1.0)) bad("sweep_ftol must be from 0 to less than 1");
  if (!(std::isfinite(o.model_size) && o.model_size >= 0.0)) bad("model_size must be >= 0 metres");
  const std::size_t n = contour.size();
  if (n < (closed ? 3u : 2u))
    bad("the contour has " + std::to_string(n) + " points; a " + (closed ? "closed" : "open") + " wire needs at least " +
        (closed ? "3" : "2"));
  for (std::size_t i = 0; i < n; ++i)
    if (!contour[i].allFinite()) bad("contour point " + std::to_string(i) + " is not finite");
  std::vector<char> used(n, 0);
  for (std::size_t c = 0; c < crossings.size(); ++c) {
    const TargetCrossing& x = crossings[c];
    const std::string name = "crossing " + std::to_string(c);
    if (x.vertex < 0 || static_cast<std::size_t>(x.vertex) >= n)
      bad(name + " names contour vertex " + std::to_string(x.vertex) + ", outside [0, " + std::to_string(n) + ")");
    if (used[x.vertex]) bad(name + " is at contour vertex " + std::to_string(x.vertex) + ", which another crossing already uses");
    used[x.vertex] = 1;
    if (x.active) {
      if (!x.bisector.allFinite() || x.bisector.norm() < 1e-12) bad(name + " is active but its bisector h* is zero or not finite");
      if (!(std::isfinite(x.contact_angle) && x.contact_angle > 0.0 && x.contact_angle <= pi))
        bad(name + " has contact angle " + fmt(x.contact_angle) + " rad, outside (0, π]");
    }
  }
}



// The knots of the initial resampling: the crossings in contour order (plus the ends of an open
// wire, or one canonical vertex of a closed wire without crossings, the lexicographically smallest,
// so that the result does not depend on where the contour starts or which way it runs). Crossing
// vertices must be valid contour indices (validate).
struct Knot {
  int vertex;
  int crossing;  // -1 for an end / anchor
};
std::vector<Knot> resampling_knots(const Polyline2& contour, bool closed, const std::vector<TargetCrossing>& crossings) {
  const int n = static_cast<int>(contour.size());
  std::vector<Knot> knots;
  std::vector<int> order(crossings.size());
  for (std::size_t c = 0; c < order.size(); ++c) order[c] = static_cast<int>(c);
  std::sort(order.begin(), order.end(), [&](int a, int b) { return crossings[a].vertex < crossings[b].vertex; });
  if (!closed && (order.empty() || crossings[order.front()].vertex != 0)) knots.push_back({0, -1});
  for (int c : order) knots.push_back({crossings[c].vertex, c});
  if (!closed && (order.empty() || crossings[order.back()].vertex != n - 1)) knots.push_back({n - 1, -1});
  if (closed && knots.empty()) {
    int best = 0;
    for (int i = 1; i < n; ++i)
      if (contour[i].x() < contour[best].x() || (contour[i].x() == contour[best].x() && contour[i].y() < contour[best].y()))
        best = i;
    knots.push_back({best, -1});
  }
  return knots;
}

// Segments of the initial resampling on the piece of `arc` metres from one knot to the next: arc /
// spacing rounded, at least one (three on a closed wire's only piece); between two crossings at
// least two where the arc allows a free point (2 l_min), else one (a gap, reported apart).
int piece_segments(double arc, double spacing, double lmin, bool between_crossings, std::size_t knots, bool closed) {
  int segments = std::max(1, static_cast<int>(std::lround(arc / spacing)));
  if (closed && knots == 1) segments = std::max(3, segments);
  if (between_crossings && knots > 1) segments = arc >= 2.0 * lmin ? std::max(2, segments) : 1;
  return segments;
}
}  // namespace

int detail::initial_point_count(const Polyline2& contour, bool closed, const std::vector<TargetCrossing>& crossings,
                                const TargetShapeOptions& o) {
  const int n = static_cast<int>(contour.size());
  if (n < 2) return -1;
  for (const TargetCrossing& c : crossings)
    if (c.vertex < 0 || c.vertex >= n) return -1;
  const double spacing = o.spacing > 0.0 ? o.spacing : 1.5 * o.min_segment;
  const int n_edges = closed ? n : n - 1;
  std::vector<double> cum(static_cast<std::size_t>(n_edges) + 1, 0.0);
  for (int i = 0; i < n_edges; ++i) cum[i + 1] = cum[i] + (contour[(i + 1) % n] - contour[i]).norm();
  const double total = cum[n_edges];
  if (!(total > 0.0) || !std::isfinite(total) || !(spacing > 0.0) || total / spacing > kMaxTargetPoints) return -1;
  const std::vector<Knot> knots = resampling_knots(contour, closed, crossings);
  const int pieces = closed ? static_cast<int>(knots.size()) : static_cast<int>(knots.size()) - 1;
  int count = closed ? 0 : 1;
  for (int k = 0; k < pieces; ++k) {
    const Knot& ka = knots[k];
    const Knot& kb = knots[(k + 1) % knots.size()];
    const double s0 = cum[ka.vertex];
    double s1 = cum[kb.vertex];
    if (closed && s1 <= s0) s1 += total;  // as the problem computes it, to the last bit
    const double arc = s1 - s0;
    count += piece_segments(arc, spacing, o.min_segment, ka.crossing >= 0 && kb.crossing >= 0, knots.size(), closed);
  }
  return count;
}

// Problem set-up: target, resampling, constraints.

TargetShapeProblem::TargetShapeProblem(const Polyline2& contour, bool closed,
                                       const std::vector<TargetCrossing>& crossings, const TargetShapeOptions& options)
    : options_(options), crossings_(crossings), closed_(closed) {
  validate(contour, closed, crossings, options);
  const TargetShapeOptions& o = options_;
  if (o.spacing == 0.0) options_.spacing = 1.5 * o.min_segment;
  for (TargetCrossing& c : crossings_)
    if (c.active) c.bisector.normalize();
  const std::vector<double> cum = arc_lengths(contour);
  build_target(contour);
  check_crossings(resample(contour, cum));
  collect_constraints();
}

std::vector<double> TargetShapeProblem::arc_lengths(const Polyline2& contour) const {
  const std::string& w = options_.wire_name;
  const double spacing = options_.spacing;
  const int n = static_cast<int>(contour.size());
  const int n_edges = closed_ ? n : n - 1;
  // Cumulative arc length of the input contour (closed: cum[n] is the total length).
  std::vector<double> cum(static_cast<std::size_t>(n_edges) + 1, 0.0);
  for (int i = 0; i < n_edges; ++i) cum[i + 1] = cum[i] + (contour[(i + 1) % n] - contour[i]).norm();
  const double total = cum[n_edges];
  if (!(total > 0.0)) throw InputError("target shape of wire " + w + ": the contour has zero length");
  if (total / (spacing / 4.0) > kMaxTargetPoints)
    throw InputError("target shape of wire " + w + ": the wire is " + fmt(total, 4) + " m long, which at a spacing of " +
                     mm(spacing) + " is more than " + fmt(kMaxTargetPoints, 1) +
                     " points; is the model in millimetres? scale it to its real size (size) or raise min_segment");
  return cum;
}

// The target: the input contour with long edges subdivided (at most spacing/4), so that the
// IMLS kernel never blends normals of distant parts of a coarse polygon; its normals, kernel
// support and the grids of its points and edges.
void TargetShapeProblem::build_target(const Polyline2& contour) {
  const bool closed = closed_;
  const double spacing = options_.spacing;
  const int n = static_cast<int>(contour.size());
  const int n_edges = closed ? n : n - 1;
  const double max_edge = spacing / 4.0;
  for (int i = 0; i < n_edges; ++i) {
    const Vec2 a = contour[i], b = contour[(i + 1) % n];
    const double len = (b - a).norm();
    if (len <= 0.0) continue;
    if (target_.empty() || (target_.back() - a).norm() > 0.0) target_.push_back(a);
    const int pieces = std::max(1, static_cast<int>(std::ceil(len / max_edge)));
    for (int k = 1; k < pieces; ++k) target_.push_back(a + (static_cast<double>(k) / pieces) * (b - a));
  }
  if (!closed) target_.push_back(contour[n - 1]);
  if (closed && target_.size() > 1 && (target_.back() - target_.front()).norm() == 0.0) target_.pop_back();
  const int m = static_cast<int>(target_.size());
  const int m_edges = closed ? m : m - 1;
  normals_.resize(m);
  double length = 0.0;
  for (int k = 0; k < m_edges; ++k) length += (target_[(k + 1) % m] - target_[k]).norm();
  for (int k = 0; k < m; ++k) {
    Vec2 t = Vec2::Zero();
    if (closed || k > 0) t += (target_[k] - target_[(k + m - 1) % m]).normalized();
    if (closed || k < m - 1) t += (target_[(k + 1) % m] - target_[k]).normalized();
    if (t.norm() < 1e-9) t = (target_[(k + 1) % m] - target_[k]).normalized();  // a cusp
    t.normalize();
    normals_[k] = Vec2(-t.y(), t.x());
  }
  h_ = 2.0 * length / std::max(1, m_edges);
  // Uniform grid of cell >= h over the target's bounding box (at most ~512 cells a side).
  Vec2 lo = target_[0], hi = target_[0];
  for (const Vec2& p : target_) lo = lo.cwiseMin(p), hi = hi.cwiseMax(p);
  const double extent = std::max((hi - lo).maxCoeff(), h_);
  cell_ = std::max(h_, extent / 512.0);
  grid_origin_ = lo;
  grid_nx_ = static_cast<int>((hi.x() - lo.x()) / cell_) + 1;
  grid_ny_ = static_cast<int>((hi.y() - lo.y()) / cell_) + 1;
  grid_start_.assign(static_cast<std::size_t>(grid_nx_) * grid_ny_ + 1, 0);
  auto cell_of = [&](const Vec2& p) {
    const int ix = std::clamp(static_cast<int>((p.x() - lo.x()) / cell_), 0, grid_nx_ - 1);
    const int iy = std::clamp(static_cast<int>((p.y() - lo.y()) / cell_), 0, grid_ny_ - 1);
    return iy * grid_nx_ + ix;
  };
  for (const Vec2& p : target_) ++grid_start_[cell_of(p) + 1];
  for (std::size_t c = 1; c < grid_start_.size(); ++c) grid_start_[c] += grid_start_[c - 1];
  grid_items_.assign(target_.size(), 0);
  std::vector<int> fill(grid_start_.begin(), grid_start_.end() - 1);
  for (int k = 0; k < m; ++k) grid_items_[fill[cell_of(target_[k])]++] = k;
  // The edges, by the cells of their bounding boxes (ecell_of is monotone, so the cell holding
  // any point of an edge lies in that range), on a grid of its own.
  // Cells of 2h: on the Airplane's recorded solves 1, 2 and 4 h took the same time within the
  // noise (docs/method-target-shape.md).
  edge_cell_ = 2.0 * cell_;
  edge_nx_ = static_cast<int>((hi.x() - lo.x()) / edge_cell_) + 1;
  edge_ny_ = static_cast<int>((hi.y() - lo.y()) / edge_cell_) + 1;
  auto ecell_of = [&](const Vec2& p) {
    const int ix = std::clamp(static_cast<int>((p.x() - lo.x()) / edge_cell_), 0, edge_nx_ - 1);
    const int iy = std::clamp(static_cast<int>((p.y() - lo.y()) / edge_cell_), 0, edge_ny_ - 1);
    return iy * edge_nx_ + ix;
  };
  auto edge_cells = [&](int k, auto&& visit) {
    const Vec2 a = target_[k], b = target_[(k + 1) % m];
    const int c0 = ecell_of(a.cwiseMin(b)), c1 = ecell_of(a.cwiseMax(b));
    for (int iy = c0 / edge_nx_; iy <= c1 / edge_nx_; ++iy)
      for (int ix = c0 % edge_nx_; ix <= c1 % edge_nx_; ++ix) visit(iy * edge_nx_ + ix);
  };
  edge_start_.assign(static_cast<std::size_t>(edge_nx_) * edge_ny_ + 1, 0);
  for (int k = 0; k < m_edges; ++k) edge_cells(k, [&](int c) { ++edge_start_[c + 1]; });
  for (std::size_t c = 1; c < edge_start_.size(); ++c) edge_start_[c] += edge_start_[c - 1];
  edge_items_.assign(static_cast<std::size_t>(edge_start_.back()), 0);
  std::vector<int> edge_fill(edge_start_.begin(), edge_start_.end() - 1);
  for (int k = 0; k < m_edges; ++k) edge_cells(k, [&](int c) { edge_items_[edge_fill[c]++] = k; });
}

// The initial resampling between the knots (crossings, ends), with the crossings' vertices and
// the pairs of consecutive crossings too close for a free point between them.
std::vector<TargetShapeProblem::Gap> TargetShapeProblem::resample(const Polyline2& contour,
                                                                  const std::vector<double>& cum) {
  const bool closed = closed_;
  const std::string& w = options_.wire_name;
  const double spacing = options_.spacing, lmin = options_.min_segment;
  const int n = static_cast<int>(contour.size());
  const int n_edges = closed ? n : n - 1;
  const double total = cum[n_edges];
  auto point_at = [&](double s) -> Vec2 {
    if (closed) s = std::fmod(std::fmod(s, total) + total, total);
    s = std::clamp(s, 0.0, total);
    int j = static_cast<int>(std::upper_bound(cum.begin(), cum.end(), s) - cum.begin()) - 1;
    j = std::clamp(j, 0, n_edges - 1);
    const double len = cum[j + 1] - cum[j];
    const double t = len > 0.0 ? (s - cum[j]) / len : 0.0;
    return contour[j] + std::clamp(t, 0.0, 1.0) * (contour[(j + 1) % n] - contour[j]);
  };

  const std::vector<Knot> knots = resampling_knots(contour, closed, crossings_);
  crossing_vertices_.assign(crossings_.size(), -1);
  statuses_.assign(crossings_.size(), TargetCrossingStatus{});
  std::vector<Gap> gaps;
  const int pieces = closed ? static_cast<int>(knots.size()) : static_cast<int>(knots.size()) - 1;
  for (int k = 0; k < pieces; ++k) {
    const Knot& ka = knots[k];
    const Knot& kb = knots[(k + 1) % knots.size()];
    const double s0 = cum[ka.vertex];
    double s1 = cum[kb.vertex];
    if (closed && s1 <= s0) s1 += total;  // wraps (or the single-knot loop)
    const double arc = s1 - s0;
    const bool between_crossings = ka.crossing >= 0 && kb.crossing >= 0;
    if (between_crossings && arc <= 0.0 && knots.size() > 1)
      throw InputError("target shape of wire " + w + ": crossings " + std::to_string(ka.crossing) + " and " +
                       std::to_string(kb.crossing) + " are at the same point of the contour");
    const int segments = piece_segments(arc, spacing, lmin, between_crossings, knots.size(), closed);
    if (between_crossings && knots.size() > 1 && arc < 2.0 * lmin)
      gaps.push_back({ka.crossing, kb.crossing, arc, (contour[kb.vertex] - contour[ka.vertex]).norm()});
    if (ka.crossing >= 0) crossing_vertices_[ka.crossing] = static_cast<int>(initial_.size());
    initial_.push_back(contour[ka.vertex]);
    fixed_.push_back(ka.crossing >= 0 ? 1 : 0);
    for (int j = 1; j < segments; ++j) {
      initial_.push_back(point_at(s0 + arc * j / segments));
      fixed_.push_back(0);
    }
  }
  if (!closed) {
    const Knot& last = knots.back();
    if (last.crossing >= 0) crossing_vertices_[last.crossing] = static_cast<int>(initial_.size());
    initial_.push_back(contour[last.vertex]);
    fixed_.push_back(last.crossing >= 0 ? 1 : 0);
  }
  return gaps;
}

// Per-crossing feasibility before solving: the causes no solve can change.
void TargetShapeProblem::check_crossings(const std::vector<Gap>& gaps) {
  const bool closed = closed_;
  const TargetShapeOptions& o = options_;
  const std::string& w = o.wire_name;
  const double lmin = o.min_segment;
  const int m = static_cast<int>(initial_.size());
  const double friction_angle = std::atan(o.friction);
  beta_.assign(crossings_.size(), 0.0);
  auto mark = [&](int c, CrossingCause cause, const CrossingFigures& figures) {
    TargetCrossingStatus& s = statuses_[c];
    if (!s.realised) return;  // keep the first reason
    detail::set_cause(s, c, w, cause, figures);
  };
  for (std::size_t c = 0; c < crossings_.size(); ++c) {
    const TargetCrossing& x = crossings_[c];
    TargetCrossingStatus& s = statuses_[c];
    s.vertex = crossing_vertices_[c];
    if (!x.active) {
      s.status = "inactive";
      continue;
    }
    beta_[c] = x.contact_angle / 2.0 - friction_angle;
    const int v = s.vertex;
    const int ci = static_cast<int>(c);
    CrossingFigures f;
    f.contact_angle = x.contact_angle;
    f.friction_angle = friction_angle;
    if (!closed && (v == 0 || v == m - 1)) {
      mark(ci, CrossingCause::open_end, {});
    } else if (beta_[c] <= 0.0) {
      mark(ci, CrossingCause::contact_vs_friction, f);
    } else if (pi - 2.0 * beta_[c] > o.max_bend + 1e-12) {
      // the bend is 180° less the contact angle, plus twice the friction angle
      f.bend = pi - 2.0 * beta_[c];
      f.limit = o.max_bend;
      mark(ci, CrossingCause::min_bend, f);
    }
  }
  for (const Gap& g : gaps) {
    CrossingFigures f;
    f.first = g.a;
    f.second = g.b;
    f.length = g.arc;
    f.limit = lmin;
    f.scale = detail::gap_scale(g.arc, lmin);
    f.model_size = o.model_size;
    if (g.chord < lmin) {
      // The direct segment is too short to bend: a fabrication problem whatever the hooks.
      mark(g.a, CrossingCause::short_piece, f);
      mark(g.b, CrossingCause::short_piece, f);
      continue;
    }
    // A fixed edge: its contact constraint is a constant that either holds or cannot be met.
    for (int c : {g.a, g.b}) {
      if (!crossings_[c].active || !statuses_[c].realised) continue;
      const int v = crossing_vertices_[c];
      const int other = crossing_vertices_[c == g.a ? g.b : g.a];
      const double a = angle_between(initial_[other] - initial_[v], crossings_[c].bisector);
      if (a > beta_[c] + o.angle_tolerance) mark(c, CrossingCause::fixed_edge, f);
    }
  }
}

// The solver's constraints: those touching at least one free point.
void TargetShapeProblem::collect_constraints() {
  const bool closed = closed_;
  const int m = static_cast<int>(initial_.size());
  const int edges = closed ? m : m - 1;
  for (int i = 0; i < edges; ++i)
    if (!fixed_[i] || !fixed_[(i + 1) % m]) constraints_.push_back({Kind::length, i, -1, -1});
  for (int i = 0; i < m; ++i) {
    if (!closed && (i == 0 || i == m - 1)) continue;
    const int a = (i + m - 1) % m, b = (i + 1) % m;
    if (m < 3) continue;
    if (!fixed_[a] || !fixed_[i] || !fixed_[b]) constraints_.push_back({Kind::bend, i, -1, -1});
  }
  for (std::size_t c = 0; c < crossings_.size(); ++c) {
    if (!crossings_[c].active || !statuses_[c].realised) continue;
    const int v = crossing_vertices_[c];
    for (int nb : {(v + m - 1) % m, (v + 1) % m})
      if (!fixed_[nb]) constraints_.push_back({Kind::contact, v, nb, static_cast<int>(c)});
  }
  // Each bend and contact constraint's cosine, taken once (every evaluation, and a dozen times
  // for each active one in the SQP's Hessian, reads it).
  constraint_cos_.reserve(constraints_.size());
  for (const Constraint& c : constraints_)
    constraint_cos_.push_back(c.kind == Kind::bend      ? std::cos(bend_limit(options_, c.vertex))
                              : c.kind == Kind::contact ? std::cos(beta_[c.crossing])
                                                        : 0.0);
}

namespace {
// d(û·v̂)/du for non-zero u.
Vec2 d_unit_dot(const Vec2& u, const Vec2& vhat) {
  const double len = u.norm();
  const Vec2 uhat = u / len;
  return (vhat - uhat.dot(vhat) * uhat) / len;
}
}  // namespace

double TargetShapeProblem::constraint(std::size_t k, const Polyline2& p, Polyline2* grad) const {
  const Constraint& c = constraints_.at(k);
  const int m = static_cast<int>(p.size());
  if (grad && static_cast<int>(grad->size()) != m) grad->resize(m, Vec2::Zero());
  switch (c.kind) {
    case Kind::length: {
      const double lmin2 = options_.min_segment * options_.min_segment;
      const auto pts = detail::constraint_points(c, m);
      const int a = pts[0], b = pts[1];
      const Vec2 e = p[b] - p[a];
      if (grad) {
        (*grad)[b] -= (2.0 / lmin2) * e;
        (*grad)[a] += (2.0 / lmin2) * e;
      }
      return 1.0 - e.squaredNorm() / lmin2;
    }
    case Kind::bend: {
      const auto [a, i, b] = detail::constraint_points(c, m);
      const Vec2 u = p[i] - p[a], v = p[b] - p[i];
      const Vec2 uh = u.normalized(), vh = v.normalized();
      if (grad) {
        const Vec2 du = d_unit_dot(u, vh), dv = d_unit_dot(v, uh);  // of û·v̂
        (*grad)[a] += du;
        (*grad)[i] -= du;
        (*grad)[i] += dv;
        (*grad)[b] -= dv;
      }
      return constraint_cos_[k] - uh.dot(vh);  // cos(bend limit)
    }
    case Kind::contact: {
      const Vec2& h = crossings_[c.crossing].bisector;
      const Vec2 u = p[c.neighbour] - p[c.vertex];
      if (grad) {
        const Vec2 du = d_unit_dot(u, h);
        (*grad)[c.neighbour] -= du;
        (*grad)[c.vertex] += du;
      }
      return constraint_cos_[k] - u.normalized().dot(h);  // cos(β)
    }
  }
  return 0.0;
}

}  // namespace wiresculpt
