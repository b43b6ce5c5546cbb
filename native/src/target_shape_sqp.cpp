#include "target_shape_sqp.hpp"

#include "exact/small_triangular.hpp"

#include <Eigen/Cholesky>
#include <Eigen/Dense>
#include <Eigen/QR>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <optional>
#include <vector>

#include <nlopt.h>

namespace wiresculpt::detail {

// ---------------------------------------------------------------------------------------------
// The QP: Goldfarb and Idnani's dual method ("A numerically stable dual method for solving
// strictly convex quadratic programs", Math. Programming 27, 1983), written for small dense
// problems: the active constraints' least-squares step is recomputed by a QR factorisation at
// every change instead of being updated.

bool solve_convex_qp(const Eigen::LLT<Eigen::MatrixXd>& llt, const Eigen::VectorXd& g, const Eigen::MatrixXd& A,
                     const Eigen::VectorXd& c, Eigen::VectorXd& d, Eigen::VectorXd& lambda, QpBuffers& buffers,
                     double tol) {
  const Eigen::Index n = g.size(), m = A.rows();
  const double* L = llt.matrixLLT().data();  // L's lower triangle, column-major (leading dimension n)
  // In Goldfarb-Idnani's form the constraints are n_kᵀ d >= b_k with n_k = -a_k, b_k = c_k;
  // ñ_k = L⁻¹ n_k, so that W⁻¹ = L⁻ᵀ L⁻¹ turns every projection into a Euclidean one.
  // A's rows as contiguous columns, for the scans below; ñ_k (columns of Nt) is computed the
  // first time constraint k enters.
  buffers.At = A.transpose();
  const Eigen::MatrixXd& At = buffers.At;
  Eigen::MatrixXd& Nt = buffers.Nt;
  Nt.resize(n, m);
  std::vector<char>& whitened = buffers.whitened;
  whitened.assign(static_cast<std::size_t>(m), 0);
  d = -g;  // -W⁻¹ g, as llt.solveInPlace(d) gives it (exact/small_triangular.hpp)
  lower_solve_in_place(L, n, n, d.data());
  lower_transpose_solve_in_place(L, n, n, d.data());
  lambda = Eigen::VectorXd::Zero(m);
  std::vector<Eigen::Index>& active = buffers.active;
  active.clear();
  std::vector<double>& u = buffers.u;  // multipliers of `active`
  u.clear();
  std::vector<char>& in = buffers.in;
  in.assign(static_cast<std::size_t>(m), 0);
  ActiveBasis& basis = buffers.basis;
  basis.reset(n);
  Eigen::VectorXd& q = buffers.q;
  Eigen::VectorXd& z = buffers.z;
  q.resize(n), z.resize(n);
  const double scale = 1.0 + g.cwiseAbs().maxCoeff();
  const int max_steps = static_cast<int>(10 * (n + m) + 10);
  int step = 0;
  while (step < max_steps) {
    // The most violated constraint not yet active (A d as one product, whose sums are added in
    // another order than the dot product below: see sp).
    Eigen::Index p = -1;
    double worst = -tol * scale;
    buffers.s.noalias() = A * d;
    for (Eigen::Index k = 0; k < m; ++k) {
      if (in[static_cast<std::size_t>(k)]) continue;
      const double s = -(buffers.s[k] + c[k]);
      if (s < worst) worst = s, p = k;
    }
    if (p < 0) {
      for (std::size_t j = 0; j < active.size(); ++j) lambda[active[j]] = u[j];
      return true;
    }
    if (!whitened[static_cast<std::size_t>(p)]) {
      Nt.col(p) = -At.col(p);
      lower_solve_in_place(L, n, n, Nt.col(p).data());
      whitened[static_cast<std::size_t>(p)] = 1;
    }
    double up = 0.0;
    for (bool first = true; step < max_steps; ++step, first = false) {
      const Eigen::Index na = static_cast<Eigen::Index>(active.size());
      basis.project(Nt.col(p), q);
      const Eigen::VectorXd& r = basis.coefficients();
      const double zn = q.squaredNorm();
      z = q;
      lower_transpose_solve_in_place(L, n, n, z.data());
      // Dual step length: the first active multiplier to reach zero.
      double t1 = std::numeric_limits<double>::infinity();
      Eigen::Index drop = -1;
      for (Eigen::Index j = 0; j < na; ++j)
        if (r[j] > 0.0 && u[static_cast<std::size_t>(j)] / r[j] < t1) t1 = u[static_cast<std::size_t>(j)] / r[j], drop = j;
      // Primal step length: to make constraint p hold. The scan found p violated by worst < 0; the
      // dot product is the value every earlier result was computed with (taking `worst` instead
      // moves a recorded Chair call by 9 mm and changes 85 of 106 scenes, 2 beyond the 0.1 mm
      // tolerance), and where rounding made it disagree in sign with the scan the step would go
      // backwards: then the scan's.
      double sp = -(At.col(p).dot(d) + c[p]);
      if (first && !(sp < 0.0)) sp = worst;
      const bool dependent = na == n || zn <= 1e-14 * std::max(1.0, Nt.col(p).squaredNorm());
      const double t2 = dependent ? std::numeric_limits<double>::infinity() : -sp / zn;
      const double t = std::min(t1, t2);
      if (!std::isfinite(t)) return false;  // the constraints are inconsistent
      if (!dependent) d += t * z;
      for (Eigen::Index j = 0; j < na; ++j) u[static_cast<std::size_t>(j)] -= t * r[j];
      up += t;
      if (t == t2) {  // p holds: it joins the active set
        active.push_back(p);
        u.push_back(up);
        in[static_cast<std::size_t>(p)] = 1;
        basis.add(q);
        ++step;
        break;
      }
      in[static_cast<std::size_t>(active[static_cast<std::size_t>(drop)])] = 0;
      active.erase(active.begin() + drop);
      u.erase(u.begin() + drop);
      basis.rebuild(Nt, active);
    }
  }
  return false;
}

bool solve_convex_qp(const Eigen::LLT<Eigen::MatrixXd>& llt, const Eigen::VectorXd& g, const Eigen::MatrixXd& A,
                     const Eigen::VectorXd& c, Eigen::VectorXd& d, Eigen::VectorXd& lambda, double tol) {
  QpBuffers buffers;
  return solve_convex_qp(llt, g, A, c, d, lambda, buffers, tol);
}

bool solve_convex_qp(const Eigen::MatrixXd& W, const Eigen::VectorXd& g, const Eigen::MatrixXd& A,
                     const Eigen::VectorXd& c, Eigen::VectorXd& d, Eigen::VectorXd& lambda, double tol) {
  if (W.rows() == 0 || !W.allFinite()) return false;
  const Eigen::LLT<Eigen::MatrixXd> llt(W);
  if (llt.info() != Eigen::Success) return false;
  return solve_convex_qp(llt, g, A, c, d, lambda, tol);
}

namespace {

using Mat2 = Eigen::Matrix2d;

class BlockModel {
 public:
  BlockModel(const TargetShapeProblem& problem, const SqpBlock& block, const SqpSettings& s, const Polyline2& p,
             SqpWorkspace& ws)
      : pr_(problem), b_(block), s_(s), m_(static_cast<int>(p.size())), var_(ws.var), grad_(ws.grad),
        scratch_(ws.scratch), work_(ws.work), samples_(ws.samples), hessian_(ws.hessian) {
    samples_.clear();  // the last evaluation with gradients is this model's
    var_.assign(m_, -1);
    for (std::size_t k = 0; k < b_.points->size(); ++k) var_[(*b_.points)[k]] = static_cast<int>(2 * k);
    n_ = static_cast<int>(2 * b_.points->size());
    mc_ = static_cast<int>(b_.constraints->size());
    grad_.assign(m_, Vec2::Zero());
    scratch_.assign(m_, Vec2::Zero());
  }
  int variables() const { return n_; }
  int constraints() const { return mc_; }

