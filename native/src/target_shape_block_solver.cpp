// The block solver (target_shape_block_solver.hpp).
#include "target_shape_block_solver.hpp"

#include <nlopt.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <exception>
#include <functional>
#include <limits>
#include <optional>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "nlopt_text.hpp"
#include "target_shape_sqp.hpp"
#include "wiresculpt/error.hpp"

namespace wiresculpt::detail {
namespace {

struct SolverData {
  const TargetShapeProblem* problem = nullptr;
  const Block* block = nullptr;
  std::vector<int> var_of;  // point -> first variable index in the current block, -1 otherwise
  double scale_x = 1.0;     // p = scale_x * x
  double scale_f = 1.0;     // f = E / scale_f
  Polyline2 p, grad, cgrad;
  // solve_block's buffers, kept across blocks: the block's variables, the points before it, its
  // start, its answer, and the points before it in the sweep.
  std::vector<double> block_x;
  Polyline2 before, start, after, sweep_before;
  const ProgressFn* progress = nullptr;
  int evaluations = 0;
  int max_evaluations = 1;
  bool cancelled = false;

  // TargetShapeAlgorithm::sqp where NLopt's SLSQP leads a block (slsqp_block stopped): one NLopt run
  // is both the lead-in and the fallback. Before its evaluation lead + 1, `take_over` gets the point
  // NLopt would have returned had it stopped after `lead` evaluations (the best point so far, by
  // SLSQP's own rule in NLopt's slsqp.c) and returns true when the SQP solved the block from there;
  // NLopt is then stopped. Otherwise NLopt goes on exactly as a second run from the block's start
  // would (SLSQP is deterministic), without repeating its first `lead` evaluations.
  struct LeadIn {
    int lead = 0;
    double tol = 0.0;  // the constraints' tolerance (NLopt's feasibility test)
    std::function<bool(const std::vector<double>&)> take_over;
    int evaluations = 0;  // this run's, so far
    bool fired = false, took_over = false;
    std::exception_ptr error;  // what take_over threw (NLopt's wrapper would turn it into a failure)
    std::vector<double> best_x;
    double best_f = std::numeric_limits<double>::infinity(), best_infeasibility = best_f;
    bool best_feasible = false;
    std::vector<double> last_x;  // the evaluation in progress, settled at the next one
    double last_f = 0.0, last_infeasibility = 0.0;
    bool last_feasible = true, pending = false;

    void settle() {  // slsqp.c: "update best point so far"
      if (pending && std::isfinite(last_f) &&
          ((last_f < best_f && (last_feasible || !best_feasible)) || (!best_feasible && last_infeasibility < best_infeasibility))) {
        best_f = last_f;
        best_feasible = last_feasible;
        best_infeasibility = last_infeasibility;
        best_x = last_x;
      }
      pending = false;
    }
    void begin(const double* x, std::size_t n) {
      settle();
      // No finite f in the lead-in (only where the points were not finite): no SQP, SLSQP alone.
      if (!fired && evaluations == lead && !best_x.empty()) {
        fired = true;
        try {
          took_over = take_over(best_x);
        } catch (...) {  // e.g. Cancelled: stop NLopt, the caller throws it again
          error = std::current_exception();
          throw nlopt::forced_stop();
        }
        if (took_over) throw nlopt::forced_stop();
      }
      ++evaluations;
      last_x.assign(x, x + n);
      last_f = std::numeric_limits<double>::quiet_NaN();
      last_infeasibility = 0.0;
      last_feasible = pending = true;
    }
    void constraint(double c) {
      last_infeasibility = last_infeasibility >= c ? last_infeasibility : c;  // slsqp.c's MAX2, NaN included
      last_feasible = last_feasible && c <= tol;
    }
  };
  LeadIn* lead_in = nullptr;

  // Counts one evaluation and polls the progress callback at the first and then every
  // kProgressEvery; false when it asks to cancel.
  bool count_evaluation();

