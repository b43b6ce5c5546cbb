#pragma once
// Per-wire target-shape optimisation (Sec. 4.3 of Miguel, Lepoutre, Bickel 2016, Eq. 3-5): turn a
// wire's dense sliced contour into a fabricable polyline that stays close to it, keeps every
// crossing point fixed, respects the bending machine (segments >= l_min, bends <= max) and opens
// each active crossing's kink towards the bisector the layering chose (contact constraints).
// The method, its choices and the measurements behind them are in docs/method-target-shape.md.
// The input (crossings, options) is in target_shape_options.hpp, many wires at once in
// target_shape_batch.hpp; this header gives both.
//
// Everything is in the wire's own 2D plane frame (Plane::to_2d), metres and radians.
//
//   minimise    E(p) = E_d(p) + w_r E_r(p)
//   subject to  |p_{i+1} - p_i| >= l_min                      every segment with a free end
//               bend(p_i) <= max_bend                          every vertex with a free neighbour
//               angle(p_{r±1} - p_r, h*) + atan(μ) <= α*/2     both edges of every active crossing r
//               p_r = contour point of crossing r              (crossings are not variables)
//
// E_d is the IMLS distance of Eq. 4 (point-to-tangent-line distances of the target points,
// blended with a compact kernel of support h = 2 × the average target sampling distance, each
// optimised point weighted by the length of its incident segments). Where a point has too little
// kernel mass (no target point within h, typically a neighbour of a kink moved off the contour)
// E_d blends smoothly into the squared distance to the nearest point of the target polyline, so
// the energy is defined everywhere and continuously differentiable except on the medial axis of
// the target (where it stays continuous). E_r is Eq. 5 read as a sum of squared norms:
// Σ_i |u_i - (u_{i-1} + u_{i+1})/2|² over the interior vertices, u = p - p_initial.
#include <coroutine>
#include <exception>
#include <memory>
#include <numbers>
#include <optional>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "wiresculpt/geometry.hpp"
#include "wiresculpt/progress.hpp"
#include "wiresculpt/target_shape_options.hpp"