  void to_x(const Polyline2& p, Eigen::VectorXd& x) const {
    x.resize(n_);
    for (int i : *b_.points) x[var_[i]] = p[i].x() / s_.scale_x, x[var_[i] + 1] = p[i].y() / s_.scale_x;
  }
  void to_points(const Eigen::VectorXd& x, Polyline2& p) const {
    for (int i : *b_.points) p[i] = s_.scale_x * Vec2(x[var_[i]], x[var_[i] + 1]);
  }

  // f, and (when g) its gradient; constraint values, and (when A) their Jacobian.
  double evaluate(const Polyline2& p, Eigen::VectorXd* g, Eigen::VectorXd& c, Eigen::MatrixXd* A) {
    double f;
    if (g) {
      for (int t : *b_.terms)
        for (int sd : {-1, 0, 1}) grad_[wrap(t + sd)] = Vec2::Zero();
      f = pr_.energy_terms(p, *b_.terms, &grad_, &samples_) / s_.scale_f;
      g->resize(n_);
      const double gs = s_.scale_x / s_.scale_f;
      for (int i : *b_.points) (*g)[var_[i]] = gs * grad_[i].x(), (*g)[var_[i] + 1] = gs * grad_[i].y();
    } else {
      f = pr_.energy_terms(p, *b_.terms) / s_.scale_f;
    }
    c.resize(mc_);
    if (A) A->setZero(mc_, n_);
    const auto& all = pr_.constraints();
    for (int k = 0; k < mc_; ++k) {
      const int ck = (*b_.constraints)[k];
      if (!A) {
        c[k] = pr_.constraint(ck, p);
        continue;
      }
      const auto pts = constraint_points(all[ck], m_);
      for (int q : pts)
        if (q >= 0) scratch_[q] = Vec2::Zero();
      c[k] = pr_.constraint(ck, p, &scratch_);
      for (int q : pts) {
        if (q < 0 || var_[q] < 0) continue;
        (*A)(k, var_[q]) = s_.scale_x * scratch_[q].x();
        (*A)(k, var_[q] + 1) = s_.scale_x * scratch_[q].y();
      }
    }
    return f;
  }