  void unpack(const double* x) {
    for (std::size_t k = 0; k < block->points.size(); ++k) p[block->points[k]] = scale_x * Vec2(x[2 * k], x[2 * k + 1]);
  }
};

// The progress callback is polled at the first evaluation and then every this many: a Python
// callback takes the GIL, and polled at every evaluation (20-100 µs each) it serialised the wires
// that the pipeline solves on two threads. 16 evaluations are at most a few milliseconds.
constexpr int kProgressEvery = 16;

// TargetShapeAlgorithm::sqp: SLSQP evaluations that lead a block where the basin is chosen (10: with
// 5, one of 116 recorded corpus solves ended in another local minimum; with 10 and 20 none did).
// detail::slsqp_block replicates them with our own QP.
constexpr int kSqpBasinEvaluations = 10;
// The result text of a block the SQP solved (TargetShapeResult::nlopt_result).
const std::string kSqpConverged = "SQP_CONVERGED";

bool SolverData::count_evaluation() {
  ++evaluations;
  if (progress && *progress && (evaluations - 1) % kProgressEvery == 0) {
    try {
      report_progress(*progress, "target_shape", std::min(1.0, static_cast<double>(evaluations) / max_evaluations));
    } catch (const Cancelled&) {
      cancelled = true;
      return false;
    }
  }
  return true;
}

double objective(unsigned n, const double* x, double* g, void* data) {
  auto* d = static_cast<SolverData*>(data);
  if (d->lead_in) d->lead_in->begin(x, n);
  if (!d->count_evaluation()) throw nlopt::forced_stop();
  d->unpack(x);
  double f;
  if (!g) {
    f = d->problem->energy_terms(d->p, d->block->terms, nullptr) / d->scale_f;
  } else {
    std::fill(d->grad.begin(), d->grad.end(), Vec2::Zero());
    f = d->problem->energy_terms(d->p, d->block->terms, &d->grad) / d->scale_f;
    const double gs = d->scale_x / d->scale_f;
    for (std::size_t k = 0; k < d->block->points.size(); ++k) {
      g[2 * k] = gs * d->grad[d->block->points[k]].x();
      g[2 * k + 1] = gs * d->grad[d->block->points[k]].y();
    }
  }
  if (d->lead_in) d->lead_in->last_f = f;
  return f;
}

void constraints_fn(unsigned m, double* result, unsigned n, const double* x, double* g, void* data) {
  auto* d = static_cast<SolverData*>(data);
  d->unpack(x);
  const auto& all = d->problem->constraints();
  const int np = static_cast<int>(d->p.size());
  if (g) std::fill(g, g + static_cast<std::size_t>(m) * n, 0.0);
  for (unsigned k = 0; k < m; ++k) {
    const int ck = d->block->constraints[k];
    if (!g) {
      result[k] = d->problem->constraint(ck, d->p);
      if (d->lead_in) d->lead_in->constraint(result[k]);
      continue;
    }
    // A constraint touches at most three points: clear them, evaluate, scatter.
    const auto pts = constraint_points(all[ck], np);
    for (int q : pts)
      if (q >= 0) d->cgrad[q] = Vec2::Zero();
    result[k] = d->problem->constraint(ck, d->p, &d->cgrad);
    if (d->lead_in) d->lead_in->constraint(result[k]);
    double* row = g + static_cast<std::size_t>(k) * n;
    for (int q : pts) {
      if (q < 0 || d->var_of[q] < 0) continue;
      row[d->var_of[q]] = d->scale_x * d->cgrad[q].x();
      row[d->var_of[q] + 1] = d->scale_x * d->cgrad[q].y();
    }
  }
}

nlopt::algorithm nlopt_algorithm(TargetShapeAlgorithm a) {
  switch (a) {
    case TargetShapeAlgorithm::slsqp: return nlopt::LD_SLSQP;
    case TargetShapeAlgorithm::sqp: return nlopt::LD_SLSQP;  // its fallback
    case TargetShapeAlgorithm::auglag_lbfgs: return nlopt::AUGLAG;
    case TargetShapeAlgorithm::ccsaq: return nlopt::LD_CCSAQ;
    case TargetShapeAlgorithm::mma: return nlopt::LD_MMA;
  }
  return nlopt::LD_SLSQP;
}


}  // namespace

struct BlockSolver::Impl {
  const TargetShapeProblem& problem;
  const TargetShapeOptions& o;
  std::function<double()> elapsed;
  TargetShapeResult& result;
  SolverData data;
  std::string worst_result;              // the first failure code of any block
  std::array<int, 2> shift_guess{0, 0};  // sqp: shared by the blocks (SqpSettings::shift_guess)
  SqpWorkspace workspace;                // sqp: the blocks' buffers (SqpSettings::workspace)
  // The block being solved: NLopt for it (set up where it first runs), its variables' answer and
  // energy, NLopt's code, and whether the SQP solved it or NLopt ran.
  std::optional<nlopt::opt> nlopt_opt;
  double f = 0.0;
  nlopt::result r = nlopt::FAILURE;
  bool by_sqp = false, nlopt_ran = false;

