#pragma once
// From a 2D rest polyline to the machine's program: feed, bend, feed, bend, ..., feed
// (Sec. 5.1: "the feeder either pushes the wire forward into the bending head, or the bending
// head rotates at a given angle"), with spring-back compensation from the calibration fit.
//
// Conventions
//   points   #P by 2, metres, an OPEN polyline starting at the cut (a closed wire's rest shape
//            already repeats the cut at both ends, docs/formats.md). The wire leaves the machine
//            starting with points[0].
//   feed     metres of wire pushed before a bend (the edge lengths between bend points).
//   bend     radians, the signed turn of the wire's direction at a bend point, walking from the
//            cut, in the polyline's own frame (x right, y up): positive = counter-clockwise =
//            "left". |bend| < pi. How a sign becomes a head direction is
//            MachineProfile::left_is_positive.
//   commanded radians sent to the head after compensation, same sign as bend:
//            |commanded| = (|bend| - b) / a, inverting the fit measured = a * commanded + b.
//
// The small-bend rule (turns under MachineProfile::min_bend, which the machine cannot make
// reliably). The rebuilt wire's direction is kept within min_bend / 2 of the input's:
//   1. Walk the interior points from the cut keeping a carried turn c (initially 0): the turn
//      the rebuilt wire still owes the input.
//   2. At point j with turn theta_j let t = theta_j + c.
//      - |t| >= min_bend: a bend of t is made at j, c = 0. The small turns met since the last
//        bend are ACCUMULATED into this bend, so the direction after it is exactly the input's.
//        Exception: when |t| > max_bend but |theta_j| <= max_bend (the carry would push a legal
//        bend over the limit) the bend is theta_j and c is carried on to the next point.
//      - min_bend / 2 <= |t| < min_bend: the smallest reliable bend, min_bend * sign(t), is made
//        at j and the overshoot c = t - min_bend * sign(t) is carried (|c| <= min_bend / 2).
//      - |t| < min_bend / 2: no bend at j; the feeds on both sides MERGE into one and c = t.
//      Rounding to the nearest of {0, +-min_bend} makes the direction error alternate in sign
//      along a gentle arc instead of always lagging, so position errors do not add up.
//   3. A carry left after the last interior point has no bend to join and is DROPPED
//      (BendProgram::dropped_turn, |dropped_turn| < min_bend).
//   Merging only lengthens feeds, so the rule never creates a feed shorter than the input's.
//   The cost is reported as BendProgram::shape_error: the largest distance, over the wire's
//   arc length s, between the input polyline and the rebuilt one (both start at the same point
//   and direction; both are piecewise linear in s with kinks at input points, so the maximum is
//   attained at an input point and computed exactly there).
//
// Numbering (one for every message about a wire's bends): bend k is the k-th bend from the cut,
// made at step k of the program, which first feeds the wire before it (the G-code's "; step k"
// and the bend table's row k); a place is also given as its arc length from the cut in mm.
//
// Refused (InputError, nothing returned): fewer than 2 points, non-finite coordinates, a
// zero-length segment (naming the points); and the problems bend_program_problems lists, the
// first of them: a bend over max_bend (naming the bend, where it is and its angle), a feed
// shorter than min_feed (naming the step, the bends around it and where it starts), a commanded
// angle beyond max_commanded or non-positive after compensation (naming the bend and its angle).
#include <cstddef>
#include <string>
#include <vector>

#include "wiresculpt/fab/machine.hpp"
#include "wiresculpt/geometry.hpp"