  // The Hessian of f + Σ λ_k c_k over the block's variables, into W.
  void hessian(const Polyline2& p, const Eigen::VectorXd& lambda, Eigen::MatrixXd& W) {
    Eigen::MatrixXd& H = hessian_;
    H.setZero(n_, n_);
    const double hs = s_.scale_x * s_.scale_x / s_.scale_f;
    auto add = [&](int a, int b, const Mat2& B, double scale) {  // B = d²/dp_a dp_b
      if (var_[a] < 0 || var_[b] < 0) return;
      H.block<2, 2>(var_[a], var_[b]) += scale * B;
    };
    const bool closed = pr_.closed();
    // E_d: terms w_i D(p_i), w_i = Σ_j |p_i - p_j| over the neighbours j of i.
    const double step = 1e-7 * s_.min_segment;  // differences of the IMLS gradient
    for (std::size_t k = 0; k < b_.terms->size(); ++k) {
      const int i = (*b_.terms)[k];
      // D and its gradient where the last evaluation with gradients took them (nearly always
      // these very points: the iterate is the trial point evaluated last), else anew.
      Vec2 dD;
      double D;
      if (k < samples_.size() && samples_[k].q == p[i]) {
        D = samples_[k].value;
        dD = samples_[k].gradient;
      } else {
        D = pr_.imls(p[i], &dD);
      }
      Mat2 HD = Mat2::Zero();  // only the (i, i) block needs it
      for (int r = 0; r < 2 && var_[i] >= 0; ++r) {  // forward differences: O(step) is far below what Newton needs
        Vec2 gp, q = p[i];
        q[r] += std::max(step, 1e-12 * std::abs(q[r]));
        const double taken = q[r] - p[i][r];  // the step the coordinate really took
        pr_.imls(q, &gp);
        HD.col(r) = (gp - dD) / taken;
      }
      HD = (0.5 * (HD + HD.transpose())).eval();
      double w = 0.0;
      Mat2 Hii = Mat2::Zero();
      for (int side : {-1, 1}) {
        const int j0 = i + side;
        if (!closed && (j0 < 0 || j0 >= m_)) continue;
        const int j = wrap(j0);
        const Vec2 e = p[i] - p[j];
        const double len = e.norm();
        w += len;
        if (len <= 0.0) continue;
        const Vec2 eh = e / len;
        const Mat2 P = (Mat2::Identity() - eh * eh.transpose()) / len;
        Hii += dD * eh.transpose() + eh * dD.transpose() + D * P;
        const Mat2 Hij = -dD * eh.transpose() - D * P;  // d²/dp_i dp_j
        add(i, j, Hij, hs);
        add(j, i, Hij.transpose(), hs);
        add(j, j, D * P, hs);
      }
      Hii += w * HD;
      add(i, i, Hii, hs);
    }
    // w_r E_r: Σ_i w_r |u_i - (u_a + u_b)/2|², a constant quadratic.
    const double wr = s_.regularization;
    for (int i : *b_.terms) {
      if (wr <= 0.0 || (!closed && (i == 0 || i == m_ - 1))) continue;
      const std::array<int, 3> q{wrap(i - 1), i, wrap(i + 1)};
      const std::array<double, 3> co{-0.5, 1.0, -0.5};
      for (int a = 0; a < 3; ++a)
        for (int b = 0; b < 3; ++b) add(q[a], q[b], Mat2::Identity(), hs * 2.0 * wr * co[a] * co[b]);
    }
    // Constraints: λ_k ∇²c_k (lengths exactly, bends and contacts by central differences).
    const auto& all = pr_.constraints();
    const double lmin2 = s_.min_segment * s_.min_segment;
    const double cs = s_.scale_x * s_.scale_x;
    Polyline2& q = work_;
    q = p;
    for (int k = 0; k < mc_; ++k) {
      const double l = lambda[k];
      if (!(l > 0.0)) continue;
      const int ck = (*b_.constraints)[k];
      const auto pts = constraint_points(all[ck], m_);
      if (all[ck].kind == TargetShapeProblem::Kind::length) {
        const Mat2 B = (-2.0 / lmin2) * Mat2::Identity();
        add(pts[0], pts[0], B, l * cs);
        add(pts[1], pts[1], B, l * cs);
        add(pts[0], pts[1], -B, l * cs);
        add(pts[1], pts[0], -B, l * cs);
        continue;
      }
      const double h = 1e-7 * s_.min_segment;
      std::array<std::array<Vec2, 3>, 6> col{};  // d(∇c)/d(coordinate r of point pts[a])
      for (int a = 0; a < 3; ++a) {
        if (pts[a] < 0 || var_[pts[a]] < 0) continue;
        for (int r = 0; r < 2; ++r) {
          std::array<Vec2, 3> gp{}, gm{};
          for (int sgn : {1, -1}) {
            q[pts[a]][r] = p[pts[a]][r] + sgn * h;
            for (int b = 0; b < 3; ++b)
              if (pts[b] >= 0) scratch_[pts[b]] = Vec2::Zero();
            pr_.constraint(ck, q, &scratch_);
            for (int b = 0; b < 3; ++b)
              if (pts[b] >= 0) (sgn > 0 ? gp : gm)[b] = scratch_[pts[b]];
          }
          q[pts[a]][r] = p[pts[a]][r];
          for (int b = 0; b < 3; ++b) col[2 * a + r][b] = (gp[b] - gm[b]) / (2.0 * h);
        }
      }
      for (int a = 0; a < 3; ++a)
        for (int b = 0; b < 3; ++b) {
          if (pts[a] < 0 || pts[b] < 0 || var_[pts[a]] < 0 || var_[pts[b]] < 0) continue;
          Mat2 B;  // d²c / dp_b dp_a, symmetrised
          for (int r = 0; r < 2; ++r)
            for (int s = 0; s < 2; ++s) B(s, r) = 0.5 * (col[2 * a + r][b][s] + col[2 * b + s][a][r]);
          add(pts[b], pts[a], B, l * cs);
        }
    }
    W = 0.5 * (H + H.transpose());
  }

