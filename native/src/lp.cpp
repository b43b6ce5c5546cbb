#include "lp.hpp"

#include <glpk.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>
#include <string>

#include "glpk_guard.hpp"

namespace wiresculpt::detail {

namespace {

// GLPK's numbers: outside these magnitudes its scaling (glp_set_rii / glp_set_sjj) and its
// factorisation fail, so a problem holding one is refused before GLPK sees it
// (docs/robustness.md).
constexpr double kLargest = 1e100, kSmallest = 1e-100;
// Entries below this fraction of their column's largest are rounding noise (solve_lp).
constexpr double kNoise = 1e-13;

int bound_type(double lo, double hi) {
  const bool l = std::isfinite(lo), h = std::isfinite(hi);
  if (l && h) return lo == hi ? GLP_FX : GLP_DB;
  if (l) return GLP_LO;
  if (h) return GLP_UP;
  return GLP_FR;
}

double finite_or_zero(double v) { return std::isfinite(v) ? v : 0.0; }

// A matrix entry that is rounding noise of its column (|a| <= kNoise × the column's largest
// |a|, `col_max`), zero in all but representation: GLPK never sees it (glpk_rows drops it), so
// it is not refused for being below kSmallest either (a plane normal [1e-99, 1, 0] makes entries
// of 9e-101 beside ones of 0.5; they must solve as the zeros of [0, 1, 0] do). Never a number
// that is not finite.
bool is_noise(double v, double col_max) { return std::isfinite(v) && !(std::abs(v) > kNoise * col_max); }

// The first number GLPK cannot take among the triplets from `first_tri` (rounding noise aside,
// is_noise against `col_max`), the objective and column bounds (when `columns`) and the row bounds
// from `first_row`, as a sentence; empty when all are fine. solve_lp checks the whole problem; the cutting-plane rounds only the rows they add.
std::string out_of_range(const LinearProgram& in, std::size_t first_tri, std::size_t first_row, bool columns,
                         const std::vector<double>& col_max) {
  auto bad = [](double v, bool nonzero_entry) {
    if (!std::isfinite(v)) return true;
    const double a = std::abs(v);
    return a > kLargest || (nonzero_entry && a < kSmallest);
  };
  auto say = [](const std::string& what, double v) {
    std::ostringstream s;
    s << what << " is " << v << ", outside the range the LP solver handles (magnitudes 1e-100 to 1e100)";
    return s.str();
  };
  for (std::size_t t = first_tri; t < in.tri_val.size(); ++t)
    if (in.tri_val[t] != 0.0 && !is_noise(in.tri_val[t], col_max[in.tri_col[t]]) && bad(in.tri_val[t], true))
      return say("a coefficient (row " + std::to_string(in.tri_row[t]) + ", column " + std::to_string(in.tri_col[t]) + ")",
                 in.tri_val[t]);
  if (columns)
    for (std::size_t j = 0; j < in.obj.size(); ++j)
      if (bad(in.obj[j], false)) return say("objective coefficient " + std::to_string(j), in.obj[j]);
  auto bound_bad = [&](double v) { return std::isnan(v) || (std::isfinite(v) && bad(v, false)); };
  for (std::size_t r = first_row; r < in.row_lo.size(); ++r)
    if (bound_bad(in.row_lo[r]) || bound_bad(in.row_hi[r]))
      return say("a bound of row " + std::to_string(r), bound_bad(in.row_lo[r]) ? in.row_lo[r] : in.row_hi[r]);
  if (columns)
    for (std::size_t j = 0; j < in.col_lo.size(); ++j)
      if (bound_bad(in.col_lo[j]) || bound_bad(in.col_hi[j]))
        return say("a bound of column " + std::to_string(j), bound_bad(in.col_lo[j]) ? in.col_lo[j] : in.col_hi[j]);
  return {};
}

// The rows [first_row, R) of a problem as GLPK takes them: the triplets from `first_tri` that are
// not rounding noise (|a| > kNoise × the largest |a| of their column, `col_max`), 1-based, in the
// triplets' order (slot 0 unused, as GLPK wants), with the smallest kept |a| of each column
// lowered into `col_min_kept`; and each row's type and finite bounds. A row left empty is free
// when its bounds admit 0 up to rounding; `infeasible` is set when one does not.
struct GlpkRows {
  std::vector<int> row, col;  // 1-based, in triplet order (glp_load_matrix)
  std::vector<double> val;
  std::vector<int> type;
  std::vector<double> lo, hi;
  bool infeasible = false;
};

GlpkRows glpk_rows(const LinearProgram& in, std::size_t first_tri, std::size_t first_row,
                   const std::vector<double>& col_max, std::vector<double>* col_min_kept) {
  const std::size_t R = in.row_lo.size();
  GlpkRows g;
  g.row.push_back(0);
  g.col.push_back(0);
  g.val.push_back(0.0);
  std::vector<char> used(R - first_row, 0);
  for (std::size_t t = first_tri; t < in.tri_val.size(); ++t) {
    const double a = std::abs(in.tri_val[t]);
    if (!(a > kNoise * col_max[in.tri_col[t]])) continue;
    g.row.push_back(in.tri_row[t] + 1);
    g.col.push_back(in.tri_col[t] + 1);
    g.val.push_back(in.tri_val[t]);
    used[in.tri_row[t] - first_row] = 1;
    double& m = (*col_min_kept)[in.tri_col[t]];
    m = std::min(m, a);
  }
  for (std::size_t r = first_row; r < R; ++r) {
    const bool u = used[r - first_row];
    if (!u && (in.row_lo[r] > 1e-9 * (1.0 + std::abs(in.row_lo[r])) ||
               in.row_hi[r] < -1e-9 * (1.0 + std::abs(in.row_hi[r]))))
      g.infeasible = true;
    g.type.push_back(u ? bound_type(in.row_lo[r], in.row_hi[r]) : GLP_FR);
    g.lo.push_back(finite_or_zero(in.row_lo[r]));
    g.hi.push_back(finite_or_zero(in.row_hi[r]));
  }
  return g;
}

// What a guarded GLPK body is given and answers. Bodies run inside run_guarded: only trivially
// destructible locals, nothing that throws.
struct GlpkCall {
  glp_prob* p;
  int dir, cols;  // the direction and every column's count
  // build: every column; extend: the new columns only
  const int* col_type;
  const double *col_lo, *col_hi;
  const double* obj;  // every column
  int set_objective;  // extend: the objective or direction changed, or columns were added
  // build: every row; extend: the new rows
  int rows, entries;
  const int* row_type;
  const double *row_lo, *row_hi;
  const int *ia, *ja;
  const double* ar;
  int new_cols;  // extend
  // answers
  double* x;  // cols entries
  int ret, status, iterations;
  double objective;
};

void read_answer(GlpkCall& q) {
  q.status = glp_get_status(q.p);
  if (q.ret == 0 && q.status == GLP_OPT) {
    for (int j = 0; j < q.cols; ++j) q.x[j] = glp_get_col_prim(q.p, j + 1);
    q.objective = glp_get_obj_val(q.p);
  }
}

// GLPK's simplex has no iteration limit by default, and on a degenerate vertex its primal
// simplex can cycle for ever (a load capacity LP of the globe's hook search did: the solve, and
// Blender with it, hung). Far above what any LP here needs (tens to a few thousand iterations).
int simplex_iteration_limit(int rows, int cols) { return 10000 + 100 * (rows + cols); }

// `ret` of a simplex run with that limit; when it was reached (cycling on a degenerate vertex), the
// code of a run again from a fresh basis with the textbook ratio test and the dual simplex.
int after_cycling(glp_prob* lp, glp_smcp& parm, int ret) {
  if (ret != GLP_EITLIM) return ret;
  parm.r_test = GLP_RT_STD;
  parm.meth = GLP_DUALP;
  glp_adv_basis(lp, 0);
  return glp_simplex(lp, &parm);
}

// A new problem holding everything, scaled, solved with presolve (and without it when the
// presolved solve stopped with an error; again with the textbook ratio test when it cycled).
// Leaves the problem alive in q.p.
void build_body(void* c) {
  GlpkCall& q = *static_cast<GlpkCall*>(c);
  glp_prob* lp = glp_create_prob();
  q.p = lp;
  glp_set_obj_dir(lp, q.dir);
  if (q.rows > 0) glp_add_rows(lp, q.rows);
  if (q.cols > 0) glp_add_cols(lp, q.cols);
  for (int r = 0; r < q.rows; ++r) glp_set_row_bnds(lp, r + 1, q.row_type[r], q.row_lo[r], q.row_hi[r]);
  for (int j = 0; j < q.cols; ++j) {
    glp_set_col_bnds(lp, j + 1, q.col_type[j], q.col_lo[j], q.col_hi[j]);
    glp_set_obj_coef(lp, j + 1, q.obj[j]);
  }
  glp_load_matrix(lp, q.entries, q.ia, q.ja, q.ar);
  glp_scale_prob(lp, GLP_SF_AUTO);
  glp_smcp parm;
  glp_init_smcp(&parm);
  parm.msg_lev = GLP_MSG_OFF;
  parm.presolve = GLP_ON;
  parm.it_lim = simplex_iteration_limit(q.rows, q.cols);
  int ret = glp_simplex(lp, &parm);
  if (ret != 0 && ret != GLP_ENOPFS && ret != GLP_ENODFS) {  // retry without presolve
    parm.presolve = GLP_OFF;
    glp_adv_basis(lp, 0);
    ret = glp_simplex(lp, &parm);
  }
  q.ret = after_cycling(lp, parm, ret);
  q.iterations = glp_get_it_cnt(lp);
  read_answer(q);
}

// Adds q.new_cols columns and q.rows rows (their entries sorted by row, q.ia 1-based row numbers
// of the whole problem) with the new rows' auxiliary variables basic and the new columns
// non-basic, scales the new rows, sets the objective when it changed, and re-solves from the last
// basis: with the dual simplex when only rows were added (the old optimal basis stays dual
// feasible; only the new rows' bounds are violated), else with the primal simplex (the old rows
// are still satisfied; the new objective is not yet optimal).
void extend_body(void* c) {
  GlpkCall& q = *static_cast<GlpkCall*>(c);
  glp_prob* lp = q.p;
  const int before = glp_get_it_cnt(lp);
  if (q.new_cols > 0) {
    const int first = glp_add_cols(lp, q.new_cols);
    for (int j = 0; j < q.new_cols; ++j) glp_set_col_bnds(lp, first + j, q.col_type[j], q.col_lo[j], q.col_hi[j]);
  }
  if (q.set_objective) {
    glp_set_obj_dir(lp, q.dir);
    for (int j = 0; j < q.cols; ++j) glp_set_obj_coef(lp, j + 1, q.obj[j]);
  }
  const int first = q.rows > 0 ? glp_add_rows(lp, q.rows) : 0;  // new rows are basic (GLP_BS)
  int t = 1;
  for (int r = 0; r < q.rows; ++r) {
    const int i = first + r;
    glp_set_row_bnds(lp, i, q.row_type[r], q.row_lo[r], q.row_hi[r]);
    const int start = t;
    double largest = 0.0;
    while (t <= q.entries && q.ia[t] == i) {
      largest = std::max(largest, std::abs(q.ar[t]) * glp_get_sjj(lp, q.ja[t]));
      ++t;
    }
    if (t > start) {
      glp_set_mat_row(lp, i, t - start, q.ja + start - 1, q.ar + start - 1);
      // The row's scale factor as GLPK's equilibration would make it: its largest scaled entry 1,
      // rounded to a power of 2 (no rounding error in the scaling).
      int e = 0;
      std::frexp(1.0 / largest, &e);
      glp_set_rii(lp, i, std::ldexp(1.0, e - 1));
    }
  }
  glp_smcp parm;
  glp_init_smcp(&parm);
  parm.msg_lev = GLP_MSG_OFF;
  parm.presolve = GLP_OFF;
  parm.meth = q.set_objective ? GLP_PRIMAL : GLP_DUALP;
  parm.it_lim = simplex_iteration_limit(glp_get_num_rows(lp), glp_get_num_cols(lp));
  q.ret = after_cycling(lp, parm, glp_simplex(lp, &parm));
  q.iterations = glp_get_it_cnt(lp) - before;
  read_answer(q);
}

void delete_body(void* c) { glp_delete_prob(static_cast<glp_prob*>(c)); }

LpSolution interpret(const GlpkCall& q, std::vector<double>& x) {
  LpSolution out;
  out.iterations = q.iterations;
  if (q.ret == 0 || q.ret == GLP_ENOPFS || q.ret == GLP_ENODFS) {
    if (q.ret == GLP_ENOPFS || q.status == GLP_NOFEAS) out.status = LpSolution::infeasible;
    else if (q.ret == GLP_ENODFS || q.status == GLP_UNBND) out.status = LpSolution::unbounded;
    else if (q.status == GLP_OPT) out.status = LpSolution::optimal;
  }
  if (out.status == LpSolution::optimal) {
    out.x = std::move(x);
    out.objective = q.objective;
  } else if (out.status == LpSolution::failed) {
    out.reason = "GLPK's simplex stopped (code " + std::to_string(q.ret) + ") without a solution";
  }
  return out;
}

}  // namespace

struct HeldLp::State {
  glp_prob* p = nullptr;
  unsigned generation = 0;  // GLPK's environment when `p` was made (glpk_guard.hpp)
  // What of the LinearProgram GLPK holds: rows, triplets, and the columns' bounds and objective.
  std::size_t rows = 0, tris = 0;
  bool maximise = true;
  std::vector<double> obj, col_lo, col_hi;
  std::vector<double> col_max, col_min_kept;  // per column: largest entry, smallest entry kept
  bool alive() const { return p && generation == glpk_generation(); }
  // Records that GLPK now holds `in`, with its per-column largest entries and smallest kept.
  void hold(const LinearProgram& in, std::vector<double> in_col_max, std::vector<double> in_col_min_kept) {
    rows = in.row_lo.size();
    tris = in.tri_val.size();
    maximise = in.maximise;
    obj = in.obj;
    col_lo = in.col_lo;
    col_hi = in.col_hi;
    col_max = std::move(in_col_max);
    col_min_kept = std::move(in_col_min_kept);
  }
  void release() {
    if (alive()) run_guarded(delete_body, p);
    p = nullptr;
  }
};

HeldLp::HeldLp() : s_(std::make_unique<State>()) {}
HeldLp::~HeldLp() { s_->release(); }
bool HeldLp::held() const { return s_->alive(); }

LpSolution HeldLp::build(const LinearProgram& in) {
  State& s = *s_;
  s.release();
  LpSolution out;
  out.builds = 1;
  const int K = static_cast<int>(in.obj.size());
  const int R = static_cast<int>(in.row_lo.size());
  if (in.col_lo.size() != in.obj.size() || in.col_hi.size() != in.obj.size() || in.row_hi.size() != in.row_lo.size() ||
      in.tri_row.size() != in.tri_val.size() || in.tri_col.size() != in.tri_val.size()) {
    out.reason = "the LP's arrays differ in size";
    return out;
  }
  for (std::size_t t = 0; t < in.tri_val.size(); ++t)
    if (in.tri_row[t] < 0 || in.tri_row[t] >= R || in.tri_col[t] < 0 || in.tri_col[t] >= K) {
      out.reason = "a coefficient names row " + std::to_string(in.tri_row[t]) + ", column " +
                   std::to_string(in.tri_col[t]) + ", outside the LP";
      return out;
    }
  // Entries below 1e-13 of their column's largest are rounding noise of cross products (a
  // structural zero computed as 1e-19 would otherwise pin a variable); rows left empty become
  // free when their bounds admit 0 up to rounding, else the LP is infeasible.
  std::vector<double> col_max(K, 0.0), col_min_kept(K, std::numeric_limits<double>::infinity());
  for (std::size_t t = 0; t < in.tri_val.size(); ++t)
    col_max[in.tri_col[t]] = std::max(col_max[in.tri_col[t]], std::abs(in.tri_val[t]));
  out.reason = out_of_range(in, 0, 0, true, col_max);
  if (!out.reason.empty()) return out;
  const GlpkRows g = glpk_rows(in, 0, 0, col_max, &col_min_kept);
  if (g.infeasible) {
    out.status = LpSolution::infeasible;
    return out;
  }
  std::vector<int> col_type(K);
  std::vector<double> col_lo(K), col_hi(K), x(K, 0.0);
  for (int j = 0; j < K; ++j) {
    col_type[j] = bound_type(in.col_lo[j], in.col_hi[j]);
    col_lo[j] = finite_or_zero(in.col_lo[j]);
    col_hi[j] = finite_or_zero(in.col_hi[j]);
  }
  GlpkCall q{nullptr, in.maximise ? GLP_MAX : GLP_MIN, K, col_type.data(), col_lo.data(), col_hi.data(),
             in.obj.data(), 0, R, static_cast<int>(g.val.size()) - 1, g.type.data(), g.lo.data(), g.hi.data(),
             g.row.data(), g.col.data(), g.val.data(), 0, x.data(), 0, 0, 0, 0.0};
  const unsigned generation = glpk_generation();
  if (!run_guarded(build_body, &q)) {  // GLPK's environment (and the problem) is gone
    out.reason = "GLPK stopped with an internal error";
    return out;
  }
  s.p = q.p;
  s.generation = generation;
  s.hold(in, std::move(col_max), std::move(col_min_kept));
  LpSolution sol = interpret(q, x);
  sol.builds = 1;
  return sol;
}

LpSolution HeldLp::extend(const LinearProgram& in) {
  State& s = *s_;
  LpSolution out;
  out.reason = "the LP is not the one GLPK holds grown by rows and columns";
  const std::size_t R = in.row_lo.size(), T = in.tri_val.size(), K = in.obj.size(), K0 = s.obj.size();
  if (!s.alive() || K < K0 || in.col_lo.size() != K || in.col_hi.size() != K || in.row_hi.size() != R || R < s.rows ||
      T < s.tris || in.tri_row.size() != T || in.tri_col.size() != T)
    return out;
  for (std::size_t j = 0; j < K0; ++j)
    if (in.col_lo[j] != s.col_lo[j] || in.col_hi[j] != s.col_hi[j]) return out;
  for (std::size_t t = s.tris; t < T; ++t)
    if (in.tri_row[t] < static_cast<int>(s.rows) || in.tri_row[t] >= static_cast<int>(R) || in.tri_col[t] < 0 ||
        in.tri_col[t] >= static_cast<int>(K) || (t > s.tris && in.tri_row[t] < in.tri_row[t - 1]))
      return out;
  std::vector<double> col_max = s.col_max;
  col_max.resize(K, 0.0);
  for (std::size_t t = s.tris; t < T; ++t)
    col_max[in.tri_col[t]] = std::max(col_max[in.tri_col[t]], std::abs(in.tri_val[t]));
  std::string bad = out_of_range(in, s.tris, s.rows, true, col_max);
  if (!bad.empty()) {
    out.reason = std::move(bad);
    return out;
  }
  for (std::size_t j = 0; j < K0; ++j)
    if (!(s.col_min_kept[j] > kNoise * col_max[j])) return out;  // an entry held would be noise now
  std::vector<double> col_min_kept = s.col_min_kept;
  col_min_kept.resize(K, std::numeric_limits<double>::infinity());
  const GlpkRows g = glpk_rows(in, s.tris, s.rows, col_max, &col_min_kept);
  if (g.infeasible) {
    out.reason.clear();
    out.status = LpSolution::infeasible;
    return out;
  }
  // New columns, and the objective where it changed (the least-out-of-plane LP after the force LP).
  const int new_cols = static_cast<int>(K - K0);
  std::vector<int> col_type(new_cols);
  std::vector<double> col_lo(new_cols), col_hi(new_cols);
  for (int j = 0; j < new_cols; ++j) {
    col_type[j] = bound_type(in.col_lo[K0 + j], in.col_hi[K0 + j]);
    col_lo[j] = finite_or_zero(in.col_lo[K0 + j]);
    col_hi[j] = finite_or_zero(in.col_hi[K0 + j]);
  }
  const bool same_objective = in.maximise == s.maximise && new_cols == 0 && in.obj == s.obj;
  std::vector<double> x(K, 0.0);
  GlpkCall q{s.p, in.maximise ? GLP_MAX : GLP_MIN, static_cast<int>(K), col_type.data(), col_lo.data(),
             col_hi.data(), in.obj.data(), same_objective ? 0 : 1, static_cast<int>(R - s.rows),
             static_cast<int>(g.val.size()) - 1, g.type.data(), g.lo.data(), g.hi.data(), g.row.data(),
             g.col.data(), g.val.data(), new_cols, x.data(), 0, 0, 0, 0.0};
  if (!run_guarded(extend_body, &q)) {
    s.p = nullptr;
    out.reason = "GLPK stopped with an internal error";
    return out;
  }
  s.hold(in, std::move(col_max), std::move(col_min_kept));
  return interpret(q, x);
}


void free_thread_glpk() { free_glpk_environment(); }

void append_rows(LinearProgram& lp, const Eigen::MatrixXd& A, double lo, double hi) {
  for (Eigen::Index i = 0; i < A.rows(); ++i) {
    const int row = static_cast<int>(lp.row_lo.size());
    lp.row_lo.push_back(lo);
    lp.row_hi.push_back(hi);
    for (Eigen::Index j = 0; j < A.cols(); ++j)
      if (A(i, j) != 0.0) {
        lp.tri_row.push_back(row);
        lp.tri_col.push_back(static_cast<int>(j));
        lp.tri_val.push_back(A(i, j));
      }
  }
}

LpSolution solve_lp(const LinearProgram& in) { return HeldLp().build(in); }


LpSolution solve_lp_with_torque_rows(LinearProgram& lp, const TorqueBlocks& blocks, const TorquePolytope& polytope,
                                     double t_max, std::set<std::pair<int, int>>& added, int* rounds, bool warm_start,
                                     HeldLp* keep, CutRows cut_rows) {
  const Eigen::Index V = blocks.A.rows() / 3, cols = blocks.A.cols();
  int iterations = 0, builds = 0, warm = 0;
  HeldLp own;
  HeldLp& held = keep ? *keep : own;
  // |e_k · t| <= |e_k| |t|: a torque shorter than t_max / max_k |e_k| meets every row, so its
  // gauge need not be computed (180 rows a vertex). The factor 1 - 1e-12 keeps this on the safe
  // side of rounding: every vertex it skips is one the gauge would pass, the rows are the same.
  double longest_row2 = 0.0;
  for (const Vec3& e : polytope.rows) longest_row2 = std::max(longest_row2, e.squaredNorm());
  const double inside2 = t_max * t_max * (1.0 - 1e-12) * (1.0 - 1e-12);
  for (;;) {
    LpSolution sol;
    if (warm_start && held.held()) {
      sol = held.extend(lp);
      if (sol.status == LpSolution::optimal) {
        ++warm;
      } else {  // whatever stopped the warm solve, the rebuilt problem answers (never a worse answer)
        iterations += sol.iterations;
        sol = held.build(lp);
        ++builds;
      }
    } else {
      sol = held.build(lp);
      ++builds;
    }
    if (rounds) ++*rounds;
    iterations += sol.iterations;
    sol.iterations = iterations;
    sol.builds = builds;
    sol.warm_solves = warm;
    if (sol.status != LpSolution::optimal) return sol;
    const Eigen::Map<const Eigen::VectorXd> x(sol.x.data(), cols);
    const Eigen::VectorXd t = blocks.A * x + blocks.c;
    bool grew = false;
    auto add = [&](Eigen::Index v, int k) {
      if (!added.insert({static_cast<int>(v), k}).second) return;
      const Eigen::RowVectorXd row = polytope.rows[k].transpose() * blocks.A.middleRows(3 * v, 3);
      const int r = static_cast<int>(lp.row_lo.size());
      for (Eigen::Index j = 0; j < cols; ++j)
        if (row(j) != 0.0) {
          lp.tri_row.push_back(r);
          lp.tri_col.push_back(static_cast<int>(j));
          lp.tri_val.push_back(row(j));
        }
      lp.row_lo.push_back(-std::numeric_limits<double>::infinity());
      lp.row_hi.push_back(t_max - polytope.rows[k].dot(blocks.c.segment<3>(3 * v)));
      grew = true;
    };
    for (Eigen::Index v = 0; v < V; ++v) {
      const Vec3 tv = t.segment<3>(3 * v);
      if (tv.squaredNorm() * longest_row2 < inside2) continue;
      int k = -1;
      if (torque_gauge(polytope, tv, t_max, &k) <= 1.0 + 1e-9) continue;
      // The most violated row, and (CutRows::with_neighbours) those of its neighbours that are
      // violated too: the optimum slides to them next otherwise (docs/method-forces.md §15).
      add(v, k);
      if (cut_rows == CutRows::with_neighbours)
        for (int nb : polytope.neighbours[k])
          if (polytope.rows[nb].dot(tv) > t_max * (1.0 + 1e-9)) add(v, nb);
    }
    if (!grew) return sol;
  }
}


namespace {

// The largest |entry| of each of `cols` columns (an index outside them counts for none).
std::vector<double> column_largest(int cols, const std::vector<int>& tri_col, const std::vector<double>& tri_val) {
  std::vector<double> out(static_cast<std::size_t>(cols), 0.0);
  for (std::size_t t = 0; t < tri_val.size(); ++t)
    if (tri_col[t] >= 0 && tri_col[t] < cols && std::isfinite(tri_val[t]))
      out[static_cast<std::size_t>(tri_col[t])] = std::max(out[static_cast<std::size_t>(tri_col[t])], std::abs(tri_val[t]));
  return out;
}

}  // namespace

struct EqualityLp::State {
  glp_prob* p = nullptr;
  unsigned generation = 0;  // GLPK's environment when `p` was made (glpk_guard.hpp)
  glp_smcp parm;
  std::vector<double> rhs;
  bool alive() const { return generation == glpk_generation(); }
};

namespace {

struct EqualityBuild {
  int rows, cols, entries;
  const int *ia, *ja;
  const double *ar, *cost;
  glp_prob* p;
};

void equality_build_body(void* c) {
  EqualityBuild& q = *static_cast<EqualityBuild*>(c);
  glp_prob* p = glp_create_prob();
  q.p = p;
  glp_set_obj_dir(p, GLP_MIN);
  if (q.rows > 0) glp_add_rows(p, q.rows);
  if (q.cols > 0) glp_add_cols(p, q.cols);
  for (int r = 1; r <= q.rows; ++r) glp_set_row_bnds(p, r, GLP_FX, 0.0, 0.0);
  for (int j = 1; j <= q.cols; ++j) {
    glp_set_col_bnds(p, j, GLP_LO, 0.0, 0.0);
    glp_set_obj_coef(p, j, q.cost[j - 1]);
  }
  glp_load_matrix(p, q.entries, q.ia, q.ja, q.ar);
}

struct EqualitySolve {
  glp_prob* p;
  glp_smcp* parm;
  int rows;
  const int* changed;  // row indices (0-based) whose right-hand side changed
  int changes;
  const double* b;
  int attempts, outcome;  // outcome: 0 feasible, 1 infeasible, 2 failed
};

void equality_solve_body(void* c) {
  EqualitySolve& q = *static_cast<EqualitySolve*>(c);
  for (int k = 0; k < q.changes; ++k) {
    const int r = q.changed[k];
    glp_set_row_bnds(q.p, r + 1, GLP_FX, q.b[r], q.b[r]);
  }
  q.parm->meth = GLP_DUALP;
  q.outcome = 2;
  for (int attempt = 0; attempt < 2; ++attempt) {
    ++q.attempts;
    const int ret = glp_simplex(q.p, q.parm);
    if (ret == 0) {
      const int status = glp_get_status(q.p);
      if (status == GLP_OPT || status == GLP_FEAS) {
        q.outcome = 0;
        return;
      }
      if (status == GLP_NOFEAS || glp_get_prim_stat(q.p) == GLP_NOFEAS) {
        q.outcome = 1;
        return;
      }
    }
    // A singular or ill-conditioned basis: restart from the slack basis with the primal simplex.
    glp_std_basis(q.p);
    q.parm->meth = GLP_PRIMAL;
  }
}

}  // namespace

EqualityLp::EqualityLp(int rows, int cols, const std::vector<int>& tri_row, const std::vector<int>& tri_col,
                       const std::vector<double>& tri_val, const std::vector<double>& cost)
    : s_(std::make_unique<State>()) {
  s_->rhs.assign(static_cast<std::size_t>(std::max(rows, 0)), 0.0);
  std::vector<int> ia{0}, ja{0};
  std::vector<double> ar{0.0};
  bool valid = rows >= 0 && cols >= 0 && cost.size() == static_cast<std::size_t>(cols) &&
               tri_row.size() == tri_val.size() && tri_col.size() == tri_val.size();
  const std::vector<double> col_max = valid ? column_largest(cols, tri_col, tri_val) : std::vector<double>();
  for (std::size_t t = 0; valid && t < tri_val.size(); ++t) {
    const double a = std::abs(tri_val[t]);
    valid = tri_row[t] >= 0 && tri_row[t] < rows && tri_col[t] >= 0 && tri_col[t] < cols && std::isfinite(a) &&
            a <= kLargest;
    if (!valid) break;
    if (a != 0.0 && a < kSmallest && is_noise(a, col_max[tri_col[t]])) continue;  // zero but for rounding: not loaded
    valid = a == 0.0 || a >= kSmallest;
    ia.push_back(tri_row[t] + 1);
    ja.push_back(tri_col[t] + 1);
    ar.push_back(tri_val[t]);
  }
  for (std::size_t j = 0; valid && j < cost.size(); ++j) valid = std::isfinite(cost[j]) && std::abs(cost[j]) <= kLargest;
  if (!valid) return;  // p stays null: every solve is an internal_error
  glp_init_smcp(&s_->parm);
  s_->parm.msg_lev = GLP_MSG_OFF;
  s_->parm.presolve = GLP_OFF;
  s_->parm.pricing = GLP_PT_STD;  // textbook pricing: these LPs are small, steepest edge does not pay
  s_->parm.meth = GLP_DUALP;  // costs >= 0: the slack basis and every optimal basis stay dual feasible
                              // when the right-hand side changes
  s_->parm.it_lim = simplex_iteration_limit(rows, cols);  // cycling ends as a failed solve, not a hang
  EqualityBuild q{rows, cols, static_cast<int>(ar.size()) - 1, ia.data(), ja.data(), ar.data(), cost.data(), nullptr};
  const unsigned generation = glpk_generation();
  if (run_guarded(equality_build_body, &q)) {
    s_->p = q.p;
    s_->generation = generation;
  }
}

EqualityLp::~EqualityLp() {
  if (s_->p && s_->alive()) glp_delete_prob(s_->p);
}

EqualityLp::Outcome EqualityLp::solve(const std::vector<double>& b, int* attempts) {
  State& s = *s_;
  if (!s.p || !s.alive() || b.size() != s.rhs.size()) return Outcome::internal_error;
  std::vector<int> changed;
  for (std::size_t r = 0; r < s.rhs.size(); ++r) {
    if (!std::isfinite(b[r]) || std::abs(b[r]) > kLargest) return Outcome::internal_error;
    if (b[r] != s.rhs[r]) changed.push_back(static_cast<int>(r));
  }
  EqualitySolve q{s.p, &s.parm, static_cast<int>(s.rhs.size()), changed.data(), static_cast<int>(changed.size()),
                  b.data(), 0, 2};
  const bool ran = run_guarded(equality_solve_body, &q);
  if (attempts) *attempts += q.attempts;
  if (!ran || !s.alive()) return Outcome::internal_error;
  for (int r : changed) s.rhs[static_cast<std::size_t>(r)] = b[static_cast<std::size_t>(r)];
  return q.outcome == 0 ? Outcome::feasible : q.outcome == 1 ? Outcome::infeasible : Outcome::failed;
}

}  // namespace wiresculpt::detail
