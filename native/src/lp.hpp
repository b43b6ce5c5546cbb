#pragma once
// The one linear-programming layer of the core, over GLPK (through glpk_guard, the only place
// that runs GLPK's simplex). Private to the core: stability (Eq. 1), forces (Eq. 6-7), the lazy
// torque rows of torque_bound.hpp, the in-plane balance of in_plane.hpp and load capacity all
// state their LPs here. Method notes: docs/method-forces.md (forces, torque rows, load capacity)
// and docs/method-layering.md (stability); GLPK's failure modes: docs/robustness.md.
//
// Two shapes of problem:
//   LinearProgram / solve_lp      one LP, built and solved once (presolve on): in-plane balance;
//                                 solve_lp_with_torque_rows keeps it in GLPK across its rounds and
//                                 re-solves from the last basis after adding rows (dual simplex):
//                                 forces, torque rows, load capacity.
//   EqualityLp                    min c·x subject to A x = b, x >= 0, kept alive between solves
//                                 so that a new right-hand side b restarts from the last basis
//                                 (dual simplex): the stability checks of Eq. 1, which solve one
//                                 system for many unit loads.
#include <Eigen/Core>
#include <memory>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "wiresculpt/torque_bound.hpp"

namespace wiresculpt::detail {

/// A small linear program for GLPK: maximise or minimise obj·x with bounds on columns and on
/// rows r = A x (A given as triplets). ±infinity marks a missing bound.
struct LinearProgram {
  bool maximise = true;
  std::vector<double> obj, col_lo, col_hi, row_lo, row_hi;
  std::vector<int> tri_row, tri_col;
  std::vector<double> tri_val;
};

/// Appends the rows of the dense `A` to `lp`, each with bounds [lo, hi], keeping A's nonzero
/// entries as triplets (A's columns are lp's first columns).
void append_rows(LinearProgram& lp, const Eigen::MatrixXd& A, double lo, double hi);

struct LpSolution {
  enum Status { optimal, infeasible, unbounded, failed } status = failed;
  std::vector<double> x;
  double objective = 0.0;
  int iterations = 0;
  /// GLPK problems built from scratch (presolve on) for this answer: 1 for solve_lp; for
  /// solve_lp_with_torque_rows 1 when every later round was warm-started.
  int builds = 0;
  /// solve_lp_with_torque_rows: rounds re-solved from the previous round's basis (rows added,
  /// dual simplex) and kept (a warm solve that stops short of an optimum is redone by a build).
  int warm_solves = 0;
  /// When `failed`: why, as a clause ("a coefficient (row 3, column 1) is 1e-300, outside the
  /// range the LP solver handles (magnitudes 1e-100 to 1e100)", "GLPK stopped with an internal
  /// error"); empty otherwise.
  std::string reason;
};

/// GLPK simplex (presolve on, terminal output off, errors never abort: they return `failed` with
/// a reason). A number GLPK cannot take (not finite, a magnitude above 1e100, a non-zero matrix
/// entry below 1e-100) or an index outside the LP is refused before GLPK sees it; every GLPK call
/// runs inside glpk_guard's run_guarded. Matrix entries below 1e-13 of their column's largest are
/// dropped as rounding noise.
LpSolution solve_lp(const LinearProgram& lp);

/// A GLPK problem kept alive between solves on the calling thread (every GLPK call guarded, as
/// solve_lp's). build() makes it from a whole LinearProgram, exactly as solve_lp solves it
/// (checks, noise drop, presolve on). extend() takes the same program grown by rows and columns
/// only (the held rows and the held columns' bounds unchanged, each new triplet in a new row, rows
/// in order; the objective and its direction may change) and re-solves from the last basis, the new
/// rows' auxiliary variables basic: the dual simplex when only rows were added, else the primal
/// simplex. It applies solve_lp's checks and noise rule to what is new and returns `failed`,
/// leaving the held problem as it was, when the program is not such a growth of the held one or a
/// held entry would now count as noise (a rebuild answers then). After a GLPK internal error
/// nothing is held. solve_lp_with_torque_rows uses one, and passes it on when given.
class HeldLp {
 public:
  HeldLp();
  ~HeldLp();
  HeldLp(const HeldLp&) = delete;
  HeldLp& operator=(const HeldLp&) = delete;
  bool held() const;
  LpSolution build(const LinearProgram& lp);
  LpSolution extend(const LinearProgram& lp);

