#pragma once
// The solver of one block of the target shape (internal to the core): NLopt, or with
// TargetShapeAlgorithm::sqp the Newton SQP (target_shape_sqp.hpp) with its SLSQP lead-in where the
// basin is chosen and SLSQP as its fallback; a block's answer is kept only if it is no worse than
// where the block started. One solver serves every block of a run, in turn, and keeps the points.
#include <functional>
#include <memory>

#include "target_shape_parts.hpp"
#include "wiresculpt/progress.hpp"

namespace wiresculpt::detail {

class BlockSolver {
 public:
  /// Solves `problem` from the points `start`. `progress` is polled at the first evaluation and
  /// then every 16 (it may cancel: Cancelled); `elapsed` gives the run's seconds so far (against
  /// max_seconds, which every block shares). Each block adds into `result` its SQP counts
  /// (sqp_blocks, sqp_fallbacks), its NLopt code (nlopt_result: the first failure of any block,
  /// else the last block's) and a warning where the solver diverged. `problem`, `progress` and
  /// `result` must outlive the solver.
  BlockSolver(const TargetShapeProblem& problem, const Polyline2& start, const ProgressFn& progress,
              std::function<double()> elapsed, TargetShapeResult& result);
  ~BlockSolver();
  BlockSolver(const BlockSolver&) = delete;
  BlockSolver& operator=(const BlockSolver&) = delete;

  /// Solves block `b` with the other points held. `choose_basin` (sqp only): SLSQP's first
  /// evaluations lead, where the kinks' arrangement is chosen (a one-block wire, or a window
  /// centred on a crossing in the first sweep). Returns how far (metres) a point of it moved.
  double solve(const Block& b, bool choose_basin);

  const Polyline2& points() const;  ///< the points as the blocks solved so far left them
  int evaluations() const;          ///< energy evaluations so far, every block together
  bool out_of_time() const;         ///< the run's clock has reached max_seconds

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace wiresculpt::detail