  Impl(const TargetShapeProblem& p, const Polyline2& start, const ProgressFn& progress, std::function<double()> clock,
       TargetShapeResult& out)
      : problem(p), o(p.options()), elapsed(std::move(clock)), result(out) {
    const int m = static_cast<int>(start.size());
    data.problem = &problem;
    data.var_of.assign(m, -1);
    data.scale_x = o.min_segment;
    // E_d ≈ Σ 2·spacing·d_i²: this scale makes the energy's curvature across the contour O(1)
    // per point in the scaled variables, which is where SLSQP's initial Hessian guess is I.
    data.scale_f = 2.0 * o.spacing * o.min_segment * o.min_segment;
    data.p = start;
    data.grad.assign(m, Vec2::Zero());
    data.cgrad.assign(m, Vec2::Zero());
    data.progress = &progress;
    data.max_evaluations = o.max_iterations;
  }

  bool out_of_time() const { return elapsed() >= o.max_seconds; }

  // The block's variables from the current points, and the points before it.
  void begin(const Block& b) {
    data.block = &b;
    for (std::size_t k = 0; k < b.points.size(); ++k) data.var_of[b.points[k]] = static_cast<int>(2 * k);
    std::vector<double>& x = data.block_x;  // the buffers are the run's, kept across blocks
    x.assign(2 * b.points.size(), 0.0);
    for (std::size_t k = 0; k < b.points.size(); ++k) {
      x[2 * k] = data.p[b.points[k]].x() / data.scale_x;
      x[2 * k + 1] = data.p[b.points[k]].y() / data.scale_x;
    }
    data.before = data.p;
    nlopt_opt.reset();
    f = 0.0;
    r = nlopt::FAILURE;
    by_sqp = nlopt_ran = false;
  }

  // NLopt for this block, set up where it first runs, inside run_nlopt (the SQP solves most blocks
  // without it), with what is left then of the call's evaluation and wall-clock budgets
  // (max_seconds is shared by every block).
  nlopt::opt& opt(const Block& b) {
    if (nlopt_opt) return *nlopt_opt;
    const unsigned nvar = static_cast<unsigned>(2 * b.points.size());
    nlopt::opt& op = nlopt_opt.emplace(nlopt_algorithm(o.algorithm), nvar);
    if (o.algorithm == TargetShapeAlgorithm::auglag_lbfgs) {
      nlopt::opt local(nlopt::LD_LBFGS, nvar);
      local.set_ftol_rel(o.ftol_rel);
      local.set_xtol_rel(o.xtol_rel);
      local.set_maxeval(o.max_iterations);
      local.set_maxtime(o.max_seconds);
      op.set_local_optimizer(local);
    }
    op.set_min_objective(objective, &data);
    if (!b.constraints.empty())
      op.add_inequality_mconstraint(constraints_fn, &data, std::vector<double>(b.constraints.size(), o.constraint_tol));
    op.set_ftol_rel(o.ftol_rel);
    op.set_xtol_rel(o.xtol_rel);
    op.set_maxeval(std::max(1, o.max_iterations - data.evaluations));
    op.set_maxtime(std::max(1e-3, o.max_seconds - elapsed()));
    return op;
  }

  // NLopt from the block's variables (updated in place), its stops as result codes; a rejected
  // problem is the solver's error.
  nlopt::result run_nlopt(const Block& b) {
    try {
      return opt(b).optimize(data.block_x, f);
    } catch (const nlopt::roundoff_limited&) {
      return nlopt::ROUNDOFF_LIMITED;
    } catch (const nlopt::forced_stop&) {
      return nlopt::FORCED_STOP;
    } catch (const std::invalid_argument& e) {
      throw SolverError("target shape of wire " + o.wire_name + ": NLopt rejected the problem (" + e.what() + ")");
    } catch (const std::bad_alloc&) {
      throw;
    } catch (const std::runtime_error&) {
      return nlopt::FAILURE;
    }
  }

