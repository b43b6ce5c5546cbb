#pragma once
// Many wires' target shapes at once (optimize_target_shapes, TargetShapeBatch), on the calling
// thread and one more; each result is the one optimize_target_shape gives for its wire alone.
#include <memory>
#include <optional>
#include <vector>

#include "wiresculpt/target_shape.hpp"

namespace wiresculpt {

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

}  // namespace wiresculpt
