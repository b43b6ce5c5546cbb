#pragma once
// A primal-dual interior-point Newton method for one wire's whole target-shape problem (Sec. 4.3),
// private to the core. Every energy term and constraint couples at most three consecutive points,
// so the Hessian of the Lagrangian is banded (cyclic for closed wires) and one sparse LDLT solve
// per iteration costs O(points). The Hessian is analytic except for the 2×2 Hessian of the IMLS
// distance D at each point and those of the bend and contact constraints, which are central
// differences of their analytic gradients. See docs/method-target-shape.md, "Newton".
#include "wiresculpt/progress.hpp"
#include "wiresculpt/target_shape.hpp"

namespace wiresculpt::detail {

struct NewtonOutcome {
  bool converged = false;  ///< KKT conditions met (first-order optimal, feasible to constraint_tol)
  int iterations = 0;      ///< Newton iterations (one Hessian, one factorisation each)
  int evaluations = 0;     ///< energy evaluations, line-search trials included
  Polyline2 points;        ///< the last iterate (all points, fixed ones unchanged)
};

/// Solves the problem from `start` (all points; fixed ones are kept). Variables are p / scale_x,
/// the objective E / scale_f, as in the SLSQP path. Stops after `max_iterations` Newton
/// iterations without convergence. Polls `progress` (stage "target_shape") every iteration. `mu0`:
/// the first barrier parameter (small when `start` is already close to an optimum).
NewtonOutcome newton_target_shape(const TargetShapeProblem& problem, const Polyline2& start, double scale_x,
                                  double scale_f, double constraint_tol, int max_iterations,
                                  const ProgressFn& progress, double mu0 = 1e-3);

/// Newton's method on the KKT conditions of the constraints active at `start` (c_k > -1e-4, taken
/// as equalities), for a start already near an optimum (SLSQP stopped early): each iteration solves
/// [W Aᵀ; A 0] [dx; λ] = [-∇f; -c] by sparse LU. Converged only when the step and the KKT residual
/// vanish (tolerance constraint_tol), every active multiplier is >= 0 and every other constraint
/// holds: then the point is a KKT point of the inequality problem. Otherwise not converged.
NewtonOutcome polish_target_shape(const TargetShapeProblem& problem, const Polyline2& start, double scale_x,
                                  double scale_f, double constraint_tol, int max_iterations,
                                  const ProgressFn& progress);

}  // namespace wiresculpt::detail
