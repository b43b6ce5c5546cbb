#include "lp.hpp"

#include <glpk.h>

#include <algorithm>
#include <cmath>
#include <limits>

#include "glpk_guard.hpp"

namespace wiresculpt::detail {

LpSolution solve_lp(const LinearProgram& in) {
  LpSolution out;
  const int K = static_cast<int>(in.obj.size());
  const int R = static_cast<int>(in.row_lo.size());
  auto bound_type = [](double lo, double hi) {
    const bool l = std::isfinite(lo), h = std::isfinite(hi);
    if (l && h) return lo == hi ? GLP_FX : GLP_DB;
    if (l) return GLP_LO;
    if (h) return GLP_UP;
    return GLP_FR;
  };
  // Entries below 1e-13 of their column's largest are rounding noise of cross products (a
  // structural zero computed as 1e-19 would otherwise pin a variable); rows left empty become
  // free when their bounds admit 0 up to rounding, else the LP is infeasible.
  std::vector<double> col_max(K, 0.0);
  for (std::size_t t = 0; t < in.tri_val.size(); ++t)
    col_max[in.tri_col[t]] = std::max(col_max[in.tri_col[t]], std::abs(in.tri_val[t]));
  std::vector<int> ia{0}, ja{0};
  std::vector<double> ar{0.0};
  std::vector<char> row_used(R, 0);
  for (std::size_t t = 0; t < in.tri_val.size(); ++t) {
    if (!(std::abs(in.tri_val[t]) > 1e-13 * col_max[in.tri_col[t]])) continue;
    ia.push_back(in.tri_row[t] + 1);
    ja.push_back(in.tri_col[t] + 1);
    ar.push_back(in.tri_val[t]);
    row_used[in.tri_row[t]] = 1;
  }
  for (int r = 0; r < R; ++r)
    if (!row_used[r] && (in.row_lo[r] > 1e-9 * (1.0 + std::abs(in.row_lo[r])) ||
                         in.row_hi[r] < -1e-9 * (1.0 + std::abs(in.row_hi[r])))) {
      out.status = LpSolution::infeasible;
      return out;
    }
  glp_prob* lp = glp_create_prob();
  glp_set_obj_dir(lp, in.maximise ? GLP_MAX : GLP_MIN);
  if (R > 0) glp_add_rows(lp, R);
  if (K > 0) glp_add_cols(lp, K);
  for (int r = 0; r < R; ++r)
    glp_set_row_bnds(lp, r + 1, row_used[r] ? bound_type(in.row_lo[r], in.row_hi[r]) : GLP_FR, std::isfinite(in.row_lo[r]) ? in.row_lo[r] : 0.0,
                     std::isfinite(in.row_hi[r]) ? in.row_hi[r] : 0.0);
  for (int j = 0; j < K; ++j) {
    glp_set_col_bnds(lp, j + 1, bound_type(in.col_lo[j], in.col_hi[j]), std::isfinite(in.col_lo[j]) ? in.col_lo[j] : 0.0,
                     std::isfinite(in.col_hi[j]) ? in.col_hi[j] : 0.0);
    glp_set_obj_coef(lp, j + 1, in.obj[j]);
  }
  glp_load_matrix(lp, static_cast<int>(ar.size()) - 1, ia.data(), ja.data(), ar.data());
  glp_scale_prob(lp, GLP_SF_AUTO);
  glp_smcp parm;
  glp_init_smcp(&parm);
  parm.msg_lev = GLP_MSG_OFF;
  parm.presolve = GLP_ON;
  int ret = guarded_simplex(lp, &parm);
  if (ret == -1) {  // GLPK's environment (and with it `lp`) is gone
    out.status = LpSolution::failed;
    return out;
  }
  if (ret != 0 && ret != GLP_ENOPFS && ret != GLP_ENODFS) {  // retry without presolve
    parm.presolve = GLP_OFF;
    glp_adv_basis(lp, 0);
    ret = guarded_simplex(lp, &parm);
    if (ret == -1) {
      out.status = LpSolution::failed;
      return out;
    }
  }
  if (ret == 0 || ret == GLP_ENOPFS || ret == GLP_ENODFS) {
    const int status = glp_get_status(lp);
    if (ret == GLP_ENOPFS || status == GLP_NOFEAS) out.status = LpSolution::infeasible;
    else if (ret == GLP_ENODFS || status == GLP_UNBND) out.status = LpSolution::unbounded;
    else if (status == GLP_OPT) out.status = LpSolution::optimal;
    else out.status = LpSolution::failed;
  }
  if (out.status == LpSolution::optimal) {
    out.x.resize(K);
    for (int j = 0; j < K; ++j) out.x[j] = glp_get_col_prim(lp, j + 1);
    out.objective = glp_get_obj_val(lp);
  }
  out.iterations = glp_get_it_cnt(lp);
  glp_delete_prob(lp);
  return out;
}


LpSolution solve_lp_with_torque_rows(LinearProgram& lp, const TorqueBlocks& blocks, const TorquePolytope& polytope,
                                     double t_max, std::set<std::pair<int, int>>& added, int* rounds) {
  const Eigen::Index V = blocks.A.rows() / 3, cols = blocks.A.cols();
  int iterations = 0;
  for (;;) {
    LpSolution sol = solve_lp(lp);
    if (rounds) ++*rounds;
    iterations += sol.iterations;
    sol.iterations = iterations;
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
      int k = -1;
      if (torque_gauge(polytope, tv, t_max, &k) <= 1.0 + 1e-9) continue;
      // The most violated row, and those of its neighbours that are violated too (the optimum
      // slides to them next otherwise).
      add(v, k);
      for (int nb : polytope.neighbours[k])
        if (polytope.rows[nb].dot(tv) > t_max * (1.0 + 1e-9)) add(v, nb);
    }
    if (!grew) return sol;
  }
}