namespace wiresculpt {

/// Why a crossing is not realised (TargetCrossingStatus::cause), with the status each gives.
enum class CrossingCause {
  none,                 ///< realised, or inactive ("ok", "inactive")
  open_end,             ///< "open_end": an active crossing at an end of an open wire, with no kink
  contact_vs_friction,  ///< "infeasible": the contact angle is not wider than twice atan(μ)
  min_bend,             ///< "infeasible": the least bend the kink needs is over max_bend
  short_piece,          ///< "too_close": the straight piece to the next crossing is under min_segment
  fixed_edge,           ///< "too_close": the fixed piece to the next crossing lies outside the cone
  cone_missed,          ///< "infeasible": after the solve, an edge of the kink outside the cone
  neighbour_bend,       ///< "infeasible": after the solve, the free point next to it bends too much
  neighbour_segment,    ///< "infeasible": after the solve, the segment next to it is too short
};

/// The snake_case name of a cause, as the binding hands it over: "short_piece".
const char* cause_name(CrossingCause cause);

/// The figures a cause's sentence gives (each 0 / -1 where the cause has none).
struct CrossingFigures {
  double contact_angle = 0.0;   ///< radians: α* asked (contact_vs_friction, min_bend)
  double friction_angle = 0.0;  ///< radians: atan μ (contact_vs_friction, min_bend)
  /// Radians: min_bend: the least bend the kink needs, π - α* + 2 atan μ; neighbour_bend: the
  /// bend found at `point`.
  double bend = 0.0;
  /// The limit broken: min_bend: max_bend, neighbour_bend: the bend limit at `point` (radians);
  /// neighbour_segment, short_piece, fixed_edge: min_segment (metres).
  double limit = 0.0;
  /// Metres: neighbour_segment: the segment found; short_piece, fixed_edge: the arc between the
  /// two crossings.
  double length = 0.0;
  double violation = 0.0;   ///< radians: cone_missed: how far the worse edge is outside the cone
  double scale = 1.0;       ///< too_close: as TargetCrossingStatus::scale
  double model_size = 0.0;  ///< too_close: the model's size (metres; 0: not known)
  int first = -1, second = -1;  ///< too_close: the two crossings, in the wire's order
  int point = -1;               ///< neighbour_bend, neighbour_segment: the point next to the kink
};

/// What happened to one input crossing.
struct TargetCrossingStatus {
  /// "ok" (realised), "inactive" (null hook, point kept), "too_close" (no free point towards a
  /// neighbouring crossing and the fixed edge cannot satisfy the constraints), "infeasible" (the
  /// constraints cannot hold: contact angle vs friction or max bend, or the solver could not meet
  /// them, at the kink or at a free point next to it: a bend over its limit or a segment under
  /// min_segment there, named in the message), "open_end" (an active crossing at an end of an
  /// open wire has no kink).
  std::string status = "ok";
  bool realised = true;   ///< false: the caller should make it null and re-check stability
  int vertex = -1;        ///< index of the crossing in TargetShapeResult::points
  /// Achieved unit bisector (ê_r - ê_{r-1})/|…| and opening angle (radians, π straight) at the
  /// crossing; bisector is zero at an open end or where the wire is straight.
  Vec2 bisector = Vec2::Zero();
  double contact_angle = 0.0;
  /// Radians: max over both edges of angle(edge, h*) + atan(μ) - α*/2 (<= 0 when satisfied);
  /// 0 for inactive crossings.
  double contact_violation = 0.0;
  /// For "too_close": the factor (>= 1) by which the model must grow so that the closer
  /// neighbouring crossing is 2 × min_segment away along the wire (room for one free point);
  /// 1 otherwise.
  double scale = 1.0;
  std::string message;  ///< a sentence naming the wire and crossing; empty when "ok"/"inactive"
  CrossingCause cause = CrossingCause::none;  ///< why it is not realised (none when it is)
  CrossingFigures figures;                    ///< the figures `message` gives
  /// What follows the crossing's name in "crossing N on wire W: " for a caller that names it its
  /// own way ("it needs a bend of at least …"); `message` itself when that does not start with
  /// the crossing's name (too_close, about two crossings); empty when "ok"/"inactive".
  std::string words;
};

struct TargetShapeResult {
  Polyline2 points;                 ///< #m optimised points (closed: first not repeated), metres
  std::vector<int> crossing_vertices;  ///< per input crossing, its index into `points`
  std::vector<TargetCrossingStatus> crossings;  ///< per input crossing
  double max_distance = 0.0;  ///< metres: largest distance of a point to the input contour
  double rms_distance = 0.0;  ///< metres: RMS of those distances
  double min_segment = 0.0;   ///< metres: shortest segment of `points`
  double max_bend = 0.0;      ///< radians: largest bend of `points`
  /// Metres: max(0, l_min - |e|) over all segments. Radians: the largest excess of a bend over
  /// max_bend or of a contact constraint (angle(edge, h*) + atan μ - α*/2) of an active crossing
  /// that was not reported unrealisable before solving.
  double max_length_violation = 0.0;
  double max_angle_violation = 0.0;
  int iterations = 0;         ///< energy evaluations (NLopt's and the SQP's), all blocks together
  int sweeps = 0;             ///< passes over the windows (1 for a single block)
  int sqp_blocks = 0;         ///< block solves by TargetShapeAlgorithm::sqp
  int sqp_fallbacks = 0;      ///< of them, solved by SLSQP instead (the SQP did not converge)
  double seconds = 0.0;       ///< wall-clock time of the whole call (less a run's pauses: detail::TargetShapeRun)
  /// NLopt's result as text, e.g. "NLOPT_FTOL_REACHED" ("SQP_CONVERGED" for a block the SQP
  /// solved): the first failure code of any block, else
  /// the last block's code; "NLOPT_MAXEVAL_REACHED" when max_iterations ran out across windows;
  /// "none" when nothing was free.
  std::string nlopt_result;
  double energy = 0.0;        ///< E at the result (m³)
  /// Every segment, bend and solved contact constraint within its tolerance (segments between
  /// too-close crossings count; contact constraints dropped before solving do not).
  bool feasible = true;
  std::vector<std::string> warnings;  ///< sentences about violated constraints, naming vertices
  /// For a TargetShapeJob with a `plane` (optimize_target_shapes): `points` in space, metres
  /// (plane.origin + x u + y v), and their polyline's length (closed: back to the first), summed
  /// in numpy's order (detail::place_target); else empty and 0.
  Polyline3 target;
  double length = 0.0;
};

/// Optimises one wire.
///   contour   #n 2D points in the wire's plane frame, metres (n >= 2 open, n >= 3 closed)
///   closed    true: the last point connects back to the first (not repeated)
///   crossings as above; vertices distinct and in [0, n)
/// Throws InputError (non-finite input, bad index, duplicate crossing, zero bisector of an active
/// crossing, bad option) naming the wire and crossing; Cancelled when `progress` asks to stop.
/// Unrealisable crossings are not errors: they are reported in the result.
TargetShapeResult optimize_target_shape(const Polyline2& contour, bool closed,
                                        const std::vector<TargetCrossing>& crossings,
                                        const TargetShapeOptions& options = {},
                                        const ProgressFn& progress = {});

namespace detail {
/// The number of points of the initial resampling that TargetShapeProblem makes of this wire (its
/// target points, fixed crossing vertices included), without building the problem; -1 where it
/// cannot count (crossings off the contour, too few points, no length: the problem would say
/// why). optimize_target_shapes guesses from it which wires are solved as one block and what each
/// costs, to start the dearest first.
int initial_point_count(const Polyline2& contour, bool closed, const std::vector<TargetCrossing>& crossings,
                        const TargetShapeOptions& options);

/// optimize_target_shape run a piece at a time: each step() solves up to the end of the next
/// window of a windowed wire's sweeps (the set-up and a one-block wire are one piece), so that
/// optimize_target_shapes can hand a wire from one thread to the other between its windows. The
/// arithmetic is optimize_target_shape's, whatever runs which piece: the result is the same.
/// The contour, crossings and options are referred to, not copied: they must outlive the run
/// (`progress` is copied). A run's pauses do not count against max_seconds, nor in its result's
/// seconds; a run that reaches max_seconds stops where its own clock says, as optimize_target_shape.
class TargetShapeRun {
 public:
  struct promise_type {
    std::optional<TargetShapeResult> result;
    std::exception_ptr error;
    TargetShapeRun get_return_object() {
      return TargetShapeRun(std::coroutine_handle<promise_type>::from_promise(*this));
    }
    std::suspend_always initial_suspend() noexcept { return {}; }
    std::suspend_always final_suspend() noexcept { return {}; }
    std::suspend_always yield_value(int) noexcept { return {}; }
    void return_value(TargetShapeResult r) { result.emplace(std::move(r)); }
    void unhandled_exception() noexcept { error = std::current_exception(); }
  };
  TargetShapeRun(TargetShapeRun&& other) noexcept : handle_(std::exchange(other.handle_, {})) {}
  TargetShapeRun& operator=(TargetShapeRun&& other) noexcept {
    if (this != &other) {
      if (handle_) handle_.destroy();
      handle_ = std::exchange(other.handle_, {});
    }
    return *this;
  }
  TargetShapeRun(const TargetShapeRun&) = delete;
  TargetShapeRun& operator=(const TargetShapeRun&) = delete;
  ~TargetShapeRun() {
    if (handle_) handle_.destroy();
  }
  /// Runs the next piece; false once the run has ended (with its result or its exception).
  bool step() {
    if (!handle_ || handle_.done()) return false;
    handle_.resume();
    return !handle_.done();
  }
  /// The result of an ended run, once; rethrows what it threw (InputError, Cancelled, ...).
  /// std::logic_error for a run not ended, moved from or already taken.
  TargetShapeResult take() {
    if (!handle_ || !handle_.done()) throw std::logic_error("target shape: the run has not ended");
    promise_type& p = handle_.promise();
    if (p.error) std::rethrow_exception(p.error);
    if (!p.result) throw std::logic_error("target shape: the run's result was already taken");
    TargetShapeResult r = std::move(*p.result);
    p.result.reset();
    return r;
  }