 private:
  struct State;
  std::unique_ptr<State> s_;
};

/// Which rows of the polytope a round of solve_lp_with_torque_rows adds per violating block.
enum class CutRows { with_neighbours, most_violated };

/// Torques linear in an LP's columns x: block v (rows 3v..3v+2) is t_v = A_v x + c_v, its
/// components along the wire's n, u, v.
struct TorqueBlocks {
  Eigen::MatrixXd A;
  Eigen::VectorXd c;
};

/// Solves `lp`, then adds to it, for every block whose torque lies outside `polytope` (gauge
/// above 1 + 1e-9), its most violated row e_k·t_v <= t_max (and with CutRows::with_neighbours
/// the violated rows of its neighbours), and solves again until no block is outside: the optimum under every row of the
/// polytope with only the rows that matter in the LP (a cutting-plane loop over a finite row
/// set). `added` holds the (block, row) pairs already in `lp`; `rounds` counts the solves.
/// Returns the last solution (when not optimal, GLPK's status with the rows so far), with the
/// simplex iterations of every solve.
///
/// `warm_start` (default): the first round builds the GLPK problem as solve_lp does (the same
/// input checks, presolve on; or extends `keep`'s); each later round adds only the new rows to it (checked and their
/// noise dropped as solve_lp would, their auxiliary variables basic) and re-solves from the
/// previous optimal basis with the dual simplex, which that basis stays feasible for. A warm solve
/// that does not end optimal, or rows that would change which held entries are noise, fall back
/// to a build of the whole `lp` (presolve on), so the answer is never worse than a rebuild's.
/// false: every round builds from scratch (the behaviour before; tests compare the two).
/// `keep` (optional): the held problem to start from and to leave the last one in, so that a
/// later loop over a grown `lp` starts from this one's optimal basis (the forces' least-out-of-
/// plane LP, which adds rows, columns and a new objective to the force LP).
/// `cut_rows`: with_neighbours (the forces' LPs) adds a block's violated neighbour rows too, a
/// round or two fewer; most_violated (the load capacity) one row per block and round, a third
/// of the rows for GLPK to carry (docs/method-forces.md §15). Both reach the LP's optimal value;
/// where the LP has several optimal points they may end at different ones, which is why the
/// forces, whose point is the design's contact forces, keep the rule they had.
LpSolution solve_lp_with_torque_rows(LinearProgram& lp, const TorqueBlocks& blocks, const TorquePolytope& polytope,
                                     double t_max, std::set<std::pair<int, int>>& added, int* rounds,
                                     bool warm_start = true, HeldLp* keep = nullptr,
                                     CutRows cut_rows = CutRows::with_neighbours);

/// Frees the calling thread's GLPK environment (GLPK keeps one per thread and does not free it
/// when the thread ends, ~5 kB each): a thread started to solve LPs calls this last. Problems
/// still held on the thread are gone after it (EqualityLp::solve then says internal_error).
void free_thread_glpk();

/// min c·x subject to A x = b, x >= 0 (A rows × cols, given as triplets with 0-based indices),
/// kept in GLPK between solves: solve(b) changes only the rows whose b changed and restarts the
/// dual simplex from the last basis (with c >= 0 every basis stays dual feasible when b changes).
class EqualityLp {
 public:
  enum class Outcome {
    feasible,        ///< an optimal (or feasible) x exists
    infeasible,      ///< no x >= 0 with A x = b
    failed,          ///< GLPK failed twice (a singular basis, then again from the slack basis)
    internal_error,  ///< GLPK hit an internal error (its environment, and this problem, is gone), or
                     ///< the problem holds a number GLPK cannot take (see solve_lp)
  };
  EqualityLp(int rows, int cols, const std::vector<int>& tri_row, const std::vector<int>& tri_col,
             const std::vector<double>& tri_val, const std::vector<double>& cost);
  ~EqualityLp();
  EqualityLp(const EqualityLp&) = delete;
  EqualityLp& operator=(const EqualityLp&) = delete;

  /// Solves for right-hand side `b` (one entry per row). A failed attempt restarts once from the
  /// slack basis with the primal simplex. `attempts` (when given) is increased by the simplex
  /// runs made.
  Outcome solve(const std::vector<double>& b, int* attempts = nullptr);

 private:
  struct State;
  std::unique_ptr<State> s_;
};

}  // namespace wiresculpt::detail
