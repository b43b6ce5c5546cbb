// The target-shape solve of one wire (optimize_target_shape): the problem, its start and blocks,
// and the sweeps over the blocks as a coroutine that a batch can hand from thread to thread
// between two windows (detail::TargetShapeRun).
#include "wiresculpt/target_shape.hpp"

#include <chrono>
#include <cmath>
#include <functional>
#include <limits>
#include <string>
#include <vector>

#include "target_shape_block_solver.hpp"
#include "target_shape_messages.hpp"
#include "target_shape_parts.hpp"

namespace wiresculpt {

TargetShapeResult optimize_target_shape(const Polyline2& contour, bool closed,
                                        const std::vector<TargetCrossing>& crossings,
                                        const TargetShapeOptions& options, const ProgressFn& progress) {
  detail::TargetShapeRun run = detail::run_target_shape(contour, closed, crossings, options, progress);
  while (run.step()) {
  }
  return run.take();
}

namespace {
// Stop once a whole sweep lowered the wire's energy by no more than sweep_ftol of it, with every
// constraint met or with its largest violation not lowered by more than that fraction either:
// what is left is creep along the wire (see sweep_ftol). `last_energy` and `last_violation` are
// the previous sweep's, updated here.
bool sweeps_settled(const TargetShapeProblem& problem, const Polyline2& p, double& last_energy, double& last_violation) {
  const TargetShapeOptions& o = problem.options();
  const double energy = problem.energy(p);
  double violation = 0.0;
  for (std::size_t k = 0; k < problem.constraints().size(); ++k)
    violation = std::max(violation, problem.constraint(k, p));
  const bool small = last_energy - energy <= o.sweep_ftol * std::abs(energy);
  // An infeasible wire whose sweep lowered neither its energy nor its largest violation is
  // stuck there: the kink it cannot open stays as far from its cone.
  const bool stuck = violation >= (1.0 - o.sweep_ftol) * last_violation;
  last_energy = energy;
  last_violation = violation;
  return small && (violation <= o.constraint_tol || stuck);
}

// Marks the blocks other than `k` that read a point of block `k` which moved by more than
// sweep_tol since `before`.
void mark_dirty(const std::vector<detail::Block>& blocks, std::size_t k, const std::vector<std::vector<int>>& watchers,
                const Polyline2& before, const Polyline2& p, double move_tol, std::vector<char>& dirty) {
  for (int q : blocks[k].points)
    if ((p[q] - before[q]).norm() > move_tol)
      for (int other : watchers[q])
        if (other != static_cast<int>(k)) dirty[other] = 1;
}
}  // namespace

// clang 14 cannot assemble a coroutine instrumented by -fsanitize=function together with
// sanitizer coverage (the fuzz build's -fsanitize=undefined,fuzzer-no-link: "Cannot represent a
// difference across sections"), so that one check, of calls through mistyped function pointers,
// is left out of this function; every other sanitizer still instruments it.
#if defined(__clang__)
#define WIRESCULPT_NO_FUNCTION_SANITIZER __attribute__((no_sanitize("function")))
#else
#define WIRESCULPT_NO_FUNCTION_SANITIZER
#endif

// The sweeps: one block is solved once; windows are solved in turn (multiplicative Schwarz), a
// window again only when a point it depends on moved by more than sweep_tol since it was last
// solved, until none moves, the sweeps settle (sweep_ftol) or a budget runs out. Between two
// windows the run yields, so that another thread may take the next one.
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
  const TargetShapeOptions& o = problem.options();
  TargetShapeResult result;
  const Polyline2 start = start_points(problem);
  const int m = static_cast<int>(start.size());
  const std::vector<Block> blocks = make_blocks(problem);
  result.nlopt_result = "none";
  BlockSolver solver(problem, start, progress, elapsed, result);
  if (blocks.size() == 1) {
    solver.solve(blocks[0], true);
    result.sweeps = 1;
  } else if (!blocks.empty()) {
    std::vector<char> dirty(blocks.size(), 1);
    double last_energy = std::numeric_limits<double>::infinity();     // E after the previous sweep
    double last_violation = std::numeric_limits<double>::infinity();  // and its largest violation
    const std::vector<std::vector<int>> watchers = block_watchers(blocks, m, closed);
    Polyline2 before;  // the points before a window, kept across windows
    for (int sweep = 0; sweep < o.max_sweeps && !solver.out_of_time(); ++sweep) {
      bool any = false;
      for (std::size_t k = 0; k < blocks.size() && !solver.out_of_time(); ++k) {
        if (!dirty[k]) continue;
        any = true;
        dirty[k] = 0;
        before = solver.points();
        solver.solve(blocks[k], sweep == 0 && blocks[k].around_crossing);
        mark_dirty(blocks, k, watchers, before, solver.points(), o.sweep_tol, dirty);
        if (solver.evaluations() >= o.max_iterations) break;
        const auto pause = std::chrono::steady_clock::now();
        co_yield 0;  // a window solved: another thread may run the next one (TargetShapeRun)
        paused += std::chrono::steady_clock::now() - pause;
      }
      if (!any) break;
      result.sweeps = sweep + 1;
      if (solver.evaluations() >= o.max_iterations) {
        result.nlopt_result = "NLOPT_MAXEVAL_REACHED";
        break;
      }
      if (o.sweep_ftol > 0.0 && sweeps_settled(problem, solver.points(), last_energy, last_violation)) break;
    }
  }
  if (solver.out_of_time()) {
    result.nlopt_result = "NLOPT_MAXTIME_REACHED";
    result.warnings.push_back("wire " + o.wire_name + ": the target shape stopped at its time budget of " +
                              fmt(o.max_seconds, 4) + " s (max_seconds) before it converged");
  }
  result.iterations = solver.evaluations();
  measure_result(problem, crossings, solver.points(), result);
  result.seconds = elapsed();
  report_progress(progress, "target_shape", 1.0);
  co_return result;
}

}  // namespace wiresculpt
