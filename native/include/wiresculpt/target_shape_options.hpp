#pragma once
// The target shape's input (target_shape.hpp): one wire's crossings as the layering hands them
// over, and the options of its solve, each with its unit, range and default.
#include <numbers>
#include <string>
#include <vector>

#include "wiresculpt/geometry.hpp"

namespace wiresculpt {

/// One crossing on the wire, as the layering stage hands it over (docs/formats.md, `hook`).
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

/// The bend limit at point i: vertex_max_bend[i] when given (> 0), else max_bend.
double bend_limit(const TargetShapeOptions& options, int i);

}  // namespace wiresculpt
