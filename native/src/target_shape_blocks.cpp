// The blocks of the target shape's solve and which of them read each point.
#include <algorithm>
#include <vector>

#include "target_shape_parts.hpp"
#include "target_shape_sqp.hpp"

namespace wiresculpt::detail {
namespace {

// The block of the points in `range` (free ones only).
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

// A window of `window` points centred on each active realised crossing.
void add_crossing_windows(const TargetShapeProblem& problem, int window, std::vector<Block>& blocks) {
  const int m = static_cast<int>(problem.initial().size());
  const bool closed = problem.closed();
  for (std::size_t c = 0; c < problem.crossings().size(); ++c) {
    const TargetCrossingStatus& s = problem.statuses()[c];
    if (!problem.crossings()[c].active || !s.realised) continue;
    std::vector<int> range;
    const int half = window / 2;
    for (int j = -half; j < half; ++j) {
      const int q = s.vertex + j;
      if (closed || (q >= 0 && q < m)) range.push_back((q + m) % m);
    }
    blocks.push_back(make_block(problem, range));
    blocks.back().around_crossing = true;
  }
}
}  // namespace

std::vector<Block> make_blocks(const TargetShapeProblem& problem) {
  const TargetShapeOptions& o = problem.options();
  const int m = static_cast<int>(problem.initial().size());
  const bool closed = problem.closed();
  std::vector<Block> blocks;
  const int window = o.window;
  const long long one_block = o.one_block_points < 0 ? 4LL * window : o.one_block_points;
  if (window <= 0 || static_cast<long long>(m) <= one_block) {  // small wires: one block is as cheap
    std::vector<int> all(m);
    for (int i = 0; i < m; ++i) all[i] = i;
    blocks.push_back(make_block(problem, all));
  } else {
    add_crossing_windows(problem, window, blocks);  // first, then the uniform tiling
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
  return blocks;
}

std::vector<std::vector<int>> block_watchers(const std::vector<Block>& blocks, int m, bool closed) {
  std::vector<std::vector<int>> watchers(m);
  for (std::size_t k = 0; k < blocks.size(); ++k)
    for (int t : blocks[k].terms)
      for (int s : {-1, 0, 1}) {
        const int j = t + s;
        if (!closed && (j < 0 || j >= m)) continue;
        auto& wv = watchers[(j + m) % m];
        if (wv.empty() || wv.back() != static_cast<int>(k)) wv.push_back(static_cast<int>(k));
      }
  return watchers;
}

}  // namespace wiresculpt::detail