 private:
  // j from -m to 2m - 1 (a term's neighbours: from -1 to m).
  int wrap(int j) const { return j < 0 ? j + m_ : j >= m_ ? j - m_ : j; }

  const TargetShapeProblem& pr_;
  SqpBlock b_;
  SqpSettings s_;
  int m_;
  int n_ = 0, mc_ = 0;
  // The workspace's buffers.
  std::vector<int>& var_;
  Polyline2 &grad_, &scratch_, &work_;
  std::vector<TargetShapeProblem::ImlsSample>& samples_;  // of the last evaluation with gradients
  Eigen::MatrixXd& hessian_;
};

double violation(const Eigen::VectorXd& c) { return c.size() ? std::max(0.0, c.maxCoeff()) : 0.0; }
double infeasibility(const Eigen::VectorXd& c) { return c.cwiseMax(0.0).sum(); }

// The line search of one sqp_block iteration from x along the QP's step d, on the merit
// f + nu Σ max(0, c_k) (phi0 at x, `slope` its directional derivative), with a second-order
// correction after a rejected full step. True when a point was accepted: then ws.xt, ws.trial,
// `ft`, ws.gt, ws.ct and ws.At are that point's, `alpha` its step length, and ws.mu the
// correction's multipliers where the correction was taken.
template <class Counted>
bool sqp_line_search(BlockModel& model, SqpWorkspace& ws, const Eigen::LLT<Eigen::MatrixXd>& factor,
                     const Eigen::MatrixXd& A, int mc, double nu, double phi0, double slope, Counted&& counted,
                     double& alpha, double& ft) {
  const Eigen::VectorXd &x = ws.x, &g = ws.g, &d = ws.d;
  Eigen::VectorXd &xt = ws.xt, &gt = ws.gt, &ct = ws.ct, &dc = ws.dc, &mc2 = ws.mc2, &csoc = ws.csoc;
  auto merit = [&](double fv, const Eigen::VectorXd& cv) { return fv + nu * infeasibility(cv); };
  for (int ls = 0; ls < 40; ++ls) {
    xt = x + alpha * d;
    model.to_points(xt, ws.trial);
    ft = model.evaluate(ws.trial, &gt, ct, &ws.At);
    counted();
    if (std::isfinite(ft) && merit(ft, ct) <= phi0 + 1e-4 * alpha * slope) return true;
    if (ls == 0 && mc > 0) {
      // Second-order correction (the full step raised the violation of curved active
      // constraints, the Maratos effect): the same QP with the constraints' values at the trial
      // point, linearised about x.
      csoc = ct - A * d;
      if (solve_convex_qp(factor, g, A, csoc, dc, mc2, ws.qp)) {
        xt = x + dc;
        model.to_points(xt, ws.trial);
        ft = model.evaluate(ws.trial, &gt, ct, &ws.At);
        counted();
        if (std::isfinite(ft) && merit(ft, ct) <= phi0 + 1e-4 * slope) {
          ws.mu = mc2;
          return true;
        }
      }
    }
    alpha *= 0.5;
  }
  return false;
}

// NLopt 2.7.1's tests (src/util/stop.c): relative change of f, and of x in the 1-norm.
bool relstop(double old_value, double value, double reltol) {
  const double d = std::abs(value - old_value);
  return d < reltol * (std::abs(value) + std::abs(old_value)) * 0.5 || (reltol > 0.0 && value == old_value);
}
bool xstop(const Eigen::VectorXd& xv, const Eigen::VectorXd& old, double reltol) {
  return (xv - old).lpNorm<1>() < reltol * xv.lpNorm<1>();
}

// Where Kraft's relaxed test fails after the fifth restart (its tolerance is 0 here), NLopt's
// code: the roundoff limit, or at a feasible point its ftol or xtol test ×10 against the start of
// this step (where x and f still are).
int relaxed_stop(bool feasible, double f0, double f, const Eigen::VectorXd& x, const Eigen::VectorXd& x0, double ftol_rel,
                 double xtol_rel) {
  if (!feasible) return NLOPT_ROUNDOFF_LIMITED;
  if (relstop(f0, f, 10.0 * ftol_rel)) return NLOPT_FTOL_REACHED;
  if (xstop(x, x0, 10.0 * xtol_rel)) return NLOPT_XTOL_REACHED;
  return NLOPT_ROUNDOFF_LIMITED;
}

// Kraft's sums, term by term onto `start`: the test function t = f + Σ μ_j max(c_j, 0).
double kraft_penalty(const Eigen::VectorXd& mu, const Eigen::VectorXd& cv, double start) {
  double h = start;
  for (Eigen::Index j = 0; j < mu.size(); ++j) h += mu[j] * std::max(cv[j], 0.0);
  return h;
}

// Powell's damped BFGS update of B with the step s and y = ∇L(x) - ∇L(x0) (y and Bs are buffers).
void powell_update(Eigen::MatrixXd& B, const Eigen::VectorXd& s, Eigen::VectorXd& y, Eigen::VectorXd& Bs) {
  Bs.noalias() = B * s;
  double sy = s.dot(y);
  const double sBs = s.dot(Bs);
  const double damped = sBs * 0.2;
  if (sy < damped) {
    const double theta = (sBs - damped) / (sBs - sy);
    y = theta * y + (1.0 - theta) * Bs;
    sy = damped;
  }
  B.noalias() += (y * y.transpose()) / sy;
  B.noalias() -= (Bs * Bs.transpose()) / sBs;
}

}  // namespace

Eigen::MatrixXd sqp_lagrangian_hessian(const TargetShapeProblem& problem, const SqpBlock& block,
                                       const SqpSettings& settings, const Polyline2& p, const Eigen::VectorXd& lambda,
                                       bool after_evaluation) {
  SqpWorkspace ws;
  BlockModel model(problem, block, settings, p, ws);
  if (after_evaluation) {  // as the SQP does: D and its gradient come from this evaluation
    Eigen::VectorXd g, c;
    Eigen::MatrixXd A;
    model.evaluate(p, &g, c, &A);
  }
  Eigen::MatrixXd W;
  model.hessian(p, lambda, W);
  return W;
}

Eigen::VectorXd sqp_lagrangian_gradient(const TargetShapeProblem& problem, const SqpBlock& block,
                                        const SqpSettings& settings, const Polyline2& p, const Eigen::VectorXd& lambda) {
  SqpWorkspace ws;
  BlockModel model(problem, block, settings, p, ws);
  Eigen::VectorXd g, c;
  Eigen::MatrixXd A;
  model.evaluate(p, &g, c, &A);
  return g + A.transpose() * lambda;
}

// Adds ρ a_k a_kᵀ for every constraint with λ_k > 0, then δI, until W is positive definite;
// `factor` gets its Cholesky factor. False when it cannot be made so (not finite).
//
// The shifts tried form one sequence, in this order: none; ρ = 4^k d_max for k = 0..10 (d_max the
// largest diagonal entry; only when some λ_k > 0); then, with ρ at its last value, δ = 4^j 1e-8 d_max
// for j = 0, 1, ...: 61 shifts at most, and the first that makes W positive definite is taken. Each
// shift adds a positive semidefinite matrix to the one before, so once one succeeds all later ones
// do: the first is found by a search from where the block's previous iteration ended (`guess`)
// instead of one factorisation per shift (a window far from its contour needs a dozen shifts at
// every iteration). The shift taken is the same.
bool convexify(Eigen::MatrixXd& W, const Eigen::MatrixXd& A, const Eigen::VectorXd& lambda,
               Eigen::LLT<Eigen::MatrixXd>& factor, std::array<int, 2>& guess, double* delta_taken,
               ShiftBuffers& buffers) {
  constexpr int kShifts = 61;
  const Eigen::Index n = W.rows();
  Eigen::MatrixXd& AtA = buffers.AtA;
  AtA.setZero(n, n);
  bool any = false;
  for (Eigen::Index k = 0; k < A.rows(); ++k)
    if (lambda[k] > 0.0) {
      AtA.noalias() += A.row(k).transpose() * A.row(k);
      any = true;
    }
  const double dmax = std::max(1e-12, W.diagonal().cwiseAbs().maxCoeff());
  auto shift = [&](int i) -> std::pair<double, double> {  // (ρ, δ) of shift i; ×4 is exact in binary
    if (i == 0) return {0.0, 0.0};
    if (any) {
      if (i <= 11) return {std::ldexp(dmax, 2 * (i - 1)), 0.0};
      return {std::ldexp(dmax, 20), std::ldexp(1e-8 * dmax, 2 * (i - 12))};
    }
    return {0.0, std::ldexp(1e-8 * dmax, 2 * (i - 1))};
  };
  std::array<signed char, kShifts> known{};  // 0 untried, 1 positive definite, -1 not
  // Two slots for the shifted matrix and its factor: a shift that works keeps its slot (the next
  // try goes to the other), so the first definite shift, always the last that worked, need not be
  // factored again after a later try failed.
  std::array<Eigen::MatrixXd, 2>& Wd = buffers.Wd;
  std::array<Eigen::LLT<Eigen::MatrixXd>, 2>& llt = buffers.llt;
  std::array<int, 2> held{-1, -1};  // the shift each slot holds
  int slot = 0;                     // where the next try goes
  auto definite = [&](int i) {
    if (known[i] == 0) {
      const auto [rho, delta] = shift(i);
      Wd[slot] = W;
      if (rho > 0.0) Wd[slot] += rho * AtA;
      Wd[slot].diagonal().array() += delta;
      llt[slot].compute(Wd[slot]);
      held[slot] = i;
      known[i] = llt[slot].info() == Eigen::Success && Wd[slot].allFinite() ? 1 : -1;
      if (known[i] > 0) slot ^= 1;
    }
    return known[i] > 0;
  };
  int& start = guess[any ? 0 : 1];
  int lo = 0, hi = kShifts;  // the first definite shift lies in [lo, hi] (hi: none)
  const int g = std::clamp(start, 0, kShifts - 1);
  if (definite(g)) {
    hi = g;
    for (int step = 1; lo < hi; step *= 2) {  // gallop down
      const int i = std::max(lo, hi - step);
      if (definite(i)) hi = i;
      else { lo = i + 1; break; }
    }
  } else {
    lo = g + 1;
    for (int step = 1; lo < hi; step *= 2) {  // gallop up
      const int i = std::min(kShifts - 1, lo + step - 1);
      if (definite(i)) { hi = i; break; }
      lo = i + 1;
    }
  }
  while (lo < hi) {  // binary search
    const int mid = lo + (hi - lo) / 2;
    if (definite(mid)) hi = mid;
    else lo = mid + 1;
  }
  if (hi >= kShifts) return false;
  const int kept = held[0] == hi ? 0 : 1;  // hi worked after every other success, so it was kept
  start = hi;
  factor = llt[kept];
  W.swap(Wd[kept]);
  if (delta_taken) *delta_taken = shift(hi).second;
  return true;
}

bool convexify(Eigen::MatrixXd& W, const Eigen::MatrixXd& A, const Eigen::VectorXd& lambda,
               Eigen::LLT<Eigen::MatrixXd>& factor, std::array<int, 2>& guess, double* delta_taken) {
  ShiftBuffers buffers;
  return convexify(W, A, lambda, factor, guess, delta_taken, buffers);
}

SqpOutcome sqp_block(const TargetShapeProblem& problem, const SqpBlock& block, Polyline2& p_io,
                     const SqpSettings& settings) {
  SqpOutcome out;
  std::optional<SqpWorkspace> own;
  SqpWorkspace& ws = settings.workspace ? *settings.workspace : own.emplace();
  BlockModel model(problem, block, settings, p_io, ws);
  const int n = model.variables(), mc = model.constraints();
  if (n == 0) {
    out.converged = true;
    return out;
  }
  auto counted = [&] {
    ++out.evaluations;
    if (settings.on_evaluation) settings.on_evaluation();
  };
  // Every buffer below is set before it is read (the workspace's, kept across blocks).
  Polyline2 &p = ws.p, &trial = ws.trial;
  p = p_io, trial = p_io;
  Eigen::VectorXd &x = ws.x, &g = ws.g, &c = ws.c, &ct = ws.ct, &lambda = ws.lambda, &d = ws.d, &mu = ws.mu;
  model.to_x(p, x);
  lambda.setZero(mc);
  Eigen::MatrixXd& A = ws.A;
  double f = model.evaluate(p, &g, c, &A);
  counted();
  double nu = 1.0;  // ℓ1 penalty of the merit function f + ν Σ max(0, c_k)
  Eigen::LLT<Eigen::MatrixXd>& factor = ws.factor;
  Eigen::MatrixXd& W = ws.W;
  QpBuffers& qp = ws.qp;
  ShiftBuffers& shifts = ws.shifts;
  // The line search's buffers (each use sets their contents and sizes).
  Eigen::VectorXd &xt = ws.xt, &gt = ws.gt;
  Eigen::MatrixXd& At = ws.At;
  std::array<int, 2> own_guess{0, 0};
  std::array<int, 2>& shift = settings.shift_guess ? *settings.shift_guess : own_guess;
  for (int it = 0; it < settings.max_iterations; ++it) {
    out.iterations = it + 1;
    // Convexify. The curvature of the contact and bend constraints, weighted by their multipliers,
    // makes the Lagrangian indefinite across the constraints that hold with equality; adding
    // ½ρ (a_k·d)² for each of them (k with λ_k > 0) is constant along a constraint the QP keeps
    // active (a_k·d = -c_k there), so it changes no such solution, and adds ρ a_k a_kᵀ. What is left
    // (far from the contour) gets δI.
    // Eigen's Cholesky accepts NaN, so anything not finite ends here (SLSQP decides).
    if (!std::isfinite(f) || !g.allFinite() || !c.allFinite() || !A.allFinite()) return out;
    model.hessian(p, lambda, W);
    double delta = 0.0;
    if (!W.allFinite() || !convexify(W, A, lambda, factor, shift, &delta, shifts)) return out;
    // Inconsistent linearised constraints (a kink that cannot be opened from here): the caller's
    // SLSQP decides, as it always did.
    if (!solve_convex_qp(factor, g, A, c, d, mu, qp)) return out;
    // At a KKT point the QP's own step vanishes: converged when it is below step_tol at a feasible
    // point (its line search could not tell so small a step from rounding).
    if (violation(c) <= settings.constraint_tol && d.lpNorm<Eigen::Infinity>() <= settings.step_tol) {
      out.converged = true;
      break;
    }
    nu = std::max(nu, 1.5 * (mu.size() ? mu.maxCoeff() : 0.0) + 1e-12);
    const double phi0 = f + nu * infeasibility(c);
    const double slope = g.dot(d) - nu * infeasibility(c);
    // Feasible, and the QP predicts a decrease of at most ftol_rel of f (SLSQP's own test on the
    // energy): nothing is left to gain, and a line search could not tell such a step from
    // rounding.
    if (violation(c) <= settings.constraint_tol && -slope <= settings.ftol_rel * std::abs(f)) {
      out.converged = true;
      break;
    }
    if (!(slope < 0.0)) return out;
    double alpha = 1.0;
    double ft = 0.0;
    // Trial points are evaluated with their gradients: the accepted one (nearly always the first)
    // is the next iterate, whose values the next iteration needs (the same numbers as evaluating it
    // again, one evaluation fewer).
    if (!sqp_line_search(model, ws, factor, A, mc, nu, phi0, slope, counted, alpha, ft)) return out;
    const double step = (xt - x).lpNorm<Eigen::Infinity>();
    x = xt;
    p.swap(trial);
    const double f_old = f;
    f = ft;
    g.swap(gt);
    c.swap(ct);
    A.swap(At);
    lambda = mu;
    // Converged: feasible after a full step (only the QP's own step, or its correction, measures
    // how far x is from a KKT point; one that backtracking shrank to nothing does not) that was
    // negligible, or a Newton step (no δI: a δ-damped one converges only linearly) of at most
    // settle_step, or that changed f by at most ftol_rel of it (SLSQP's own test).
    const bool feasible = violation(c) <= settings.constraint_tol;
    const double settled = delta == 0.0 ? std::max(settings.step_tol, settings.settle_step) : settings.step_tol;
    if (feasible && alpha == 1.0 && (step <= settled || std::abs(f_old - f) <= settings.ftol_rel * std::abs(f))) {
      out.converged = true;
      break;
    }
  }
  if (out.converged) p_io = p;
  return out;
}

SlsqpOutcome slsqp_block(const TargetShapeProblem& problem, const SqpBlock& block, Polyline2& p_io,
                         const SqpSettings& settings, int max_evaluations, double xtol_rel,
                         const std::function<bool()>& out_of_time) {
  SlsqpOutcome out;
  std::optional<SqpWorkspace> own;
  SqpWorkspace& ws = settings.workspace ? *settings.workspace : own.emplace();
  BlockModel model(problem, block, settings, p_io, ws);
  const int n = model.variables(), mc = model.constraints();
  if (n == 0) {
    out.done = true;
    out.result = NLOPT_SUCCESS;
    return out;
  }
  // Every buffer below is set before it is read (the workspace's, kept across blocks; g and A by
  // the first evaluation, which takes the gradients).
  Polyline2& p = ws.p;
  p = p_io;
  Eigen::VectorXd &x = ws.x, &g = ws.g, &c = ws.c, &r = ws.r, &s = ws.s, &mu = ws.mu;
  model.to_x(p, x);
  mu.setZero(mc);
  Eigen::MatrixXd& A = ws.A;
  // NLopt keeps the best point seen: lower f where feasible (or nothing feasible yet), else less
  // infeasible while nothing is feasible.
  Eigen::VectorXd& best_x = ws.best_x;
  best_x = x;
  double best_f = std::numeric_limits<double>::infinity(), best_infeasibility = best_f;
  bool best_feasible = false, feasible = false;
  bool finite = true;
  auto evaluate = [&](bool with_gradient) {
    model.to_points(x, p);
    const double f = with_gradient ? model.evaluate(p, &g, c, &A) : model.evaluate(p, nullptr, c, nullptr);
    ++out.evaluations;
    if (settings.on_evaluation) settings.on_evaluation();
    finite = std::isfinite(f) && c.allFinite() && (!with_gradient || (g.allFinite() && A.allFinite()));
    const double infeasible = violation(c);
    feasible = infeasible <= settings.constraint_tol;
    if (finite && ((f < best_f && (feasible || !best_feasible)) || (!best_feasible && infeasible < best_infeasibility))) {
      best_f = f;
      best_feasible = feasible;
      best_infeasibility = infeasible;
      best_x = x;
    }
    return f;
  };
  auto finish = [&](int result) {
    model.to_points(best_x, p_io);
    out.done = true;
    out.result = result;
    return out;
  };
  // NLopt's stops after an evaluation: the evaluation budget, then the time (0: go on).
  auto budget = [&] {
    if (out.evaluations >= max_evaluations) return static_cast<int>(NLOPT_MAXEVAL_REACHED);
    if (out_of_time && out_of_time()) return static_cast<int>(NLOPT_MAXTIME_REACHED);
    return 0;
  };
  double f = evaluate(true);
  if (!finite) return out;
  if (const int stop = budget()) return finish(stop);
  Eigen::MatrixXd& B = ws.B;
  B.setIdentity(n, n);
  Eigen::LLT<Eigen::MatrixXd>& factor = ws.factor;
  QpBuffers& qp = ws.qp;
  double f_prev = std::numeric_limits<double>::infinity();
  Eigen::VectorXd& x_prev = ws.x_prev;
  x_prev = x;
  // Each iteration's vectors (each use sets their contents and sizes).
  Eigen::VectorXd &v = ws.v, &x0 = ws.x0, &y = ws.y, &Bs = ws.Bs;
  int resets = 1;
  for (;;) {
    factor.compute(B);
    // Kraft's LDLᵀ update keeps B positive definite where this dense one may lose it to rounding:
    // not modelled, NLopt's SLSQP decides.
    if (factor.info() != Eigen::Success) return out;
    // Inconsistent linearised constraints: SLSQP would solve its augmented problem (a slack
    // variable relaxing them), which this replica does not model (written out with our QP, its
    // steps left NLopt's within a few evaluations): the caller runs NLopt's SLSQP instead.
    if (!solve_convex_qp(factor, g, A, c, s, r, qp)) return out;
    v.noalias() = g + A.transpose() * r;  // ∇L at the start of the step
    const double f0 = f;
    x0 = x;
    const double gs = g.dot(s);
    for (int j = 0; j < mc; ++j) mu[j] = std::max(r[j], 0.5 * (mu[j] + r[j]));
    const double h1 = kraft_penalty(mu, c, 0.0);
    const double t0 = f + h1;
    double h3 = gs - h1;
    if (h3 >= 0.0) {  // no descent for the test function: restart from the identity
      if (++resets > 5) return finish(relaxed_stop(feasible, f0, f, x, x0, settings.ftol_rel, xtol_rel));
      B.setIdentity();
      continue;
    }
    double alpha = 1.0;
    int line = 0;
    for (;;) {
      ++line;
      h3 *= alpha;
      s *= alpha;
      x = x0 + s;
      f = evaluate(line == 1);
      if (!finite) return out;
      if (const int stop = budget()) return finish(stop);
      const double dt = kraft_penalty(mu, c, f) - t0;
      if (dt <= h3 / 10.0 || line > 10) break;
      alpha = std::max(h3 / (2.0 * (h3 - dt)), 0.1);
    }
    if (line > 1) {  // NLopt evaluates the accepted point again, with its gradient
      f = evaluate(true);
      if (!finite) return out;
      if (const int stop = budget()) return finish(stop);
    }
    // NLopt 2.7.1 tests after every line search, feasible or not (2.9 added "at a feasible point").
    if (std::isfinite(f_prev)) {
      if (relstop(f_prev, f, settings.ftol_rel)) return finish(NLOPT_FTOL_REACHED);
      if (xstop(x, x_prev, xtol_rel)) return finish(NLOPT_XTOL_REACHED);
    }
    f_prev = f;
    x_prev = x;
    // Powell's damped BFGS update with y = ∇L(x) - ∇L(x0), both with the step's multipliers.
    y.noalias() = g + A.transpose() * r - v;
    powell_update(B, s, y, Bs);
  }
}

}  // namespace wiresculpt::detail
