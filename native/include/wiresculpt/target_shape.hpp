#pragma once
// Per-wire target-shape optimisation (Sec. 4.3 of Miguel, Lepoutre, Bickel 2016, Eq. 3-5): turn a
// wire's dense sliced contour into a fabricable polyline that stays close to it, keeps every
// crossing point fixed, respects the bending machine (segments >= l_min, bends <= max) and opens
// each active crossing's kink towards the bisector the layering chose (contact constraints).
// The method, its choices and the measurements behind them are in docs/method-target-shape.md.
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

namespace wiresculpt {

struct TargetShapeOptions;
/// The bend limit at point i: vertex_max_bend[i] when given (> 0), else max_bend.
double bend_limit(const TargetShapeOptions& options, int i);

/// One crossing on the wire, as the layering stage hands it over (FORMATS.md, `hook`).
struct TargetCrossing {
  /// Index into the input contour of the vertex that IS the crossing point (exactly on it).
  int vertex = -1;
  /// Desired unit bisector h* in the plane frame: the direction the kink must open to (Sec. 4.1,
  /// h = (ê_r - ê_{r-1}) / |…|). Normalised here; must be non-zero when `active`.
  Vec2 bisector = Vec2::Zero();
  /// Desired contact angle α* in radians, (0, π]: the angle between the two edges at the kink
  /// (Sec. 4.1, the angle between e_r and -e_{r-1}; π is straight).
  double contact_angle = 2.0 * std::numbers::pi / 3.0;
  /// false for the null hook: the crossing point stays fixed, no contact constraint.
  bool active = true;
};

enum class TargetShapeAlgorithm {
  slsqp,         ///< NLopt LD_SLSQP (default: see docs/method-target-shape.md)
  /// Newton SQP per block (target_shape_sqp.hpp), led by SLSQP's first evaluations where the
  /// basin is chosen and replaced by SLSQP where it fails; the pipeline's choice (see
  /// docs/method-target-shape.md)
  sqp,
  auglag_lbfgs,  ///< NLopt AUGLAG with LD_LBFGS as the local solver
  ccsaq,         ///< NLopt LD_CCSAQ
  mma,           ///< NLopt LD_MMA
};

struct TargetShapeOptions {
  /// Metres, in (0, 10]. The machine's minimum distance between bending points (Sec. 5.1).
  /// Default 0.015.
  double min_segment = 0.015;
  /// Radians, in (0, π]. The largest bend (turning angle, π minus the kink's opening) the machine
  /// makes at one point (Sec. 4.3, c_f,angle). Default 2π/3 (120°).
  double max_bend = 2.0 * std::numbers::pi / 3.0;
  /// Radians, per point of the result (an index into TargetShapeResult::points, which is the
  /// same for every solve of one contour with the same crossings and spacing): a tighter bend
  /// limit at that point than max_bend. The coupling with the rest shape (Sec. 4.3) sets it where
  /// the forces bend the rest shape beyond the machine. Entries <= 0 or past the end: max_bend.
  /// Default empty.
  std::vector<double> vertex_max_bend;
  /// Metres, in the wire's plane frame: points to start the solve from instead of the resampled
  /// contour with its kinks turned open, one per point of the result (the same count as a solve
  /// of this contour with these crossings and spacing returns; else InputError). The crossing
  /// points are always the contour's own; the regulariser still measures from the resampling, so
  /// the problem is the same and only the start changes. The coupling with the rest shape passes
  /// the previous round's result when it lowers a vertex's bend limit (warm start; see
  /// docs/method-target-shape.md). Default empty (cold start).
  Polyline2 start;
  /// Metres. Arc-length spacing of the initial resampling between consecutive crossings; 0 means
  /// 1.5 × min_segment. 0, or from min_segment/10 to 10 m (should not be below min_segment). A
  /// wire longer than 250000 × spacing (10^6 target points) is refused. Default 0.
  double spacing = 0.0;
  /// w_r of Eq. 3, in metres (E_d is in m³, E_r in m²). Default 1e-3 m: a one-point bump of
  /// height a costs about 2·spacing·a² in E_d and 1.5·w_r·a² in E_r, so at the default spacing the
  /// regulariser weighs about 1/30 of the distance term: it smooths the displacement field near
  /// kinks without pulling the wire off the contour.
  double regularization = 1e-3;
  /// Coulomb friction coefficient μ (Table 1: steel 0.32, brass 0.23). The contact constraint
  /// adds α(μ) = atan(μ), the friction angle, to each edge's angle from h* (Sec. 4.3), the same
  /// α(μ) as ContactOptions::friction in contact.hpp. 0 gives the purely geometric constraint.
  double friction = 0.32;
  TargetShapeAlgorithm algorithm = TargetShapeAlgorithm::slsqp;
  /// NLopt's relative tolerance on the energy. Default 1e-12.
  double ftol_rel = 1e-12;
  /// NLopt's relative tolerance on the variables (scaled by min_segment). Default 1e-10.
  double xtol_rel = 1e-10;
  /// Tolerance on each constraint in its solver form (dimensionless: 1 - |e|²/l_min² for lengths,
  /// cosines for angles). Default 1e-10.
  double constraint_tol = 1e-10;
  /// Maximum number of energy evaluations over all blocks (SLSQP uses about one per iteration),
  /// 1 to 10^7. Default 20000.
  int max_iterations = 20000;
  /// Points per block: 0 or 4 to 10000. 0, or a wire of at most 4 × window points, is solved as one NLopt
  /// problem; otherwise windows of `window` points centred on each active crossing, then
  /// overlapping windows of `window` consecutive points (every window/2 points), are solved in
  /// turn, each with the rest of the wire held, until no window moves a point by more than
  /// sweep_tol (multiplicative Schwarz / block coordinate descent). Dense SLSQP costs O(n³) per
  /// iteration, so windows make long wires fast; see docs/method-target-shape.md. Default 8.
  int window = 8;
  /// Points: a wire of at most this many points is solved as one block even with windows; -1
  /// means 4 × window. From -1 to 10000. Default -1.
  int one_block_points = -1;
  /// Metres. A window is solved again when a point its energy terms read moved by more than this
  /// since its last solve. Default 1e-7 (0.1 µm, a hundredth of the 10 µm to which a realised
  /// segment is checked): at 1 nm the sweeps chase SLSQP's own stopping noise (the optimum is
  /// flat along the wire) for 10-20 times as many evaluations without changing the energy's
  /// first 7 digits; see docs/method-target-shape.md.
  double sweep_tol = 1e-7;
  /// Relative energy decrease per sweep, in [0, 1). With windows, the sweeps also stop once a
  /// whole sweep lowered the wire's energy E by no more than sweep_ftol × E and either every
  /// constraint holds (to constraint_tol) or the largest violation went down by no more than
  /// sweep_ftol of it (a kink that cannot be opened stays as far from its cone sweep after sweep;
  /// such a wire's crossing is reported, and further sweeps only creep). The optimum is flat along the wire, and sweeps after the first few mostly
  /// move points along it (millimetres on a 3 m wire, each sweep a little) without changing their
  /// distance to the contour; see docs/method-target-shape.md. 0: off, the sweeps run until no
  /// window moves a point by more than sweep_tol. Default 0; the pipeline uses 1e-3.
  double sweep_ftol = 0.0;
  /// Maximum number of sweeps over the windows, 1 to 100000. Default 200.
  int max_sweeps = 200;
  /// Seconds: the wall-clock budget of the whole call, in (0, 86400]. When it runs out the
  /// solver stops where it is: nlopt_result "NLOPT_MAXTIME_REACHED" and a warning naming the
  /// wire (the constraints are then checked as usual). Default 120.
  double max_seconds = 120.0;
  /// Metres: the model's current size (largest bounding-box side), used to say how large it must
  /// be scaled when two crossings are too close. 0: only the scale factor is reported.
  double model_size = 0.0;
  /// Radians. A contact or bend constraint violated by more than this after the solve marks the
  /// result (and the crossing) as not realised. Default 1e-6.
  double angle_tolerance = 1e-6;
  /// Metres. Same for segment lengths. Default 1e-6.
  double length_tolerance = 1e-6;
  /// Shown in every message about this wire.
  std::string wire_name = "wire";
};

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

/// One wire's problem for optimize_target_shapes: optimize_target_shape's arguments.
struct TargetShapeJob {
  Polyline2 contour;
  bool closed = false;
  std::vector<TargetCrossing> crossings;
  TargetShapeOptions options;
  /// The wire's plane (origin, u, v; the normal is not read): its result's `target` and `length`
  /// are then filled on the thread that solved it.
  std::optional<Plane> plane;
};

/// optimize_target_shape of every job, on the calling thread and, with threads = 2, one more
/// started here: each thread takes the free job with the most work left by a guess (the dearest
/// first), and between two windows of a windowed wire hands it over when a free one has clearly
/// more left, so that three equal wires share two threads (only who runs which piece, never a
/// result, depends on it: detail::TargetShapeRun). Every result is the one
/// optimize_target_shape returns for that job alone (with `target` and `length` filled for a job
/// with a plane), and they come back in the jobs' order.
/// Only the calling thread calls `progress` (with a job's own fractions, and while it waits for
/// the other thread's last job); when it asks to stop, both threads stop at their next progress
/// poll (every 16 evaluations). After both threads stopped, throws the exception `progress` threw
/// if it threw one, else the error of the first job (in the jobs' order) that threw one:
/// InputError naming its wire, or Cancelled. threads: 1 or 2.
std::vector<TargetShapeResult> optimize_target_shapes(const std::vector<TargetShapeJob>& jobs, int threads = 2,
                                                      const ProgressFn& progress = {});

namespace detail {
/// Fills r.target (r.points placed in `plane`: origin + x u + y v, in that order) and r.length,
/// their polyline's length with the edges' norms added as numpy's sum adds them (exact/numpy_sum.hpp):
/// the same numbers, to the bit, as the target-shape stage's to_3d and polyline_length.
void place_target(TargetShapeResult& r, const Plane& plane, bool closed);

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

/// What optimize_target_shapes did besides its results, for tests: how often a thread handed its
/// wire over for another between two windows.
struct TargetShapesStats {
  int hand_overs = 0;
};
/// optimize_target_shapes, counting into `stats` (when non-null).
std::vector<TargetShapeResult> optimize_target_shapes(const std::vector<TargetShapeJob>& jobs, int threads,
                                                      const ProgressFn& progress, TargetShapesStats* stats);
}  // namespace detail

/// optimize_target_shapes with the jobs handed over one at a time: with two threads, the other
/// thread is woken when the batch is made, starts at the first add() and solves while the caller
/// prepares the next jobs (the stage's Python reads each wire's frame and crossings); finish() then works on the calling thread too until every
/// job is solved, exactly as optimize_target_shapes does (it is this batch with every job added at
/// once). Every result is the one optimize_target_shape returns for that job alone (with its
/// `target` and `length` for a job with a plane), in the order added. Before finish()
/// the other thread polls no `progress` and hands no wire over. Call add() and finish() from the
/// thread that made the batch; destroying a batch that was not finished stops its other thread
/// at its next poll and joins it.
class TargetShapeBatch {
 public:
  explicit TargetShapeBatch(int threads);  ///< 1 or 2, else InputError
  TargetShapeBatch(const TargetShapeBatch&) = delete;
  TargetShapeBatch& operator=(const TargetShapeBatch&) = delete;
  ~TargetShapeBatch();
  void add(TargetShapeJob job);
  /// The results, as optimize_target_shapes returns them (and throws as it throws). Once only.
  std::vector<TargetShapeResult> finish(const ProgressFn& progress = {}, detail::TargetShapesStats* stats = nullptr);

 private:
  struct State;
  std::unique_ptr<State> state_;
};

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