 private:
  explicit TargetShapeRun(std::coroutine_handle<promise_type> h) : handle_(h) {}
  std::coroutine_handle<promise_type> handle_;
};

TargetShapeRun run_target_shape(const Polyline2& contour, bool closed, const std::vector<TargetCrossing>& crossings,
                                const TargetShapeOptions& options, ProgressFn progress);

}  // namespace detail


/// The optimisation problem of one wire, exposed for tests and diagnostics: the initial
/// resampled polyline and every term with its analytic gradient with respect to ALL points
/// (fixed ones included). optimize_target_shape builds one of these.
class TargetShapeProblem {
 public:
  TargetShapeProblem(const Polyline2& contour, bool closed, const std::vector<TargetCrossing>& crossings,
                     const TargetShapeOptions& options = {});

  enum class Kind { length, bend, contact };
  /// One inequality constraint in solver form, c(p) <= 0 (dimensionless):
  ///   length  at edge i (p_i -> p_{i+1}):   1 - |e_i|² / l_min²
  ///   bend    at vertex i:                   cos(max_bend) - ê_{i-1}·ê_i
  ///   contact at crossing vertex r, side ±:  cos(α*/2 - atan μ) - û·h*, u = p_{r±1} - p_r
  struct Constraint {
    Kind kind = Kind::length;
    int vertex = -1;    ///< edge start (length), vertex (bend), crossing vertex (contact)
    int neighbour = -1; ///< contact: the incident vertex r±1
    int crossing = -1;  ///< contact: index into the input crossings
  };

