#pragma once
// A Newton SQP for one block of the target-shape problem (TargetShapeAlgorithm::sqp; see
// docs/method-target-shape.md): the Hessian of the Lagrangian (analytic but for forward
// differences of the IMLS gradient and central ones of the bend and contact gradients), a dense
// convex QP per step solved by the dual active-set method of Goldfarb and Idnani, an ℓ1 merit line
// search with a second-order correction. It reports failure, rather than guessing, where the
// linearised constraints are inconsistent (a kink that cannot be opened), the Lagrangian cannot be
// convexified, a step is no descent, the line search stalls, a value is not finite, or 60
// iterations do not converge: the caller then solves the block with SLSQP from the block's start.

#include <array>
#include <functional>
#include <vector>

#include <Eigen/Cholesky>
#include <Eigen/Core>

#include "wiresculpt/target_shape.hpp"

namespace wiresculpt::detail {

// The active constraints' whitened normals ñ_j (columns of Ñ) as Ñ = U R, U with orthonormal
// columns (modified Gram-Schmidt, twice), R upper triangular: adding a column costs O(n |S|);
// dropping one rebuilds the factorisation of the rest.
class ActiveBasis {
 public:
  // Empties the basis for vectors of n entries (its buffers are kept when their size is).
  void reset(Eigen::Index n) {
    U_.resize(n, n), R_.resize(n, n), w_.resize(n), r_.resize(n), q_.resize(n);
    k_ = 0;
  }
  // The part of v orthogonal to the basis (q) and its coefficients in it (w() = Uᵀ v).
  template <typename V>
  void project(const V& v, Eigen::VectorXd& q) {
    q = v;
    w_.head(k_).setZero();
    for (int pass = 0; pass < 2; ++pass)
      for (Eigen::Index j = 0; j < k_; ++j) {
        const double a = U_.col(j).dot(q);
        q -= a * U_.col(j);
        w_[j] += a;
      }
  }
  // Solves R r = w() (the coefficients of the projected vector in the columns of Ñ).
  const Eigen::VectorXd& coefficients() {
    r_.head(k_) = w_.head(k_);
    if (k_ > 0) R_.topLeftCorner(k_, k_).triangularView<Eigen::Upper>().solveInPlace(r_.head(k_));
    return r_;
  }
  // Adds the vector last projected (q its orthogonal part).
  void add(const Eigen::VectorXd& q) {
    const double nq = q.norm();
    U_.col(k_) = q / nq;
    R_.col(k_).head(k_) = w_.head(k_);
    R_(k_, k_) = nq;
    ++k_;
  }
  // Rebuilds the basis from the given columns of Ñ, in order.
  void rebuild(const Eigen::MatrixXd& Nt, const std::vector<Eigen::Index>& columns) {
    k_ = 0;
    for (Eigen::Index j : columns) {
      project(Nt.col(j), q_);
      add(q_);
    }
  }