  SqpSettings sqp_settings() {
    SqpSettings ss;
    ss.scale_x = data.scale_x;
    ss.scale_f = data.scale_f;
    ss.min_segment = o.min_segment;
    ss.regularization = o.regularization;
    ss.constraint_tol = o.constraint_tol;
    ss.ftol_rel = o.ftol_rel;
    ss.shift_guess = &shift_guess;
    ss.workspace = &workspace;
    ss.on_evaluation = [this] {
      if (!data.count_evaluation()) throw Cancelled();
    };
    return ss;
  }

  // The SQP's answer (data.start) as the block's variables.
  void finish_by_sqp(const Block& b) {
    for (std::size_t k = 0; k < b.points.size(); ++k) {
      data.block_x[2 * k] = data.start[b.points[k]].x() / data.scale_x;
      data.block_x[2 * k + 1] = data.start[b.points[k]].y() / data.scale_x;
    }
    r = nlopt::SUCCESS;
    by_sqp = true;
  }

  // SQP from the point the lead-in reached (none when it is not finite); true when it converged.
  bool sqp_from(const Block& b, const SqpBlock& sb, const SqpSettings& ss, const std::vector<double>& xp) {
    for (double v : xp)
      if (!std::isfinite(v)) return false;
    for (std::size_t k = 0; k < b.points.size(); ++k) data.start[b.points[k]] = data.scale_x * Vec2(xp[2 * k], xp[2 * k + 1]);
    return sqp_block(problem, sb, data.start, ss).converged;
  }

  // NLopt's SLSQP leads: its run goes on as the fallback where the SQP fails (SolverData::LeadIn).
  void lead_by_nlopt(const Block& b, const SqpBlock& sb, const SqpSettings& ss, int lead) {
    SolverData::LeadIn lead_in;
    lead_in.lead = std::max(1, std::min(lead, o.max_iterations - data.evaluations));
    lead_in.tol = o.constraint_tol;
    lead_in.take_over = [&](const std::vector<double>& xp) { return sqp_from(b, sb, ss, xp); };
    {
      struct Attached {  // the callbacks see the lead-in only during this run
        SolverData& d;
        ~Attached() { d.lead_in = nullptr; }
      } attached{data};
      data.lead_in = &lead_in;
      r = run_nlopt(b);
    }
    if (lead_in.error) std::rethrow_exception(lead_in.error);
    if (data.cancelled) throw Cancelled();
    nlopt_ran = true;
    if (lead_in.took_over) {
      finish_by_sqp(b);
    } else if (!lead_in.fired && sqp_from(b, sb, ss, data.block_x)) {  // NLopt stopped within the lead-in
      finish_by_sqp(b);
    }
  }

  // TargetShapeAlgorithm::sqp: the block by Newton SQP. Where the basin is chosen SLSQP's first
  // kSqpBasinEvaluations evaluations lead the way and SQP finishes from where they got: started
  // cold there, Newton's long steps along the wire (where the energy is flat) reach other local
  // minima (docs/method-target-shape.md). Those evaluations are SLSQP's steps replicated with our
  // QP (slsqp_block, a fraction of the cost of NLopt's dense least-squares subproblem), or NLopt's
  // own where the replica stops. Where SQP fails (the linearised constraints are inconsistent, or
  // its line search stalls) SLSQP solves the block from the block's start, as with algorithm
  // slsqp; where NLopt led, that is its lead-in's own run going on (SolverData::LeadIn), so its
  // first evaluations are not repeated.
  void solve_by_sqp(const Block& b, bool choose_basin) {
    const SqpSettings ss = sqp_settings();
    const SqpBlock sb{&b.points, &b.terms, &b.constraints};
    data.start = data.p;
    const int lead = std::max(1, std::min(kSqpBasinEvaluations, o.max_iterations - data.evaluations));
    // SLSQP's first steps, replicated with our QP (slsqp_block); NLopt's own SLSQP where the
    // replica stops (inconsistent linearised constraints, a value not finite).
    if (choose_basin && slsqp_block(problem, sb, data.start, ss, lead, o.xtol_rel, [this] { return out_of_time(); }).done)
      choose_basin = false;
    if (choose_basin) {
      lead_by_nlopt(b, sb, ss, lead);
    } else if (sqp_block(problem, sb, data.start, ss).converged) {  // from the replica's point or the block's start
      finish_by_sqp(b);
    }
    // The fallback gets what is left of the call's budgets after the lead-in and the SQP (NLopt
    // is set up when it runs; where NLopt led, its run was the fallback: its budget was what was
    // left before its lead-in, after the replica).
    ++result.sqp_blocks;
    if (!by_sqp) ++result.sqp_fallbacks;
  }