namespace wiresculpt::fab {

/// One machine step: feed, then bend (the final step only feeds).
struct BendStep {
  double feed = 0.0;       ///< m of wire fed before the bend
  double bend = 0.0;       ///< rad, signed target turn after the feed (0 on the final step)
  double commanded = 0.0;  ///< rad, spring-back compensated head command (0 on the final step)
  int vertex = -1;         ///< index in the input polyline of the bend point; -1 on the final step
};

struct BendProgram {
  std::vector<BendStep> steps;   ///< in machine order, starting at the cut; last step has no bend
  Vec2 start = Vec2::Zero();     ///< m, the input's first point (the cut)
  double start_heading = 0.0;    ///< rad, direction of the input's first segment (atan2)
  std::size_t input_points = 0;  ///< #P of the input polyline
  double wire_length = 0.0;      ///< m, total wire (sum of feeds)
  int bend_count = 0;            ///< bends made (steps.size() - 1)
  int merged_points = 0;         ///< interior input points where no bend is made (rule step 2)
  int rounded_bends = 0;         ///< bends rounded up to min_bend (rule step 2, second case)
  int small_turns = 0;           ///< of those, points whose own turn was non-zero but < min_bend
  double dropped_turn = 0.0;     ///< rad, carry dropped at the end of the wire (rule step 3)
  double shape_error = 0.0;      ///< m, max over arc length of |input(s) - rebuilt(s)|
  double machine_seconds = 0.0;  ///< s, estimate: sum over bend steps of
                                 ///< max(seconds_per_bend, feed/feed_speed + 2|commanded|/bend_speed)
                                 ///< plus the final feed / feed_speed
};

/// Something that keeps a wire from being made on the machine.
struct BendProblem {
  enum class Kind {
    over_bend,   ///< |bend| > max_bend
    short_feed,  ///< a feed < min_feed
    command,     ///< the compensated command is not positive or beyond max_commanded
  };
  Kind kind = Kind::over_bend;
  int number = 0;     ///< the bend (over_bend, command) or the step (short_feed), from 1
  int from = -1;      ///< input point of the bend, or where the short feed starts
  int to = -1;        ///< input point of the bend, or where the short feed ends (the next bend or the end)
  double at = 0.0;    ///< m, arc length from the cut (points[0]) to `from`
  double value = 0.0; ///< rad |bend| or m feed
  double limit = 0.0; ///< rad max_bend / max_commanded, or m min_feed
  std::string message;  ///< the sentence make_bend_program throws for it
};

/// Every problem of the program for `points` on `profile`, in the order make_bend_program meets
/// them (bends walking from the cut, then feeds, then compensation); empty when it can be made.
/// Throws InputError for the input errors above.
std::vector<BendProblem> bend_program_problems(const Polyline2& points, const MachineProfile& profile);

/// The program that bends `points` (#P by 2, metres, open, starting at the cut) on `profile`.
/// Throws InputError as listed above; validates the profile first.
BendProgram make_bend_program(const Polyline2& points, const MachineProfile& profile);

/// The polyline the program makes (bend points only, #steps + 1 points), from the recorded start
/// point and heading, or from the origin heading +x when `from_origin`. Uses the target bends
/// (before compensation), so a program without merged points rebuilds its input exactly.
Polyline2 rebuild_polyline(const BendProgram& program, bool from_origin = false);

/// What the machine makes of `program` (the preview): the program run forward
/// through `machine`'s spring-back line, the inverse of the compensation. Each step feeds as
/// programmed; each commanded angle c leaves the wire turned by sign(c) * (a * |c| + b) with
/// a = machine.springback_a, b = machine.springback_b (the fit measured = a * commanded + b).
/// Walked from the program's start point and heading (as rebuild_polyline: bend points only,
/// #steps + 1 points, metres). With the profile that compensated the program it equals
/// rebuild_polyline(program); with another fit it shows the drift that fit predicts.
/// Throws InputError when `machine` is not a valid profile (validate()).
Polyline2 predict_polyline(const BendProgram& program, const MachineProfile& machine);

/// Input-polyline indices of the bend points, in order (for tick marks on templates).
std::vector<std::size_t> bend_vertices(const BendProgram& program);

/// Spring-back compensation of one target bend (rad): sign(target) * (|target| - b) / a.
/// Throws InputError naming `bend_number` when the result is not positive or exceeds the head's range.
double compensate(double target, const MachineProfile& profile, int bend_number = 0);

/// The pointwise distance used for shape_error: max over arc length s of |a(s) - b(s)| where both
/// polylines are walked from their first point (the shorter one is extended by its last point).
double arclength_distance(const Polyline2& a, const Polyline2& b);

}  // namespace wiresculpt::fab