struct EqualityLp::State {
  glp_prob* p = nullptr;
  unsigned generation = 0;  // GLPK's environment when `p` was made (glpk_guard.hpp)
  glp_smcp parm;
  std::vector<double> rhs;
  bool alive() const { return generation == glpk_generation(); }
};

EqualityLp::EqualityLp(int rows, int cols, const std::vector<int>& tri_row, const std::vector<int>& tri_col,
                       const std::vector<double>& tri_val, const std::vector<double>& cost)
    : s_(std::make_unique<State>()) {
  configure_glpk();
  s_->p = glp_create_prob();
  s_->generation = glpk_generation();
  s_->rhs.assign(rows, 0.0);
  glp_prob* p = s_->p;
  glp_set_obj_dir(p, GLP_MIN);
  glp_add_rows(p, rows);
  glp_add_cols(p, cols);
  for (int r = 1; r <= rows; ++r) glp_set_row_bnds(p, r, GLP_FX, 0.0, 0.0);
  for (int j = 1; j <= cols; ++j) {
    glp_set_col_bnds(p, j, GLP_LO, 0.0, 0.0);
    glp_set_obj_coef(p, j, cost[j - 1]);
  }
  std::vector<int> ia{0}, ja{0};
  std::vector<double> ar{0.0};
  for (std::size_t t = 0; t < tri_val.size(); ++t) {
    ia.push_back(tri_row[t] + 1);
    ja.push_back(tri_col[t] + 1);
    ar.push_back(tri_val[t]);
  }
  glp_load_matrix(p, static_cast<int>(ar.size()) - 1, ia.data(), ja.data(), ar.data());
  glp_init_smcp(&s_->parm);
  s_->parm.msg_lev = GLP_MSG_OFF;
  s_->parm.presolve = GLP_OFF;
  s_->parm.pricing = GLP_PT_STD;  // textbook pricing: these LPs are small, steepest edge does not pay
  s_->parm.meth = GLP_DUALP;  // costs >= 0: the slack basis and every optimal basis stay dual feasible
                              // when the right-hand side changes
}

EqualityLp::~EqualityLp() {
  if (s_->p && s_->alive()) glp_delete_prob(s_->p);
}

EqualityLp::Outcome EqualityLp::solve(const std::vector<double>& b, int* attempts) {
  State& s = *s_;
  if (!s.alive()) return Outcome::internal_error;
  s.parm.meth = GLP_DUALP;
  for (std::size_t r = 0; r < s.rhs.size(); ++r)
    if (b[r] != s.rhs[r]) {
      glp_set_row_bnds(s.p, static_cast<int>(r) + 1, GLP_FX, b[r], b[r]);
      s.rhs[r] = b[r];
    }
  for (int attempt = 0; attempt < 2; ++attempt) {
    if (attempts) ++*attempts;
    const int ret = guarded_simplex(s.p, &s.parm);
    if (ret == -1 || !s.alive()) return Outcome::internal_error;
    if (ret == 0) {
      const int status = glp_get_status(s.p);
      if (status == GLP_OPT || status == GLP_FEAS) return Outcome::feasible;
      if (status == GLP_NOFEAS || glp_get_prim_stat(s.p) == GLP_NOFEAS) return Outcome::infeasible;
    }
    // A singular or ill-conditioned basis: restart from the slack basis with the primal simplex.
    glp_std_basis(s.p);
    s.parm.meth = GLP_PRIMAL;
  }
  return Outcome::failed;
}

}  // namespace wiresculpt::detail