  const Polyline2& initial() const { return initial_; }
  bool closed() const { return closed_; }
  const std::vector<char>& fixed() const { return fixed_; }  ///< per point: a crossing
  const std::vector<int>& crossing_vertices() const { return crossing_vertices_; }
  /// Constraints that depend on at least one free point (the solver's constraints).
  const std::vector<Constraint>& constraints() const { return constraints_; }
  const std::vector<TargetCrossingStatus>& statuses() const { return statuses_; }
  /// The options as solved: spacing 0 replaced by its default.
  const TargetShapeOptions& options() const { return options_; }
  /// The crossings as solved: an active crossing's bisector normalised.
  const std::vector<TargetCrossing>& crossings() const { return crossings_; }
  /// Radians: crossing c's contact cone half-angle α*/2 - atan μ (0 for an inactive crossing).
  double beta(std::size_t c) const { return beta_[c]; }
  double kernel_support() const { return h_; }  ///< metres, h of Eq. 4

  /// E_d of Eq. 4 (m³); adds dE_d/dp to `grad` when non-null (resized to #points).
  double distance_energy(const Polyline2& p, Polyline2* grad = nullptr) const;
  /// E_r of Eq. 5 (m²); adds dE_r/dp to `grad` when non-null.
  double regularization_energy(const Polyline2& p, Polyline2* grad = nullptr) const;
  /// E = E_d + w_r E_r; adds the gradient when non-null.
  double energy(const Polyline2& p, Polyline2* grad = nullptr) const;
  /// D at one point and its gradient, as imls gives them.
  struct ImlsSample {
    Vec2 q;
    double value = 0.0;
    Vec2 gradient;
  };
  /// Σ over `terms` (vertex indices) of w_i D(p_i) + w_r |Δu_i|²: the part of E that a block of
  /// points changes. Adds the gradient when non-null (grad must already have #points entries);
  /// with the gradient, `samples` (when non-null) gets term k's D at p_{terms[k]} in entry k, for a
  /// caller that needs D there again (the SQP's Hessian).
  double energy_terms(const Polyline2& p, const std::vector<int>& terms, Polyline2* grad = nullptr,
                      std::vector<ImlsSample>* samples = nullptr) const;
  /// Value of constraint k; adds its gradient to `grad` when non-null.
  double constraint(std::size_t k, const Polyline2& p, Polyline2* grad = nullptr) const;
  /// Distance (metres) from q to the input contour polyline.
  double distance_to_contour(const Vec2& q) const;
  /// The IMLS squared distance D(q) of Eq. 4 for one point (m²) with its gradient.
  double imls(const Vec2& q, Vec2* grad = nullptr) const;

 private:
  struct Gap {  // consecutive crossings without a free point between them
    int a, b;   // crossings
    double arc, chord;
  };
  // The set-up, in this order: the contour's cumulative arc lengths (InputError for no length or
  // too many target points), the target and its grids, the resampling, the crossings' causes that
  // no solve changes, the solver's constraints.
  std::vector<double> arc_lengths(const Polyline2& contour) const;
  void build_target(const Polyline2& contour);
  std::vector<Gap> resample(const Polyline2& contour, const std::vector<double>& cum);
  void check_crossings(const std::vector<Gap>& gaps);
  void collect_constraints();
  double nearest_squared(const Vec2& q, Vec2* grad) const;
  // Term i of E_d (w_i D(p_i)) and of w_r E_r (weight |Δu_i|²); gradients added to grad. With grad,
  // `sample` (when non-null) gets D(p_i) and its gradient.
  double distance_term(const Polyline2& p, int i, Polyline2* grad, ImlsSample* sample = nullptr) const;
  double regularization_term(const Polyline2& p, int i, double weight, Polyline2* grad) const;

  TargetShapeOptions options_;
  std::vector<TargetCrossing> crossings_;
  bool closed_ = true;
  Polyline2 target_;          // densified input contour
  std::vector<Vec2> normals_; // unit normals at target points
  double h_ = 0.0;
  double cell_ = 0.0;
  Vec2 grid_origin_ = Vec2::Zero();
  int grid_nx_ = 0, grid_ny_ = 0;
  std::vector<int> grid_start_, grid_items_;  // CSR buckets of target points
  // CSR buckets of target edges (edge k: target_[k] to target_[k + 1]) on the same grid, each edge
  // in every cell its bounding box meets: the nearest-point query visits only cells that can hold
  // a point nearer than the best found so far.
  double edge_cell_ = 0.0;
  int edge_nx_ = 0, edge_ny_ = 0;
  std::vector<int> edge_start_, edge_items_;
  Polyline2 initial_;
  std::vector<char> fixed_;
  std::vector<int> crossing_vertices_;
  std::vector<Constraint> constraints_;
  std::vector<double> constraint_cos_;  // per constraint: cos of its bend limit or β (0 for a length)
  std::vector<TargetCrossingStatus> statuses_;
  std::vector<double> beta_;  // per crossing: α*/2 - atan μ
};

}  // namespace wiresculpt

// The batch of many wires (it needs TargetShapeResult above): included here so that this header
// keeps giving the whole stage.
#include "wiresculpt/target_shape_batch.hpp"
