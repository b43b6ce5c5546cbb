#include "wiresculpt/load_capacity.hpp"

#include <atomic>
#include <cstdlib>
#include <chrono>
#include <exception>
#include <optional>
#include <system_error>
#include <thread>
#include <cmath>
#include <limits>
#include <numbers>
#include <set>
#include <string>
#include <utility>

#include "lp.hpp"
#include "wiresculpt/error.hpp"

namespace wiresculpt {

namespace {

// Walks and edges (weights at midpoints) per wire.
struct Edge {
  Vec3 mid;
  double weight;
};

constexpr double inf = std::numeric_limits<double>::infinity();

// What every direction's LP reads, unchanged while the directions are solved.
struct Shared {
  const Network& net;
  const Eigen::VectorXd& a0;
  const LoadCapacityOptions& options;
  int K;
  const std::vector<std::vector<int>>& walks;
  const std::vector<std::vector<Edge>>& edges;
  const Eigen::MatrixXd& M;
  const Eigen::MatrixXd& T;
  const Eigen::MatrixXd& T3;
  const TorquePolytope& polytope;
  const Eigen::VectorXd& Ma0;
  const Eigen::VectorXd& Ta0;
  const Eigen::VectorXd& T3a0;
  const Vec3& ref;
  double t_max;
  const std::vector<int>& first_row;  // first torque row of each wire, and the count after the last
  detail::CutRows cut_rows;
};

// The rows of wire w, which is not held, from `row` on: its equilibrium (weight along g times the
// load multiple λ, column K) and its torque at each position (the contact part from T, the
// weight part from the edges after it), each torque row's index and weight torque kept for the
// polytope's rows.
void add_wire_rows(const Shared& s, int w, const Vec3& g, detail::LinearProgram& lp, int& row,
                   std::vector<int>& torque_row, std::vector<Vec3>& torque_grav) {
  const int K = s.K;
  auto entry = [&](int col, double v) {
    if (v == 0.0) return;
    lp.tri_row.push_back(row);
    lp.tri_col.push_back(col);
    lp.tri_val.push_back(v);
  };
  Vec3 F = Vec3::Zero(), Tq = Vec3::Zero();
  for (const Edge& e : s.edges[w]) {
    F += e.weight * g;
    Tq += (e.mid - s.ref).cross(e.weight * g);
  }
  Eigen::Matrix<double, 6, 1> load;
  load << F, Tq;
  for (int r = 0; r < 6; ++r, ++row) {
    for (int j = 0; j < K; ++j) entry(j, s.M(6 * w + r, j));
    entry(K, load(r));
    lp.row_lo.push_back(-s.Ma0(6 * w + r));
    lp.row_hi.push_back(-s.Ma0(6 * w + r));
  }
  // Torque rows: contact part from T, weight part from the edges after each position.
  const WireSpec& wire = s.net.wires[w];
  const int rows_w = s.first_row[w + 1] - s.first_row[w];
  for (int v = 0; v < rows_w; ++v, ++row) {
    const int tr = s.first_row[w] + v;
    const Vec3& xv = wire.points[s.walks[w][v]];
    Vec3 tg = Vec3::Zero();
    for (std::size_t k = static_cast<std::size_t>(v); k < s.edges[w].size(); ++k)
      tg += (xv - s.edges[w][k].mid).cross(s.edges[w][k].weight * g);
    const double grav = tg.dot(wire.plane.normal);
    torque_row.push_back(tr);
    torque_grav.emplace_back(grav, tg.dot(wire.plane.u), tg.dot(wire.plane.v));
    for (int j = 0; j < K; ++j) entry(j, s.T(tr, j));
    entry(K, grav);
    lp.row_lo.push_back(-s.t_max - s.Ta0(tr));
    lp.row_hi.push_back(s.t_max - s.Ta0(tr));
  }
}

// The torque blocks of the rows in torque_row: their frame components as functions of (δ, λ).
detail::TorqueBlocks torque_blocks(const Shared& s, const std::vector<int>& torque_row,
                                  const std::vector<Vec3>& torque_grav) {
  const int K = s.K;
  // The slab rows above are implied by either bound; the polytope's other rows join as the
  // solutions violate them.
  detail::TorqueBlocks blocks;
  blocks.A = Eigen::MatrixXd::Zero(3 * static_cast<Eigen::Index>(torque_row.size()), K + 1);
  blocks.c.resize(blocks.A.rows());
  for (std::size_t i = 0; i < torque_row.size(); ++i) {
    const Eigen::Index b = 3 * static_cast<Eigen::Index>(i);
    blocks.A.block(b, 0, 3, K) = s.T3.middleRows(3 * torque_row[i], 3);
    blocks.A.block<3, 1>(b, K) = torque_grav[i];
    blocks.c.segment<3>(b) = s.T3a0.segment<3>(3 * torque_row[i]);
  }
  return blocks;
}

// The direction's answer from its LP's solution: λ and the coefficients, scaled into the
// polytope when GLPK's tolerance left a torque outside it.
void take_solution(const Shared& s, const detail::LpSolution& sol, const detail::TorqueBlocks& blocks,
                   LoadDirection& ld) {
  const int K = s.K;
  switch (sol.status) {
    case detail::LpSolution::optimal: {
      ld.status = "optimal";
      // (a0 + δ, λ) scaled into the polytope when GLPK's tolerance left a torque outside it.
      Eigen::VectorXd x = Eigen::Map<const Eigen::VectorXd>(sol.x.data(), K + 1);
      x.head(K) += s.a0;
      double worst = 0.0;
      const Eigen::VectorXd t = blocks.A * x;  // c is T3 a0, already in x
      for (Eigen::Index b = 0; b < t.size() / 3; ++b)
        worst = std::max(worst, torque_gauge(s.polytope, t.segment<3>(3 * b), s.t_max));
      if (s.options.torque_bound == TorqueBound::full_3d && worst > 1.0) x /= worst;
      ld.coefficients = x.head(K);
      ld.multiple = std::max(0.0, x(K));
      break;
    }
    case detail::LpSolution::unbounded:
      ld.status = "unbounded";
      ld.multiple = inf;
      break;
    case detail::LpSolution::infeasible:
      ld.status = "infeasible";
      break;
    default:
      ld.status = "failed";
  }
}

// One direction's LP; reads only `s` (shared, unchanged), so two threads can run it.
LoadDirection solve_direction(const Shared& s, int dir) {
  const int P = static_cast<int>(s.net.wires.size());
  const int K = s.K;
  static const char* const names[6] = {"+x", "-x", "+y", "-y", "+z", "-z"};
  LoadDirection ld;
  ld.name = names[dir];
  ld.gravity = Vec3::Zero();
  ld.gravity[dir / 2] = dir % 2 == 0 ? 1.0 : -1.0;
  const Vec3& g = ld.gravity;
  // The held wires: lowest point along g (largest x·g), ties within tie_tolerance.
  std::vector<double> low(P, -inf);
  double lowest = -inf;
  for (int w = 0; w < P; ++w) {
    for (const Vec3& p : s.net.wires[w].points) low[w] = std::max(low[w], p.dot(g));
    lowest = std::max(lowest, low[w]);
  }
  std::vector<char> held(P, 0);
  for (int w = 0; w < P; ++w)
    if (low[w] >= lowest - s.options.tie_tolerance) {
      held[w] = 1;
      ld.base.push_back(w);
    }
  detail::LinearProgram lp;
  lp.maximise = true;
  lp.obj.assign(K + 1, 0.0);
  lp.obj[K] = 1.0;
  lp.col_lo.resize(K + 1);
  lp.col_hi.assign(K + 1, inf);
  for (int j = 0; j < K; ++j) lp.col_lo[j] = -s.a0(j);
  lp.col_lo[K] = 0.0;
  int row = 0;
  // Torques of the wires not held: t_v = T3_v (a0 + δ) + λ t_v^grav, frame components.
  std::vector<int> torque_row;
  std::vector<Vec3> torque_grav;
  for (int w = 0; w < P; ++w)
    if (!held[w]) add_wire_rows(s, w, g, lp, row, torque_row, torque_grav);
  const detail::TorqueBlocks blocks = torque_blocks(s, torque_row, torque_grav);
  std::set<std::pair<int, int>> added;
  detail::LpSolution sol = detail::solve_lp_with_torque_rows(lp, blocks, s.polytope, s.t_max, added, &ld.lp_rounds,
                                                              s.options.lp_warm_start, nullptr, s.cut_rows);
  ld.lp_iterations = sol.iterations;
  if (sol.status == detail::LpSolution::unbounded) {
    // Cap λ: an optimum well below the cap is the problem's (rows not yet added had left λ
    // free); one at the cap means that nothing but the cones limits the load.
    const double cap = 1e8;
    lp.col_hi[K] = cap;
    const detail::LpSolution capped =
        detail::solve_lp_with_torque_rows(lp, blocks, s.polytope, s.t_max, added, &ld.lp_rounds,
                                          s.options.lp_warm_start, nullptr, s.cut_rows);
    ld.lp_iterations += capped.iterations;
    if (capped.status == detail::LpSolution::optimal && capped.x[K] < 0.5 * cap) sol = capped;
  }
  take_solution(s, sol, blocks, ld);
  return ld;
}

}  // namespace

LoadCapacityResult load_capacity(const Network& net, const std::vector<int>& cuts, const ForceProblem& problem,
                                 const Eigen::VectorXd& a0, const LoadCapacityOptions& options,
                                 const ProgressFn& progress) {
  const auto start = std::chrono::steady_clock::now();
  auto positive = [](double v) { return std::isfinite(v) && v > 0; };
  if (!positive(options.wire_diameter)) throw InputError("wire_diameter must be a finite number of metres > 0");
  // A weight far from any real wire's makes the LP's numbers leave the range GLPK handles.
  if (!(options.density >= 1.0 && options.density <= 1e5))
    throw InputError("density must be a number of kg/m^3 from 1 to 100000 (steel 7850)");
  if (!positive(options.gravity)) throw InputError("gravity must be a finite number of m/s^2 > 0");
  if (!std::isfinite(options.tie_tolerance) || options.tie_tolerance < 0)
    throw InputError("tie_tolerance must be a finite number of metres >= 0");
  if (options.threads < 1 || options.threads > 2) throw InputError("load capacity: threads must be 1 or 2");
  const int K = problem.columns();
  if (a0.size() != K)
    throw InputError("load capacity: expected " + std::to_string(K) + " pre-stress coefficients, got " +
                     std::to_string(a0.size()));
  const int P = static_cast<int>(net.wires.size());
  if (cuts.size() != static_cast<std::size_t>(P)) throw InputError("load capacity: expected one cut per wire");
  const double per_metre = std::numbers::pi * 0.25 * options.wire_diameter * options.wire_diameter * options.density *
                           options.gravity;  // N/m
  LoadCapacityResult out;
  std::vector<std::vector<int>> walks(P);
  std::vector<std::vector<Edge>> edges(P);
  for (int w = 0; w < P; ++w) {
    const WireSpec& s = net.wires[w];
    walks[w] = wire_walk(static_cast<int>(s.points.size()), s.closed, cuts[w], s.name);
    for (std::size_t k = 0; k + 1 < walks[w].size(); ++k) {
      const Vec3& p = s.points[walks[w][k]];
      const Vec3& q = s.points[walks[w][k + 1]];
      const double len = (q - p).norm();
      out.length += len;
      edges[w].push_back({0.5 * (p + q), len * per_metre});
    }
  }
  out.weight = out.length * per_metre;
  const Eigen::MatrixXd& M = problem.equilibrium();
  const Eigen::MatrixXd& T = problem.torque_rows();
  const Eigen::MatrixXd& T3 = problem.torque_frame_rows();
  const TorquePolytope& polytope = torque_polytope(options.torque_bound);
  const Eigen::VectorXd Ma0 = M * a0;
  const Eigen::VectorXd Ta0 = T * a0;
  const Eigen::VectorXd T3a0 = T3 * a0;
  const Vec3 ref = problem.reference();
  const double t_max = problem.t_max();
  // First torque row of each wire (rows are wire by wire, in walk order; see ForceProblem).
  std::vector<int> first_row(P + 1, 0);
  {
    int row = 0;
    for (int w = 0; w < P; ++w) {
      first_row[w] = row;
      row += static_cast<int>(walks[w].size()) - (net.wires[w].closed ? 1 : 0);
    }
    first_row[P] = row;
    if (row != T.rows()) throw InputError("load capacity: the cuts differ from those of the force problem");
  }

  // One row per block and round (CutRows::most_violated) unless asked, the cheaper rule here: the
  // design takes only the optimal value λ, which every rule reaches (the coefficients, one optimal
  // point of possibly several, are not written; docs/method-forces.md §15).
  const detail::CutRows cut_rows = options.lp_neighbour_rows ? detail::CutRows::with_neighbours
                                                              : detail::CutRows::most_violated;
  // What every direction reads: solve_direction reads nothing else, so two threads can run it.
  const Shared shared{net, a0, options, K, walks, edges, M, T, T3, polytope, Ma0, Ta0, T3a0, ref, t_max,
                     first_row, cut_rows};

  out.directions.resize(6);
  // Direction 0's report comes first, before the second thread starts: every run reports at least
  // this and the closing 1.0, however the threads share the directions.
  report_progress(progress, "load_capacity", 0.0);
  std::optional<std::thread> worker;
  std::atomic<int> next{0};
  std::atomic<bool> stop{false};
  std::exception_ptr worker_error;
  if (options.threads >= 2) {
    // The second thread takes directions as the calling one does; it never calls `progress` (the
    // caller's callback may need its thread, e.g. Python's GIL held by it) and frees its GLPK
    // environment when done (GLPK keeps one per thread, docs/robustness.md).
    try {
      worker.emplace([&] {
        try {
          for (int d; !stop && (d = next++) < 6;) out.directions[d] = solve_direction(shared, d);
        } catch (...) {
          worker_error = std::current_exception();
          stop = true;
        }
        detail::free_thread_glpk();
      });
    } catch (const std::system_error&) {  // no thread to be had: the calling thread does them all
    }
  }
  try {
    for (int d; !stop && (d = next++) < 6;) {
      if (d > 0) report_progress(progress, "load_capacity", d / 6.0);
      out.directions[d] = solve_direction(shared, d);
    }
  } catch (...) {
    stop = true;
    if (worker) worker->join();
    throw;
  }
  if (worker) worker->join();
  if (worker_error) std::rethrow_exception(worker_error);
  out.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  report_progress(progress, "load_capacity", 1.0);
  return out;
}

}  // namespace wiresculpt