  // Keeps the block's answer only if it is no worse than where it started (SLSQP can stop with
  // NLOPT_FAILURE at a poor point, e.g. when its line search fails): less violation, or as
  // feasible and no more energy. False when the answer was not finite.
  bool keep_if_better(const Block& b) {
    const std::vector<double>& x = data.block_x;
    const Polyline2& before = data.before;
    bool finite = true;
    for (double v : x) finite = finite && std::isfinite(v);
    auto merit = [&](const Polyline2& q) {
      double viol = 0.0;
      for (int k : b.constraints) viol = std::max(viol, problem.constraint(k, q));
      return std::make_pair(viol, problem.energy_terms(q, b.terms));
    };
    data.p = before;
    bool moved_at_all = false;
    if (finite) {
      Polyline2& after = data.after;
      after = before;
      for (std::size_t k = 0; k < b.points.size(); ++k) {
        const int q = b.points[k];
        after[q] = data.scale_x * Vec2(x[2 * k], x[2 * k + 1]);
        // bit for bit (-0.0 is not 0.0 here): else the test below decides which of the two is kept
        moved_at_all = moved_at_all || std::memcmp(after[q].data(), before[q].data(), sizeof(Vec2)) != 0;
      }
    }
    // A block that ends where it started, to the bit (about half the windows of a converging
    // sweep), keeps `before` whichever way the test goes: its two merits would be equal.
    if (moved_at_all) {
      const auto [viol0, e0] = merit(before);
      const auto [viol1, e1] = merit(data.after);
      const double tol = o.constraint_tol;
      const bool feasible_and_lower = viol1 <= tol && (viol0 > tol || e1 <= e0 + 1e-14 * std::abs(e0));
      const bool less_infeasible = r > 0 && viol0 > tol && viol1 < viol0;
      if (feasible_and_lower || less_infeasible) data.p = data.after;
    }
    return finite;
  }

  double solve(const Block& b, bool choose_basin) {
    begin(b);
    if (o.algorithm == TargetShapeAlgorithm::sqp) solve_by_sqp(b, choose_basin);
    if (!by_sqp && !nlopt_ran) r = run_nlopt(b);
    if (data.cancelled) throw Cancelled();
    const bool finite = keep_if_better(b);
    double moved = 0.0;
    for (int q : b.points) moved = std::max(moved, (data.p[q] - data.before[q]).norm());
    for (int q : b.points) data.var_of[q] = -1;
    // Keep the first non-success code (a failure in any block is the one worth reporting).
    const std::string text = by_sqp ? kSqpConverged : nlopt_result_text(r);
    if (r < 0 && worst_result.empty()) worst_result = text;
    result.nlopt_result = worst_result.empty() ? text : worst_result;
    if (!finite)
      result.warnings.push_back("the solver diverged on part of wire " + o.wire_name + "; that part keeps its previous shape");
    nlopt_opt.reset();
    return moved;
  }
};

BlockSolver::BlockSolver(const TargetShapeProblem& problem, const Polyline2& start, const ProgressFn& progress,
                         std::function<double()> elapsed, TargetShapeResult& result)
    : impl_(std::make_unique<Impl>(problem, start, progress, std::move(elapsed), result)) {}
BlockSolver::~BlockSolver() = default;
double BlockSolver::solve(const Block& b, bool choose_basin) { return impl_->solve(b, choose_basin); }
const Polyline2& BlockSolver::points() const { return impl_->data.p; }
int BlockSolver::evaluations() const { return impl_->data.evaluations; }
bool BlockSolver::out_of_time() const { return impl_->out_of_time(); }

}  // namespace wiresculpt::detail
