#pragma once
// The pieces of the target-shape solve that optimize_target_shape puts together (internal to the
// core): the start, the blocks, the sweep's bookkeeping and the result's figures. The problem
// (target_shape_problem.cpp, target_shape_energy.cpp) and the block solver
// (target_shape_block_solver.hpp) are apart.
#include <cmath>
#include <vector>

#include "wiresculpt/target_shape.hpp"

namespace wiresculpt::detail {

inline double cross2(const Vec2& a, const Vec2& b) { return a.x() * b.y() - a.y() * b.x(); }
/// Angle in [0, π] between two non-zero vectors.
inline double angle_between(const Vec2& a, const Vec2& b) { return std::atan2(std::abs(cross2(a, b)), a.dot(b)); }

/// The points a solve starts from: `problem.options().start`'s free points (a warm start; the
/// crossings stay the contour's), else the initial resampling with each free neighbour of an
/// active crossing outside its contact cone turned about the crossing onto the cone (keeping its
/// distance and its side of h*), so that the kinks start open the right way. InputError for a
/// start of the wrong size or not finite.
Polyline2 start_points(const TargetShapeProblem& problem);

/// One block of the problem handed to a solver: some free points as variables (the others held at
/// their current positions), the energy terms they change and the constraints they touch.
struct Block {
  std::vector<int> points;       ///< variables, 2 per point
  std::vector<int> terms;        ///< energy terms depending on them
  std::vector<int> constraints;  ///< indices into TargetShapeProblem::constraints()
  bool around_crossing = false;  ///< a window centred on an active crossing
};

/// The blocks: one for the whole wire (window 0 or at most one_block_points points), or a window
/// of `window` points centred on each active realised crossing (both sides of the kink move
/// together) followed by overlapping windows of `window` points every window/2 points (every
/// constraint, spanning at most three consecutive points, lies inside one window). Blocks
/// without a free point are left out.
std::vector<Block> make_blocks(const TargetShapeProblem& problem);

/// Per point, the blocks whose energy terms read it (a block is solved again when one moved).
std::vector<std::vector<int>> block_watchers(const std::vector<Block>& blocks, int points, bool closed);

/// Fills `result`'s points, statuses and figures from the solved points `p`: the distances to
/// the contour, the shortest segment and largest bend and their violations, each crossing's
/// achieved bisector, angle and contact violation, the crossings whose kink missed its cone or
/// whose neighbour breaks a machine limit (cone_missed, neighbour_bend, neighbour_segment), the
/// warnings about short segments and sharp bends, and `feasible`.
void measure_result(const TargetShapeProblem& problem, const std::vector<TargetCrossing>& crossings,
                    const Polyline2& p, TargetShapeResult& result);

}  // namespace wiresculpt::detail
