#include "wiresculpt/target_shape.hpp"

#include <nlopt.hpp>

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

#include "nlopt_text.hpp"
#include "target_shape_messages.hpp"
#include "target_shape_sqp.hpp"
#include "wiresculpt/error.hpp"

namespace wiresculpt {
namespace {

constexpr double pi = std::numbers::pi;
// Kernel mass below which E_d blends from the IMLS into the nearest-point distance. A point on a
// densely sampled target has Φ ≈ 1.63 (h = 2 × spacing); Φ = 0.5 is reached about 0.45 h off it.
constexpr double kernel_mass_full = 0.5;

using detail::deg;
using detail::fmt;
using detail::mm;

double cross2(const Vec2& a, const Vec2& b) { return a.x() * b.y() - a.y() * b.x(); }

// Angle in [0, π] between two non-zero vectors.
double angle_between(const Vec2& a, const Vec2& b) { return std::atan2(std::abs(cross2(a, b)), a.dot(b)); }


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

// Closest point of segment [a, b] to q.
Vec2 closest_on_segment(const Vec2& q, const Vec2& a, const Vec2& b) {
  const Vec2 d = b - a;
  const double l2 = d.squaredNorm();
  if (l2 <= 0.0) return a;
  const double t = std::clamp((q - a).dot(d) / l2, 0.0, 1.0);
  return a + t * d;
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

// ---------------------------------------------------------------------------------------------
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
  const std::string& w = o.wire_name;
  if (o.spacing == 0.0) options_.spacing = 1.5 * o.min_segment;
  for (TargetCrossing& c : crossings_)
    if (c.active) c.bisector.normalize();
  const double spacing = options_.spacing, lmin = o.min_segment;
  const int n = static_cast<int>(contour.size());
  const int n_edges = closed ? n : n - 1;

  // Cumulative arc length of the input contour (closed: cum[n] is the total length).
  std::vector<double> cum(static_cast<std::size_t>(n_edges) + 1, 0.0);
  for (int i = 0; i < n_edges; ++i) cum[i + 1] = cum[i] + (contour[(i + 1) % n] - contour[i]).norm();
  const double total = cum[n_edges];
  if (!(total > 0.0)) throw InputError("target shape of wire " + w + ": the contour has zero length");
  if (total / (spacing / 4.0) > kMaxTargetPoints)
    throw InputError("target shape of wire " + w + ": the wire is " + fmt(total, 4) + " m long, which at a spacing of " +
                     mm(spacing) + " is more than " + fmt(kMaxTargetPoints, 1) +
                     " points; is the model in millimetres? scale it to its real size (size) or raise min_segment");
  auto point_at = [&](double s) -> Vec2 {
    if (closed) s = std::fmod(std::fmod(s, total) + total, total);
    s = std::clamp(s, 0.0, total);
    int j = static_cast<int>(std::upper_bound(cum.begin(), cum.end(), s) - cum.begin()) - 1;
    j = std::clamp(j, 0, n_edges - 1);
    const double len = cum[j + 1] - cum[j];
    const double t = len > 0.0 ? (s - cum[j]) / len : 0.0;
    return contour[j] + std::clamp(t, 0.0, 1.0) * (contour[(j + 1) % n] - contour[j]);
  };

  // The target: the input contour with long edges subdivided (at most spacing/4), so that the
  // IMLS kernel never blends normals of distant parts of a coarse polygon.
  {
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
    // noise (docs/method-target-shape.md, issue 17, fourth round).
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

  const std::vector<Knot> knots = resampling_knots(contour, closed, crossings_);
  crossing_vertices_.assign(crossings_.size(), -1);
  statuses_.assign(crossings_.size(), TargetCrossingStatus{});
  struct Gap {
    int a, b;  // crossings
    double arc, chord;
  };
  std::vector<Gap> gaps;  // consecutive crossings without a free point between them
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
  const int m = static_cast<int>(initial_.size());

  // Per-crossing feasibility before solving.
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
    f.scale = 2.0 * lmin / std::max(g.arc, 1e-300);
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

  // The solver's constraints: those touching at least one free point.
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

// ---------------------------------------------------------------------------------------------
// Energy terms.

double TargetShapeProblem::nearest_squared(const Vec2& q, Vec2* grad) const {
  const int m = static_cast<int>(target_.size());
  const int m_edges = closed_ ? m : m - 1;
  double best = std::numeric_limits<double>::infinity();
  Vec2 best_point = target_[0];
  int best_edge = -1;
  // Equally near edges (two edges meeting at the nearest vertex: one ends there at a + 1·(b - a),
  // the other starts there, points that can differ in the last bit) are decided as the search by
  // target points did before (issue 17): the edge it tested first, in its order of rings, rows,
  // cells, points and, per point k, edge k before edge k - 1; or the lower index when q was
  // outside the points' grid. So the gradient, hence every solve, is the same as before.
  using Rank = std::array<long long, 5>;
  auto rank = [&](int k) {
    const double fx = (q.x() - grid_origin_.x()) / cell_, fy = (q.y() - grid_origin_.y()) / cell_;
    if (fx < 0 || fy < 0 || fx >= grid_nx_ || fy >= grid_ny_) return Rank{0, 0, 0, k, 0};
    const int cx = static_cast<int>(fx), cy = static_cast<int>(fy);
    auto from_point = [&](int v, int sub) {
      const Vec2& p = target_[v];
      const int ix = std::clamp(static_cast<int>((p.x() - grid_origin_.x()) / cell_), 0, grid_nx_ - 1);
      const int iy = std::clamp(static_cast<int>((p.y() - grid_origin_.y()) / cell_), 0, grid_ny_ - 1);
      return Rank{std::max(std::abs(ix - cx), std::abs(iy - cy)), iy, ix, v, sub};
    };
    return std::min(from_point(k, 0), from_point((k + 1) % m, 1));
  };
  auto try_edge = [&](int k) {
    const Vec2 c = closest_on_segment(q, target_[k], target_[(k + 1) % m]);
    const double d2 = (q - c).squaredNorm();
    if (d2 < best || (d2 == best && best_edge >= 0 && k != best_edge && rank(k) < rank(best_edge))) best = d2, best_point = c, best_edge = k;
  };
  if (m_edges == 0) {
    best = (q - target_[0]).squaredNorm();
  } else {
    const double fx = (q.x() - grid_origin_.x()) / edge_cell_, fy = (q.y() - grid_origin_.y()) / edge_cell_;
    if (!std::isfinite(fx) || !std::isfinite(fy)) {
      for (int k = 0; k < m_edges; ++k) try_edge(k);  // no distance to compare: as every edge says
    } else {
      // Rings of grid cells around q's cell, each cell holding the edges that meet it. A cell of
      // ring r is at least (r - 1) cells from q, and a cell farther from q than the best distance
      // so far cannot hold a nearer point: both are skipped, with a picometre of slack for the
      // rounding of the cell bounds, so the minimum is that of every edge (an edge tested twice,
      // from two cells, changes nothing: only a strictly nearer point replaces the best).
      constexpr double slack = 1e-12;  // m
      // q's cell, or the cell of the grid nearest it when q is outside the target's box (kink
      // neighbours pushed beyond the contour's extremes): a cell r rings from it is still at least
      // r - 1 cells from q.
      const int cx = static_cast<int>(std::clamp(fx, 0.0, edge_nx_ - 1.0));
      const int cy = static_cast<int>(std::clamp(fy, 0.0, edge_ny_ - 1.0));
      const int max_ring = std::max(edge_nx_, edge_ny_);
      double reach2 = std::numeric_limits<double>::infinity();  // (sqrt(best) + slack)^2
      auto visit = [&](int ix, int iy) {
        const double x0 = grid_origin_.x() + ix * edge_cell_, y0 = grid_origin_.y() + iy * edge_cell_;
        const double dx = std::max({0.0, x0 - q.x(), q.x() - (x0 + edge_cell_)});
        const double dy = std::max({0.0, y0 - q.y(), q.y() - (y0 + edge_cell_)});
        if (dx * dx + dy * dy > reach2) return;
        const int cell = iy * edge_nx_ + ix;
        for (int it = edge_start_[cell]; it < edge_start_[cell + 1]; ++it) {
          const double before = best;
          try_edge(edge_items_[it]);
          if (best < before) reach2 = (std::sqrt(best) + slack) * (std::sqrt(best) + slack);
        }
      };
      for (int ring = 0; ring <= max_ring; ++ring) {
        const double gap = (ring - 1) * edge_cell_;
        if (ring > 1 && gap * gap > reach2) break;
        for (int iy = std::max(cy - ring, 0); iy <= std::min(cy + ring, edge_ny_ - 1); ++iy) {
          const bool edge_row = iy == cy - ring || iy == cy + ring;
          if (edge_row) {
            for (int ix = std::max(cx - ring, 0); ix <= std::min(cx + ring, edge_nx_ - 1); ++ix) visit(ix, iy);
          } else {
            if (cx - ring >= 0) visit(cx - ring, iy);
            if (cx + ring < edge_nx_) visit(cx + ring, iy);
          }
        }
      }
    }
  }
  if (grad) *grad = 2.0 * (q - best_point);
  return best;
}

double TargetShapeProblem::distance_to_contour(const Vec2& q) const { return std::sqrt(nearest_squared(q, nullptr)); }

double TargetShapeProblem::imls(const Vec2& q, Vec2* grad) const {
  const double h2 = h_ * h_;
  double Phi = 0.0, N = 0.0;
  Vec2 dPhi = Vec2::Zero(), dN = Vec2::Zero();
  // The cell of q; a point far outside the grid (or not finite, as an optimiser's trial point can
  // be) maps to -2, so the loops below visit no cell (and no double is cast out of int's range).
  const auto cell_of = [](double t, int n) {
    const double f = std::floor(t);
    return f >= -2.0 && f <= static_cast<double>(n) + 1.0 ? static_cast<int>(f) : -2;
  };
  const int cx = cell_of((q.x() - grid_origin_.x()) / cell_, grid_nx_);
  const int cy = cell_of((q.y() - grid_origin_.y()) / cell_, grid_ny_);
  for (int iy = std::max(cy - 1, 0); iy <= std::min(cy + 1, grid_ny_ - 1); ++iy)
    for (int ix = std::max(cx - 1, 0); ix <= std::min(cx + 1, grid_nx_ - 1); ++ix) {
      const int cell = iy * grid_nx_ + ix;
      for (int it = grid_start_[cell]; it < grid_start_[cell + 1]; ++it) {
        const int k = grid_items_[it];
        const Vec2 d = q - target_[k];
        const double r2 = d.squaredNorm();
        if (r2 >= h2) continue;
        const double a = 1.0 - r2 / h2;
        const double a3 = a * a * a;
        const double phi = a3 * a;
        const double nd = normals_[k].dot(d);
        const double f = nd * nd;
        Phi += phi;
        N += phi * f;
        if (grad) {
          const Vec2 dphi = (-8.0 * a3 / h2) * d;
          dPhi += dphi;
          dN += f * dphi + (2.0 * phi * nd) * normals_[k];
        }
      }
    }
  if (Phi >= kernel_mass_full) {
    const double I = N / Phi;
    if (grad) *grad = (dN - I * dPhi) / Phi;
    return I;
  }
  // Blend into the squared distance to the nearest target point: D = s I + (1 - s) g, with the
  // C¹ smoothstep s(Φ/Φ0) that vanishes (with its derivative) where no kernel reaches q.
  Vec2 dg;
  const double g = nearest_squared(q, grad ? &dg : nullptr);
  if (Phi <= 0.0) {
    if (grad) *grad = dg;
    return g;
  }
  const double t = Phi / kernel_mass_full;
  const double s = t * t * (3.0 - 2.0 * t);
  const double ds = 6.0 * t * (1.0 - t) / kernel_mass_full;
  const double I = N / Phi;
  if (grad) {
    const Vec2 dI = (dN - I * dPhi) / Phi;
    *grad = ds * (I - g) * dPhi + s * dI + (1.0 - s) * dg;
  }
  return s * I + (1.0 - s) * g;
}

double TargetShapeProblem::distance_term(const Polyline2& p, int i, Polyline2* grad, ImlsSample* sample) const {
  const int m = static_cast<int>(p.size());
  Vec2 dD;
  const double D = imls(p[i], grad ? &dD : nullptr);
  if (grad && sample) *sample = {p[i], D, dD};
  // w_i = |p_i - p_{i-1}| + |p_{i+1} - p_i| (one term at an open end).
  double wi = 0.0;
  for (int side : {-1, 1}) {
    const int j = i + side;
    if (!closed_ && (j < 0 || j >= m)) continue;
    const int jj = (j + m) % m;
    const Vec2 e = p[i] - p[jj];
    const double len = e.norm();
    wi += len;
    if (grad && len > 0.0) {
      const Vec2 de = (D / len) * e;
      (*grad)[i] += de;
      (*grad)[jj] -= de;
    }
  }
  if (grad) (*grad)[i] += wi * dD;
  return wi * D;
}

double TargetShapeProblem::regularization_term(const Polyline2& p, int i, double weight, Polyline2* grad) const {
  const int m = static_cast<int>(p.size());
  if (!closed_ && (i == 0 || i == m - 1)) return 0.0;
  const int a = (i + m - 1) % m, b = (i + 1) % m;
  const Vec2 L = (p[i] - initial_[i]) - 0.5 * ((p[a] - initial_[a]) + (p[b] - initial_[b]));
  if (grad) {
    (*grad)[i] += (2.0 * weight) * L;
    (*grad)[a] -= weight * L;
    (*grad)[b] -= weight * L;
  }
  return weight * L.squaredNorm();
}

double TargetShapeProblem::distance_energy(const Polyline2& p, Polyline2* grad) const {
  if (grad) grad->resize(p.size(), Vec2::Zero());
  double E = 0.0;
  for (int i = 0; i < static_cast<int>(p.size()); ++i) E += distance_term(p, i, grad);
  return E;
}

double TargetShapeProblem::regularization_energy(const Polyline2& p, Polyline2* grad) const {
  if (grad) grad->resize(p.size(), Vec2::Zero());
  double E = 0.0;
  for (int i = 0; i < static_cast<int>(p.size()); ++i) E += regularization_term(p, i, 1.0, grad);
  return E;
}

double TargetShapeProblem::energy(const Polyline2& p, Polyline2* grad) const {
  if (grad) grad->resize(p.size(), Vec2::Zero());
  double E = 0.0;
  for (int i = 0; i < static_cast<int>(p.size()); ++i) {
    const double d = distance_term(p, i, grad);  // first: both add into grad, in this order
    E += d + regularization_term(p, i, options_.regularization, grad);
  }
  return E;
}

double TargetShapeProblem::energy_terms(const Polyline2& p, const std::vector<int>& terms, Polyline2* grad,
                                        std::vector<ImlsSample>* samples) const {
  double E = 0.0;
  if (grad && samples) samples->resize(terms.size());
  for (std::size_t k = 0; k < terms.size(); ++k) {
    const int i = terms[k];
    const double d = distance_term(p, i, grad, grad && samples ? &(*samples)[k] : nullptr);  // first, as in energy
    E += d + regularization_term(p, i, options_.regularization, grad);
  }
  return E;
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

// ---------------------------------------------------------------------------------------------
// The solve.

namespace {

// One block of the problem handed to NLopt: some free points as variables (the others held at
// their current positions), the energy terms they change and the constraints they touch.
struct Block {
  std::vector<int> points;       // variables, 2 per point
  std::vector<int> terms;        // energy terms depending on them
  std::vector<int> constraints;  // indices into TargetShapeProblem::constraints()
  bool around_crossing = false;  // a window centred on an active crossing
};

struct SolverData {
  const TargetShapeProblem* problem = nullptr;
  const Block* block = nullptr;
  std::vector<int> var_of;  // point -> first variable index in the current block, -1 otherwise
  double scale_x = 1.0;     // p = scale_x * x
  double scale_f = 1.0;     // f = E / scale_f
  Polyline2 p, grad, cgrad;
  // solve_block's buffers, kept across blocks: the block's variables, the points before it, its
  // start, its answer, and the points before it in the sweep.
  std::vector<double> block_x;
  Polyline2 before, start, after, sweep_before;
  const ProgressFn* progress = nullptr;
  int evaluations = 0;
  int max_evaluations = 1;
  bool cancelled = false;

  // TargetShapeAlgorithm::sqp where NLopt's SLSQP leads a block (slsqp_block stopped): one NLopt run
  // is both the lead-in and the fallback. Before its evaluation lead + 1, `take_over` gets the point
  // NLopt would have returned had it stopped after `lead` evaluations (the best point so far, by
  // SLSQP's own rule in NLopt's slsqp.c) and returns true when the SQP solved the block from there;
  // NLopt is then stopped. Otherwise NLopt goes on exactly as a second run from the block's start
  // would (SLSQP is deterministic), without repeating its first `lead` evaluations.
  struct LeadIn {
    int lead = 0;
    double tol = 0.0;  // the constraints' tolerance (NLopt's feasibility test)
    std::function<bool(const std::vector<double>&)> take_over;
    int evaluations = 0;  // this run's, so far
    bool fired = false, took_over = false;
    std::exception_ptr error;  // what take_over threw (NLopt's wrapper would turn it into a failure)
    std::vector<double> best_x;
    double best_f = std::numeric_limits<double>::infinity(), best_infeasibility = best_f;
    bool best_feasible = false;
    std::vector<double> last_x;  // the evaluation in progress, settled at the next one
    double last_f = 0.0, last_infeasibility = 0.0;
    bool last_feasible = true, pending = false;

    void settle() {  // slsqp.c: "update best point so far"
      if (pending && std::isfinite(last_f) &&
          ((last_f < best_f && (last_feasible || !best_feasible)) || (!best_feasible && last_infeasibility < best_infeasibility))) {
        best_f = last_f;
        best_feasible = last_feasible;
        best_infeasibility = last_infeasibility;
        best_x = last_x;
      }
      pending = false;
    }
    void begin(const double* x, std::size_t n) {
      settle();
      // No finite f in the lead-in (only where the points were not finite): no SQP, as before.
      if (!fired && evaluations == lead && !best_x.empty()) {
        fired = true;
        try {
          took_over = take_over(best_x);
        } catch (...) {  // e.g. Cancelled: stop NLopt, the caller throws it again
          error = std::current_exception();
          throw nlopt::forced_stop();
        }
        if (took_over) throw nlopt::forced_stop();
      }
      ++evaluations;
      last_x.assign(x, x + n);
      last_f = std::numeric_limits<double>::quiet_NaN();
      last_infeasibility = 0.0;
      last_feasible = pending = true;
    }
    void constraint(double c) {
      last_infeasibility = last_infeasibility >= c ? last_infeasibility : c;  // slsqp.c's MAX2, NaN included
      last_feasible = last_feasible && c <= tol;
    }
  };
  LeadIn* lead_in = nullptr;

  // Counts one evaluation and polls the progress callback at the first and then every
  // kProgressEvery; false when it asks to cancel.
  bool count_evaluation();

  void unpack(const double* x) {
    for (std::size_t k = 0; k < block->points.size(); ++k) p[block->points[k]] = scale_x * Vec2(x[2 * k], x[2 * k + 1]);
  }
};

using detail::constraint_points;

// The progress callback is polled at the first evaluation and then every this many: a Python
// callback takes the GIL, and polled at every evaluation (20-100 µs each) it serialised the wires
// that the pipeline solves on two threads. 16 evaluations are at most a few milliseconds.
constexpr int kProgressEvery = 16;

// TargetShapeAlgorithm::sqp: SLSQP evaluations that lead a block where the basin is chosen (10: with
// 5, one of 116 recorded corpus solves ended in another local minimum; with 10 and 20 none did).
// detail::slsqp_block replicates them with our own QP.
constexpr int kSqpBasinEvaluations = 10;
// The result text of a block the SQP solved (TargetShapeResult::nlopt_result).
const std::string kSqpConverged = "SQP_CONVERGED";

bool SolverData::count_evaluation() {
  ++evaluations;
  if (progress && *progress && (evaluations - 1) % kProgressEvery == 0) {
    try {
      report_progress(*progress, "target_shape", std::min(1.0, static_cast<double>(evaluations) / max_evaluations));
    } catch (const Cancelled&) {
      cancelled = true;
      return false;
    }
  }
  return true;
}

double objective(unsigned n, const double* x, double* g, void* data) {
  auto* d = static_cast<SolverData*>(data);
  if (d->lead_in) d->lead_in->begin(x, n);
  if (!d->count_evaluation()) throw nlopt::forced_stop();
  d->unpack(x);
  double f;
  if (!g) {
    f = d->problem->energy_terms(d->p, d->block->terms, nullptr) / d->scale_f;
  } else {
    std::fill(d->grad.begin(), d->grad.end(), Vec2::Zero());
    f = d->problem->energy_terms(d->p, d->block->terms, &d->grad) / d->scale_f;
    const double gs = d->scale_x / d->scale_f;
    for (std::size_t k = 0; k < d->block->points.size(); ++k) {
      g[2 * k] = gs * d->grad[d->block->points[k]].x();
      g[2 * k + 1] = gs * d->grad[d->block->points[k]].y();
    }
  }
  if (d->lead_in) d->lead_in->last_f = f;
  return f;
}

void constraints_fn(unsigned m, double* result, unsigned n, const double* x, double* g, void* data) {
  auto* d = static_cast<SolverData*>(data);
  d->unpack(x);
  const auto& all = d->problem->constraints();
  const int np = static_cast<int>(d->p.size());
  if (g) std::fill(g, g + static_cast<std::size_t>(m) * n, 0.0);
  for (unsigned k = 0; k < m; ++k) {
    const int ck = d->block->constraints[k];
    if (!g) {
      result[k] = d->problem->constraint(ck, d->p);
      if (d->lead_in) d->lead_in->constraint(result[k]);
      continue;
    }
    // A constraint touches at most three points: clear them, evaluate, scatter.
    const auto pts = constraint_points(all[ck], np);
    for (int q : pts)
      if (q >= 0) d->cgrad[q] = Vec2::Zero();
    result[k] = d->problem->constraint(ck, d->p, &d->cgrad);
    if (d->lead_in) d->lead_in->constraint(result[k]);
    double* row = g + static_cast<std::size_t>(k) * n;
    for (int q : pts) {
      if (q < 0 || d->var_of[q] < 0) continue;
      row[d->var_of[q]] = d->scale_x * d->cgrad[q].x();
      row[d->var_of[q] + 1] = d->scale_x * d->cgrad[q].y();
    }
  }
}

nlopt::algorithm nlopt_algorithm(TargetShapeAlgorithm a) {
  switch (a) {
    case TargetShapeAlgorithm::slsqp: return nlopt::LD_SLSQP;
    case TargetShapeAlgorithm::sqp: return nlopt::LD_SLSQP;  // its fallback
    case TargetShapeAlgorithm::auglag_lbfgs: return nlopt::AUGLAG;
    case TargetShapeAlgorithm::ccsaq: return nlopt::LD_CCSAQ;
    case TargetShapeAlgorithm::mma: return nlopt::LD_MMA;
  }
  return nlopt::LD_SLSQP;
}

// Builds the block of the points in `range` (free ones only).
Block make_block(const TargetShapeProblem& problem, const std::vector<int>& range) {
  const int m = static_cast<int>(problem.initial().size());
  const bool closed = problem.closed();
  Block b;
  std::vector<char> in(m, 0), term(m, 0);
  for (int i : range)
    if (!problem.fixed()[i]) {
      b.points.push_back(i);
      in[i] = 1;
      for (int s : {-1, 0, 1}) {
        const int j = i + s;
        if (!closed && (j < 0 || j >= m)) continue;
        term[(j + m) % m] = 1;
      }
    }
  for (int i = 0; i < m; ++i)
    if (term[i]) b.terms.push_back(i);
  const auto& cons = problem.constraints();
  for (std::size_t k = 0; k < cons.size(); ++k)
    for (int q : constraint_points(cons[k], m))
      if (q >= 0 && in[q]) {
        b.constraints.push_back(static_cast<int>(k));
        break;
      }
  return b;
}

}  // namespace

TargetShapeResult optimize_target_shape(const Polyline2& contour, bool closed,
                                        const std::vector<TargetCrossing>& crossings,
                                        const TargetShapeOptions& options, const ProgressFn& progress) {
  detail::TargetShapeRun run = detail::run_target_shape(contour, closed, crossings, options, progress);
  while (run.step()) {
  }
  return run.take();
}

// clang 14 cannot assemble a coroutine instrumented by -fsanitize=function together with
// sanitizer coverage (the fuzz build's -fsanitize=undefined,fuzzer-no-link: "Cannot represent a
// difference across sections"), so that one check, of calls through mistyped function pointers,
// is left out of this function; every other sanitizer still instruments it.
#if defined(__clang__)
#define WIRESCULPT_NO_FUNCTION_SANITIZER __attribute__((no_sanitize("function")))
#else
#define WIRESCULPT_NO_FUNCTION_SANITIZER
#endif

WIRESCULPT_NO_FUNCTION_SANITIZER
detail::TargetShapeRun detail::run_target_shape(const Polyline2& contour, bool closed,
                                                const std::vector<TargetCrossing>& crossings,
                                                const TargetShapeOptions& options, ProgressFn progress) {
  const auto t0 = std::chrono::steady_clock::now();
  // Time spent paused between pieces (TargetShapeRun): another wire's, not this one's.
  std::chrono::steady_clock::duration paused{};
  auto elapsed = [&] { return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0 - paused).count(); };
  report_progress(progress, "target_shape", 0.0);
  const TargetShapeProblem problem(contour, closed, crossings, options);
  const TargetShapeOptions& o = problem.options_;
  const std::string& w = o.wire_name;
  TargetShapeResult result;
  Polyline2 p = problem.initial();
  const int m = static_cast<int>(p.size());
  const bool warm = !o.start.empty();
  if (warm) {  // a previous result of this problem: its free points (the crossings stay the contour's)
    if (o.start.size() != p.size())
      throw InputError("target shape of wire " + w + ": start has " + std::to_string(o.start.size()) +
                       " points, but this contour with these crossings and spacing has " + std::to_string(m));
    for (int i = 0; i < m; ++i) {
      if (!o.start[i].allFinite())
        throw InputError("target shape of wire " + w + ": start point " + std::to_string(i) + " is not finite");
      if (!problem.fixed()[i]) p[i] = o.start[i];
    }
  }

  // Start (cold): each free neighbour of an active crossing that lies outside the contact cone is turned
  // about the crossing point onto the cone (keeping its distance and its side of h*), so that
  // the kinks start open the right way. The regulariser still measures from initial().
  for (std::size_t c = 0; c < crossings.size() && !warm; ++c) {
    const TargetCrossingStatus& s = problem.statuses_[c];
    if (!problem.crossings_[c].active || !s.realised) continue;
    const Vec2 h = problem.crossings_[c].bisector;
    const double cone = problem.beta_[c] * (1.0 - 1e-3);
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

  // The blocks: one for the whole wire (window 0 or at most 4 × window points), or overlapping
  // windows of `window` points every window/2 points (every constraint, spanning at most three
  // consecutive points, lies inside one window), solved in turn until no window moves (see
  // docs/method-target-shape.md).
  std::vector<Block> blocks;
  const int window = o.window;
  const long long one_block = o.one_block_points < 0 ? 4LL * window : o.one_block_points;
  if (window <= 0 || static_cast<long long>(m) <= one_block) {  // small wires: one block is as cheap
    std::vector<int> all(m);
    for (int i = 0; i < m; ++i) all[i] = i;
    blocks.push_back(make_block(problem, all));
  } else {
    // First a window of `window` points centred on each active crossing (both sides of the kink
    // move together), then the uniform tiling.
    for (std::size_t c = 0; c < crossings.size(); ++c) {
      const TargetCrossingStatus& s = problem.statuses_[c];
      if (!problem.crossings_[c].active || !s.realised) continue;
      std::vector<int> range;
      const int half = window / 2;
      for (int j = -half; j < half; ++j) {
        const int q = s.vertex + j;
        if (closed || (q >= 0 && q < m)) range.push_back((q + m) % m);
      }
      blocks.push_back(make_block(problem, range));
      blocks.back().around_crossing = true;
    }
    const int stride = window / 2;
    const int count = closed ? (m + stride - 1) / stride : std::max(1, (m - window + stride - 1) / stride + 1);
    for (int k = 0; k < count; ++k) {
      std::vector<int> range;
      const int start = closed ? k * stride : std::min(k * stride, m - window);
      for (int j = 0; j < window; ++j) range.push_back(closed ? (start + j) % m : start + j);
      blocks.push_back(make_block(problem, range));
    }
  }
  std::erase_if(blocks, [](const Block& b) { return b.points.empty(); });

  SolverData data;
  data.problem = &problem;
  data.var_of.assign(m, -1);
  data.scale_x = o.min_segment;
  // E_d ≈ Σ 2·spacing·d_i²: this scale makes the energy's curvature across the contour O(1)
  // per point in the scaled variables, which is where SLSQP's initial Hessian guess is I.
  data.scale_f = 2.0 * o.spacing * o.min_segment * o.min_segment;
  data.p = p;
  data.grad.assign(m, Vec2::Zero());
  data.cgrad.assign(m, Vec2::Zero());
  data.progress = &progress;
  data.max_evaluations = o.max_iterations;
  result.nlopt_result = "none";
  std::string worst_result;
  auto out_of_time = [&] {
    return elapsed() >= o.max_seconds;
  };
  bool choose_basin = false;  // sqp: SLSQP leads the block's first evaluations (see below)
  std::array<int, 2> shift_guess{0, 0};  // sqp: shared by the blocks (SqpSettings::shift_guess)
  detail::SqpWorkspace workspace;         // sqp: the blocks' buffers (SqpSettings::workspace)
  auto solve_block = [&](const Block& b) {
    const unsigned nvar = static_cast<unsigned>(2 * b.points.size());
    data.block = &b;
    for (std::size_t k = 0; k < b.points.size(); ++k) data.var_of[b.points[k]] = static_cast<int>(2 * k);
    // NLopt for this block, set up where it first runs, inside run_nlopt (the SQP solves most blocks
    // without it), with what is left then of the call's evaluation and wall-clock budgets
    // (max_seconds is shared by every block).
    std::optional<nlopt::opt> nlopt_opt;
    auto opt = [&]() -> nlopt::opt& {
      if (nlopt_opt) return *nlopt_opt;
      nlopt::opt& op = nlopt_opt.emplace(nlopt_algorithm(o.algorithm), nvar);
      if (o.algorithm == TargetShapeAlgorithm::auglag_lbfgs) {
        nlopt::opt local(nlopt::LD_LBFGS, nvar);
        local.set_ftol_rel(o.ftol_rel);
        local.set_xtol_rel(o.xtol_rel);
        local.set_maxeval(o.max_iterations);
        local.set_maxtime(o.max_seconds);
        op.set_local_optimizer(local);
      }
      op.set_min_objective(objective, &data);
      if (!b.constraints.empty())
        op.add_inequality_mconstraint(constraints_fn, &data, std::vector<double>(b.constraints.size(), o.constraint_tol));
      op.set_ftol_rel(o.ftol_rel);
      op.set_xtol_rel(o.xtol_rel);
      op.set_maxeval(std::max(1, o.max_iterations - data.evaluations));
      op.set_maxtime(std::max(1e-3, o.max_seconds - elapsed()));
      return op;
    };
    std::vector<double>& x = data.block_x;  // the buffers below are the run's, kept across blocks
    x.assign(nvar, 0.0);
    for (std::size_t k = 0; k < b.points.size(); ++k) {
      x[2 * k] = data.p[b.points[k]].x() / data.scale_x;
      x[2 * k + 1] = data.p[b.points[k]].y() / data.scale_x;
    }
    Polyline2& before = data.before;
    before = data.p;
    double f = 0.0;
    nlopt::result r = nlopt::FAILURE;
    // TargetShapeAlgorithm::sqp: the block by Newton SQP. Where the basin is chosen (a one-block
    // wire, or a window centred on a crossing in the first sweep, where the kinks open) SLSQP's
    // first kSqpBasinEvaluations evaluations lead the way and SQP finishes from where they got:
    // started cold there, Newton's long steps along the wire (where the energy is flat) reach other
    // local minima (docs/method-target-shape.md, issue 17 fifth round). Those evaluations are
    // SLSQP's steps replicated with our QP (detail::slsqp_block, a fraction of the cost of NLopt's
    // dense least-squares subproblem), or NLopt's own where the replica stops. Where SQP fails (the
    // linearised constraints are inconsistent, or its line search stalls) SLSQP solves the block
    // from the block's start, as with algorithm slsqp; where NLopt led, that is its lead-in's own
    // run going on (SolverData::LeadIn), so its first evaluations are not repeated.
    bool by_sqp = false, nlopt_ran = false;
    // NLopt from x (updated in place), its stops as result codes; a rejected problem is the solver's error.
    auto run_nlopt = [&]() -> nlopt::result {
      try {
        return opt().optimize(x, f);
      } catch (const nlopt::roundoff_limited&) {
        return nlopt::ROUNDOFF_LIMITED;
      } catch (const nlopt::forced_stop&) {
        return nlopt::FORCED_STOP;
      } catch (const std::invalid_argument& e) {
        throw SolverError("target shape of wire " + w + ": NLopt rejected the problem (" + e.what() + ")");
      } catch (const std::bad_alloc&) {
        throw;
      } catch (const std::runtime_error&) {
        return nlopt::FAILURE;
      }
    };
    if (o.algorithm == TargetShapeAlgorithm::sqp) {
      detail::SqpSettings ss;
      ss.scale_x = data.scale_x;
      ss.scale_f = data.scale_f;
      ss.min_segment = o.min_segment;
      ss.regularization = o.regularization;
      ss.constraint_tol = o.constraint_tol;
      ss.ftol_rel = o.ftol_rel;
      ss.shift_guess = &shift_guess;
      ss.workspace = &workspace;
      ss.on_evaluation = [&] {
        if (!data.count_evaluation()) throw Cancelled();
      };
      const detail::SqpBlock sb{&b.points, &b.terms, &b.constraints};
      Polyline2& start = data.start;
      start = data.p;
      const int lead = std::max(1, std::min(kSqpBasinEvaluations, o.max_iterations - data.evaluations));
      // SLSQP's first steps, replicated with our QP (slsqp_block); NLopt's own SLSQP where the
      // replica stops (inconsistent linearised constraints, a value not finite).
      if (choose_basin && detail::slsqp_block(problem, sb, start, ss, lead, o.xtol_rel, out_of_time).done)
        choose_basin = false;
      auto finish_by_sqp = [&] {
        for (std::size_t k = 0; k < b.points.size(); ++k) {
          x[2 * k] = start[b.points[k]].x() / data.scale_x;
          x[2 * k + 1] = start[b.points[k]].y() / data.scale_x;
        }
        r = nlopt::SUCCESS;
        by_sqp = true;
      };
      // SQP from the point the lead-in reached (none when it is not finite); true when it converged.
      auto sqp_from = [&](const std::vector<double>& xp) {
        for (double v : xp)
          if (!std::isfinite(v)) return false;
        for (std::size_t k = 0; k < b.points.size(); ++k) start[b.points[k]] = data.scale_x * Vec2(xp[2 * k], xp[2 * k + 1]);
        return detail::sqp_block(problem, sb, start, ss).converged;
      };
      if (choose_basin) {
        // NLopt's SLSQP leads: its run goes on as the fallback where the SQP fails (SolverData::LeadIn).
        SolverData::LeadIn lead_in;
        lead_in.lead = std::max(1, std::min(lead, o.max_iterations - data.evaluations));
        lead_in.tol = o.constraint_tol;
        lead_in.take_over = sqp_from;
        {
          struct Attached {  // the callbacks see the lead-in only during this run
            SolverData& d;
            ~Attached() { d.lead_in = nullptr; }
          } attached{data};
          data.lead_in = &lead_in;
          r = run_nlopt();
        }
        if (lead_in.error) std::rethrow_exception(lead_in.error);
        if (data.cancelled) throw Cancelled();
        nlopt_ran = true;
        if (lead_in.took_over) {
          finish_by_sqp();
        } else if (!lead_in.fired && sqp_from(x)) {  // NLopt stopped within the lead-in: SQP from its point
          finish_by_sqp();
        }
      } else if (detail::sqp_block(problem, sb, start, ss).converged) {  // from the replica's point or the block's start
        finish_by_sqp();
      }
      // The fallback gets what is left of the call's budgets after the lead-in and the SQP (NLopt
      // is set up when it runs; where NLopt led, its run was the fallback: its budget was what was
      // left before its lead-in, after the replica).
      ++result.sqp_blocks;
      if (!by_sqp) ++result.sqp_fallbacks;
    }
    if (!by_sqp && !nlopt_ran) r = run_nlopt();
    if (data.cancelled) throw Cancelled();
    bool finite = true;
    for (double v : x) finite = finite && std::isfinite(v);
    // Keep the block's answer only if it is no worse than where it started (SLSQP can stop with
    // NLOPT_FAILURE at a poor point, e.g. when its line search fails): less violation, or as
    // feasible and no more energy.
    auto merit = [&](const Polyline2& q) {
      double viol = 0.0;
      for (int k : b.constraints) viol = std::max(viol, problem.constraint(k, q));
      return std::make_pair(viol, problem.energy_terms(q, b.terms));
    };
    data.p = before;
    bool moved_at_all = false;
    if (finite) {
      Polyline2& after = data.after;
      after = before;
      for (std::size_t k = 0; k < b.points.size(); ++k) {
        const int q = b.points[k];
        after[q] = data.scale_x * Vec2(x[2 * k], x[2 * k + 1]);
        // bit for bit (-0.0 is not 0.0 here): else the test below decides which of the two is kept
        moved_at_all = moved_at_all || std::memcmp(after[q].data(), before[q].data(), sizeof(Vec2)) != 0;
      }
    }
    // A block that ends where it started, to the bit (about half the windows of a converging
    // sweep), keeps `before` whichever way the test goes: its two merits would be equal.
    if (moved_at_all) {
      const Polyline2& after = data.after;
      const auto [viol0, e0] = merit(before);
      const auto [viol1, e1] = merit(after);
      const double tol = o.constraint_tol;
      const bool feasible_and_lower = viol1 <= tol && (viol0 > tol || e1 <= e0 + 1e-14 * std::abs(e0));
      const bool less_infeasible = r > 0 && viol0 > tol && viol1 < viol0;
      const bool better = feasible_and_lower || less_infeasible;
      if (better) data.p = after;
    }
    double moved = 0.0;
    for (int q : b.points) moved = std::max(moved, (data.p[q] - before[q]).norm());
    for (int q : b.points) data.var_of[q] = -1;
    // Keep the first non-success code (a failure in any block is the one worth reporting).
    const std::string text = by_sqp ? kSqpConverged : detail::nlopt_result_text(r);
    if (r < 0 && worst_result.empty()) worst_result = text;
    result.nlopt_result = worst_result.empty() ? text : worst_result;
    if (!finite) result.warnings.push_back("the solver diverged on part of wire " + w + "; that part keeps its previous shape");
    return moved;
  };

  if (blocks.size() == 1) {
    choose_basin = true;
    solve_block(blocks[0]);
    result.sweeps = 1;
  } else if (!blocks.empty()) {
    // Multiplicative Schwarz sweeps: a window is solved again only when a point it depends on
    // moved by more than move_tol since it was last solved.
    const double move_tol = o.sweep_tol;
    std::vector<char> dirty(blocks.size(), 1);
    double last_energy = std::numeric_limits<double>::infinity();  // E after the previous sweep
    double last_violation = std::numeric_limits<double>::infinity();  // and its largest violation
    std::vector<std::vector<int>> watchers(m);  // point -> blocks whose terms read it
    for (std::size_t k = 0; k < blocks.size(); ++k)
      for (int t : blocks[k].terms)
        for (int s : {-1, 0, 1}) {
          const int j = t + s;
          if (!closed && (j < 0 || j >= m)) continue;
          auto& wv = watchers[(j + m) % m];
          if (wv.empty() || wv.back() != static_cast<int>(k)) wv.push_back(static_cast<int>(k));
        }
    for (int sweep = 0; sweep < o.max_sweeps && !out_of_time(); ++sweep) {
      bool any = false;
      for (std::size_t k = 0; k < blocks.size() && !out_of_time(); ++k) {
        if (!dirty[k]) continue;
        any = true;
        dirty[k] = 0;
        Polyline2& before = data.sweep_before;
        before = data.p;
        choose_basin = sweep == 0 && blocks[k].around_crossing;
        solve_block(blocks[k]);
        for (int q : blocks[k].points)
          if ((data.p[q] - before[q]).norm() > move_tol)
            for (int other : watchers[q])
              if (other != static_cast<int>(k)) dirty[other] = 1;
        if (data.evaluations >= o.max_iterations) break;
        const auto pause = std::chrono::steady_clock::now();
        co_yield 0;  // a window solved: another thread may run the next one (TargetShapeRun)
        paused += std::chrono::steady_clock::now() - pause;
      }
      if (!any) break;
      result.sweeps = sweep + 1;
      if (data.evaluations >= o.max_iterations) {
        result.nlopt_result = "NLOPT_MAXEVAL_REACHED";
        break;
      }
      // Stop once a whole sweep lowered the wire's energy by no more than sweep_ftol of it, with
      // every constraint met or with its largest violation not lowered by more than that fraction
      // either: what is left is creep along the wire (see sweep_ftol).
      if (o.sweep_ftol > 0.0) {
        const double energy = problem.energy(data.p);
        double violation = 0.0;
        for (std::size_t k = 0; k < problem.constraints().size(); ++k)
          violation = std::max(violation, problem.constraint(k, data.p));
        const bool small = last_energy - energy <= o.sweep_ftol * std::abs(energy);
        // An infeasible wire whose sweep lowered neither its energy nor its largest violation is
        // stuck there: the kink it cannot open stays as far from its cone.
        const bool stuck = violation >= (1.0 - o.sweep_ftol) * last_violation;
        last_energy = energy;
        last_violation = violation;
        if (small && (violation <= o.constraint_tol || stuck)) break;
      }
    }
  }
  if (out_of_time()) {
    result.nlopt_result = "NLOPT_MAXTIME_REACHED";
    result.warnings.push_back("wire " + w + ": the target shape stopped at its time budget of " + fmt(o.max_seconds, 4) +
                              " s (max_seconds) before it converged");
  }
  result.iterations = data.evaluations;
  p = data.p;

  // Measure the result.
  result.points = p;
  result.crossing_vertices = problem.crossing_vertices();
  result.crossings = problem.statuses();
  result.energy = problem.energy(p);
  const double friction_angle = std::atan(o.friction);
  double sum2 = 0.0;
  for (const Vec2& q : p) {
    const double d = problem.distance_to_contour(q);
    result.max_distance = std::max(result.max_distance, d);
    sum2 += d * d;
  }
  result.rms_distance = std::sqrt(sum2 / std::max(m, 1));
  const int edges = closed ? m : m - 1;
  result.min_segment = std::numeric_limits<double>::infinity();
  std::vector<int> short_edges, sharp_bends;
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
      detail::set_cause(s, static_cast<int>(c), w, CrossingCause::cone_missed, f);
    }
  }
  // A kink whose neighbours break a machine limit is not made either: the solver met the contact
  // constraints at the expense of a bend or segment next to the crossing (the kink, l_min and the
  // bend limit conflict there). Blaming the crossing lets the caller null it (or choose the other
  // hook) instead of passing on a wire the bender cannot make.
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
      detail::set_cause(s, static_cast<int>(c), w,
                        bend > 0.0 ? CrossingCause::neighbour_bend : CrossingCause::neighbour_segment, f);
      break;
    }
  }
  auto list = [](const std::vector<int>& v) {
    std::string s;
    for (std::size_t k = 0; k < v.size() && k < 8; ++k) s += (k ? ", " : "") + std::to_string(v[k]);
    if (v.size() > 8) s += ", ...";
    return s;
  };
  if (!short_edges.empty())
    result.warnings.push_back("wire " + w + ": segments starting at points " + list(short_edges) + " are shorter than " +
                              mm(o.min_segment) + " (by up to " + mm(result.max_length_violation) + ")");
  if (!sharp_bends.empty())
    result.warnings.push_back("wire " + w + ": bends at points " + list(sharp_bends) + " exceed " + deg(o.max_bend) + (o.vertex_max_bend.empty() ? "" : " or their own limits (vertex_max_bend)"));
  result.feasible = result.feasible && short_edges.empty() && sharp_bends.empty();
  result.seconds = elapsed();
  report_progress(progress, "target_shape", 1.0);
  co_return result;
}

}  // namespace wiresculpt