 private:
  Eigen::MatrixXd U_, R_;
  Eigen::VectorXd w_, r_, q_;
  Eigen::Index k_ = 0;
};

/// A QP's buffers, kept by an SQP from one iteration to the next (thousands of small QPs): each
/// QP sets their contents, and their sizes where they changed, so a QP solved with them gives what
/// it gives with fresh ones.
struct QpBuffers {
  Eigen::MatrixXd At, Nt;
  std::vector<char> whitened, in;
  std::vector<Eigen::Index> active;
  std::vector<double> u;
  ActiveBasis basis;
  Eigen::VectorXd q, z, s;
};

/// convexify's buffers, kept the same way.
struct ShiftBuffers {
  Eigen::MatrixXd AtA;
  std::array<Eigen::MatrixXd, 2> Wd;
  std::array<Eigen::LLT<Eigen::MatrixXd>, 2> llt;
};

/// The buffers of a block's solve (sqp_block, slsqp_block), kept by a run from one block to the
/// next: a globe solve made about 5,800 allocations, 96 a window, about 4 % of its time. Each use
/// sets their contents, and their sizes where they changed, so a block solved with them gives what
/// it gives with fresh ones. One block at a time.
struct SqpWorkspace {
  // The block model's.
  std::vector<int> var;
  Polyline2 grad, scratch, work;
  std::vector<TargetShapeProblem::ImlsSample> samples;
  Eigen::MatrixXd hessian;
  // The iterations'.
  Polyline2 p, trial;
  Eigen::VectorXd x, g, c, ct, lambda, d, mu, xt, gt, dc, mc2, csoc;
  Eigen::MatrixXd A, At, W;
  Eigen::LLT<Eigen::MatrixXd> factor;
  QpBuffers qp;
  ShiftBuffers shifts;
  // The SLSQP replica's.
  Eigen::VectorXd r, s, best_x, x_prev, v, x0, y, Bs;
  Eigen::MatrixXd B;
};

struct SqpBlock {
  const std::vector<int>* points = nullptr;       ///< free points solved for (2 variables each)
  const std::vector<int>* terms = nullptr;        ///< energy terms they change
  const std::vector<int>* constraints = nullptr;  ///< indices into problem.constraints()
};

struct SqpSettings {
  double scale_x = 1.0;          ///< p = scale_x x
  double scale_f = 1.0;          ///< f = E / scale_f
  double min_segment = 0.015;    ///< metres (the length constraints' l_min)
  double regularization = 1e-3;  ///< w_r
  double constraint_tol = 1e-10;
  double step_tol = 1e-9;        ///< stop when the step is this small (scaled units) and feasible
  /// Also stop after a full Newton step (convexify added no δI) of at most this (scaled units) to
  /// a feasible point, without the QP that would confirm it: Newton's next step there is smaller
  /// still (about the square of this one, which converges quadratically), so the point stops
  /// within about this of where that QP would have ended it (1e-4: 1.5 µm at the default 15 mm
  /// minimum segment; mostly the confirming QP would not have moved it at all), for a seventh
  /// fewer SQP iterations (docs/method-target-shape.md). 0: every step is
  /// confirmed by one more QP (step_tol, ftol_rel).
  double settle_step = 1e-4;
  double ftol_rel = 1e-12;       ///< or when f changed by at most this fraction of it and feasible
  int max_iterations = 60;
  /// Where the search for the convexifying shift starts (with and without active constraints),
  /// updated to where it ended: shared by the blocks of one wire, it saves factorisations and
  /// changes no result (see convexify). Null: each block starts from no shift.
  std::array<int, 2>* shift_guess = nullptr;
  /// Called at every evaluation (it may throw, e.g. Cancelled, which leaves the block unsolved).
  std::function<void()> on_evaluation;
  /// The buffers to solve in (a run's, kept across its blocks). Null: the block's own.
  SqpWorkspace* workspace = nullptr;
};

struct SqpOutcome {
  bool converged = false;
  int evaluations = 0;  ///< energy + constraint evaluations (gradients included)
  int iterations = 0;
};

struct SlsqpOutcome {
  bool done = false;    ///< false: what it does not model (see slsqp_block); `p` is unchanged
  int evaluations = 0;  ///< spent, whether done or not
  int result = 0;       ///< the nlopt_result NLopt's SLSQP would return (NLOPT_FTOL_REACHED, ...)
};

/// SLSQP on one block as NLopt 2.7.1 (the version linked) runs Kraft's algorithm: the identity as the
/// first Hessian guess, Powell's damped BFGS update (reset to the identity when the step is no
/// descent for the test function, at most five times), the ℓ1 test-function line search with its
/// penalty update, and NLopt's stops (ftol_rel and xtol_rel, in the 1-norm, after each line search;
/// the evaluation budget and `out_of_time` after each evaluation; the relaxed test after the fifth
/// reset) and its choice of the best point seen. Only the linear algebra differs: the QP subproblem
/// is solved by solve_convex_qp instead of Kraft's dense least-squares routine (whose cost grows as
/// n² (m + 2n) an iteration), and B is updated as a dense matrix, not as LDLᵀ factors. So the steps
/// are NLopt's to rounding: the same points, evaluation counts and stop codes away from convergence;
/// near it (a warm start) rounding decides where the ftol test fires. It leads sqp_block where a
/// kink's arrangement is chosen. Not done (`p` unchanged) where the linearised constraints are
/// inconsistent (SLSQP's augmented problem is not modelled), B loses positive definiteness to
/// rounding, or a value is not finite: the caller runs NLopt's SLSQP then.
SlsqpOutcome slsqp_block(const TargetShapeProblem& problem, const SqpBlock& block, Polyline2& p,
                         const SqpSettings& settings, int max_evaluations, double xtol_rel,
                         const std::function<bool()>& out_of_time = {});

/// The points constraint `c` of a wire of `np` points reads (-1: none): the edge's two ends
/// (length), the vertex and its neighbours (bend), the crossing and its neighbour (contact).
inline std::array<int, 3> constraint_points(const TargetShapeProblem::Constraint& c, int np) {
  const int before = c.vertex > 0 ? c.vertex - 1 : np - 1, after = c.vertex + 1 < np ? c.vertex + 1 : 0;
  switch (c.kind) {
    case TargetShapeProblem::Kind::length: return {c.vertex, after, -1};
    case TargetShapeProblem::Kind::bend: return {before, c.vertex, after};
    case TargetShapeProblem::Kind::contact: return {c.vertex, c.neighbour, -1};
  }
  return {-1, -1, -1};
}

/// Solves the block from `p` (the whole wire's points; only the block's points change). On
/// success `p` holds the solution; on failure `p` is left as it was.
SqpOutcome sqp_block(const TargetShapeProblem& problem, const SqpBlock& block, Polyline2& p,
                     const SqpSettings& settings);

/// The Hessian of f + Σ λ_k c_k over the block's variables (scaled as the solver sees them: p =
/// scale_x x, f = E / scale_f) at p, before convexification, and that function's gradient: what
/// sqp_block steps with, exposed for its tests. `after_evaluation`: the Hessian as the SQP takes it,
/// right after an evaluation with gradients at p (D and ∇D from that evaluation's samples).
Eigen::MatrixXd sqp_lagrangian_hessian(const TargetShapeProblem& problem, const SqpBlock& block,
                                       const SqpSettings& settings, const Polyline2& p, const Eigen::VectorXd& lambda,
                                       bool after_evaluation = false);
Eigen::VectorXd sqp_lagrangian_gradient(const TargetShapeProblem& problem, const SqpBlock& block,
                                        const SqpSettings& settings, const Polyline2& p, const Eigen::VectorXd& lambda);

/// Makes W positive definite for the QP: adds ρ a_k a_kᵀ over the constraints with λ_k > 0, then
/// δI, taking the first of a fixed sequence of shifts that works (see the definition); `factor`
/// gets W's Cholesky factor. `guess` (with / without active constraints) is where the search
/// starts and is set to where it ended; in exact arithmetic it changes no result (in floating point
/// a factorisation that succeeds at one shift could fail at a much larger one; not seen). False when
/// no shift works. `delta_taken`, when non-null, gets the δ of the shift taken (0: W's curvature is the
/// Lagrangian's along the active constraints, so the step is Newton's). Exposed for its tests.
bool convexify(Eigen::MatrixXd& W, const Eigen::MatrixXd& A, const Eigen::VectorXd& lambda,
               Eigen::LLT<Eigen::MatrixXd>& factor, std::array<int, 2>& guess, double* delta_taken = nullptr);
/// The same with the caller's buffers.
bool convexify(Eigen::MatrixXd& W, const Eigen::MatrixXd& A, const Eigen::VectorXd& lambda,
               Eigen::LLT<Eigen::MatrixXd>& factor, std::array<int, 2>& guess, double* delta_taken,
               ShiftBuffers& buffers);

/// The QP's tolerance on a constraint's violation, relative to 1 + |g|∞.
inline constexpr double kQpTolerance = 1e-12;

/// Minimises ½ dᵀ W d + gᵀ d subject to A d + c <= 0 (rows of A as a dense matrix), W symmetric
/// positive definite: the dual active-set method of Goldfarb and Idnani (1983). Returns false when
/// the constraints are inconsistent (or, never seen, its step budget runs out). `lambda` gets the
/// multipliers (>= 0). Exposed for its tests.
bool solve_convex_qp(const Eigen::LLT<Eigen::MatrixXd>& W_factor, const Eigen::VectorXd& g, const Eigen::MatrixXd& A,
                     const Eigen::VectorXd& c, Eigen::VectorXd& d, Eigen::VectorXd& lambda, double tol = kQpTolerance);
/// The same with the caller's buffers (an SQP's, kept across its QPs).
bool solve_convex_qp(const Eigen::LLT<Eigen::MatrixXd>& W_factor, const Eigen::VectorXd& g, const Eigen::MatrixXd& A,
                     const Eigen::VectorXd& c, Eigen::VectorXd& d, Eigen::VectorXd& lambda, QpBuffers& buffers,
                     double tol = kQpTolerance);
bool solve_convex_qp(const Eigen::MatrixXd& W, const Eigen::VectorXd& g, const Eigen::MatrixXd& A,
                     const Eigen::VectorXd& c, Eigen::VectorXd& d, Eigen::VectorXd& lambda, double tol = kQpTolerance);

}  // namespace wiresculpt::detail
