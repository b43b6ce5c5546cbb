#include "target_shape_newton.hpp"

#include <Eigen/SparseCholesky>
#include <Eigen/SparseCore>
#include <Eigen/SparseLU>

#include <algorithm>
#include <cmath>
#include <array>
#include <limits>
#include <vector>

namespace wiresculpt::detail {
namespace {

using Triplet = Eigen::Triplet<double>;
using SparseMatrix = Eigen::SparseMatrix<double>;
using Mat2 = Eigen::Matrix2d;

// One constraint's gradient: up to three points (6 coordinates), in variable indices (-1: fixed).
struct Row {
  std::array<int, 6> var{-1, -1, -1, -1, -1, -1};
  std::array<double, 6> val{};
};

std::array<int, 3> points_of(const TargetShapeProblem::Constraint& c, int m) {
  using Kind = TargetShapeProblem::Kind;
  switch (c.kind) {
    case Kind::length: return {c.vertex, (c.vertex + 1) % m, -1};
    case Kind::bend: return {(c.vertex + m - 1) % m, c.vertex, (c.vertex + 1) % m};
    case Kind::contact: return {c.vertex, c.neighbour, -1};
  }
  return {-1, -1, -1};
}

class Wire {
 public:
  Wire(const TargetShapeProblem& problem, double scale_x, double scale_f)
      : pr_(problem), sx_(scale_x), sf_(scale_f), m_(static_cast<int>(problem.initial().size())) {
    var_.assign(m_, -1);
    for (int i = 0; i < m_; ++i)
      if (!problem.fixed()[i]) var_[i] = 2 * n_free_++;
    scratch_.assign(m_, Vec2::Zero());
  }
  int variables() const { return 2 * n_free_; }
  int constraints() const { return static_cast<int>(pr_.constraints().size()); }
  int var(int point) const { return var_[point]; }

  void to_points(const Eigen::VectorXd& x, Polyline2& p) const {
    for (int i = 0; i < m_; ++i)
      if (var_[i] >= 0) p[i] = sx_ * Vec2(x[var_[i]], x[var_[i] + 1]);
  }
  Eigen::VectorXd to_x(const Polyline2& p) const {
    Eigen::VectorXd x(variables());
    for (int i = 0; i < m_; ++i)
      if (var_[i] >= 0) x[var_[i]] = p[i].x() / sx_, x[var_[i] + 1] = p[i].y() / sx_;
    return x;
  }

  // f = E / scale_f and (when g) its gradient in x.
  double objective(const Polyline2& p, Eigen::VectorXd* g) {
    if (!g) return pr_.energy(p) / sf_;
    grad_.assign(m_, Vec2::Zero());
    const double E = pr_.energy(p, &grad_);
    g->resize(variables());
    const double s = sx_ / sf_;
    for (int i = 0; i < m_; ++i)
      if (var_[i] >= 0) (*g)[var_[i]] = s * grad_[i].x(), (*g)[var_[i] + 1] = s * grad_[i].y();
    return E / sf_;
  }

  // Every constraint's value, and (when rows) its gradient in x.
  void constraint_values(const Polyline2& p, Eigen::VectorXd& c, std::vector<Row>* rows) {
    const auto& all = pr_.constraints();
    c.resize(constraints());
    if (rows) rows->assign(all.size(), Row{});
    for (std::size_t k = 0; k < all.size(); ++k) {
      if (!rows) {
        c[k] = pr_.constraint(k, p);
        continue;
      }
      const auto pts = points_of(all[k], m_);
      for (int q : pts)
        if (q >= 0) scratch_[q] = Vec2::Zero();
      c[k] = pr_.constraint(k, p, &scratch_);
      Row& r = (*rows)[k];
      for (int j = 0; j < 3; ++j) {
        const int q = pts[j];
        if (q < 0 || var_[q] < 0) continue;
        r.var[2 * j] = var_[q], r.var[2 * j + 1] = var_[q] + 1;
        r.val[2 * j] = sx_ * scratch_[q].x(), r.val[2 * j + 1] = sx_ * scratch_[q].y();
      }
    }
  }

  // The Hessian of f + Σ λ_k c_k in x, as triplets (both triangles).
  void lagrangian_hessian(const Polyline2& p, const Eigen::VectorXd& lambda, std::vector<Triplet>& out) {
    const bool closed = pr_.closed();
    const double hs = sx_ * sx_ / sf_;
    auto block = [&](int a, int b, const Mat2& H, double scale) {  // H = d²/dp_a dp_b
      if (var_[a] < 0 || var_[b] < 0) return;
      for (int r = 0; r < 2; ++r)
        for (int s = 0; s < 2; ++s) out.emplace_back(var_[a] + r, var_[b] + s, scale * H(r, s));
    };
    // E_d: terms w_i D(p_i), w_i = Σ_j |p_i - p_j| over the neighbours j of i.
    const double step = 1e-7;  // metres, central differences of the IMLS gradient
    for (int i = 0; i < m_; ++i) {
      Vec2 dD;
      const double D = pr_.imls(p[i], &dD);
      Mat2 HD;
      for (int r = 0; r < 2; ++r) {
        Vec2 gp, gm, q = p[i];
        q[r] += step;
        pr_.imls(q, &gp);
        q[r] -= 2.0 * step;
        pr_.imls(q, &gm);
        HD.col(r) = (gp - gm) / (2.0 * step);
      }
      HD = 0.5 * (HD + HD.transpose()).eval();
      double w = 0.0;
      Mat2 Hii = Mat2::Zero();
      for (int side : {-1, 1}) {
        const int j0 = i + side;
        if (!closed && (j0 < 0 || j0 >= m_)) continue;
        const int j = (j0 + m_) % m_;
        const Vec2 e = p[i] - p[j];
        const double len = e.norm();
        w += len;
        if (len <= 0.0) continue;
        const Vec2 eh = e / len;
        const Mat2 P = (Mat2::Identity() - eh * eh.transpose()) / len;
        Hii += dD * eh.transpose() + eh * dD.transpose() + D * P;
        const Mat2 Hij = -dD * eh.transpose() - D * P;  // d²/dp_i dp_j
        block(i, j, Hij, hs);
        block(j, i, Hij.transpose(), hs);
        block(j, j, D * P, hs);
      }
      Hii += w * HD;
      block(i, i, Hii, hs);
    }
    // w_r E_r: Σ_i w_r |u_i - (u_a + u_b)/2|², a constant quadratic.
    const double wr = pr_.options().regularization;
    for (int i = 0; i < m_ && wr > 0.0; ++i) {
      if (!closed && (i == 0 || i == m_ - 1)) continue;
      const std::array<int, 3> q{(i + m_ - 1) % m_, i, (i + 1) % m_};
      const std::array<double, 3> c{-0.5, 1.0, -0.5};
      for (int a = 0; a < 3; ++a)
        for (int b = 0; b < 3; ++b) block(q[a], q[b], Mat2::Identity(), hs * 2.0 * wr * c[a] * c[b]);
    }
    // Constraints: λ_k ∇²c_k (lengths exactly, bends and contacts by central differences).
    const auto& all = pr_.constraints();
    const double lmin2 = pr_.options().min_segment * pr_.options().min_segment;
    Polyline2 q = p;
    for (std::size_t k = 0; k < all.size(); ++k) {
      const double l = lambda[static_cast<Eigen::Index>(k)];
      if (!(l > 0.0)) continue;
      const auto pts = points_of(all[k], m_);
      if (all[k].kind == TargetShapeProblem::Kind::length) {
        const Mat2 H = (-2.0 / lmin2) * Mat2::Identity();
        block(pts[0], pts[0], H, l * sx_ * sx_);
        block(pts[1], pts[1], H, l * sx_ * sx_);
        block(pts[0], pts[1], -H, l * sx_ * sx_);
        block(pts[1], pts[0], -H, l * sx_ * sx_);
        continue;
      }
      const double h = 1e-7 * pr_.options().min_segment;
      // Columns: d(∇c)/d(coordinate r of point pts[a]).
      std::array<std::array<Vec2, 3>, 6> col{};
      for (int a = 0; a < 3; ++a) {
        if (pts[a] < 0) continue;
        for (int r = 0; r < 2; ++r) {
          std::array<Vec2, 3> gp{}, gm{};
          for (int sgn : {1, -1}) {
            q[pts[a]][r] = p[pts[a]][r] + sgn * h;
            for (int b = 0; b < 3; ++b)
              if (pts[b] >= 0) scratch_[pts[b]] = Vec2::Zero();
            pr_.constraint(k, q, &scratch_);
            for (int b = 0; b < 3; ++b)
              if (pts[b] >= 0) (sgn > 0 ? gp : gm)[b] = scratch_[pts[b]];
          }
          q[pts[a]][r] = p[pts[a]][r];
          for (int b = 0; b < 3; ++b) col[2 * a + r][b] = (gp[b] - gm[b]) / (2.0 * h);
        }
      }
      for (int a = 0; a < 3; ++a)
        for (int b = 0; b < 3; ++b) {
          if (pts[a] < 0 || pts[b] < 0) continue;
          Mat2 H;  // d²c / dp_b dp_a, symmetrised
          for (int r = 0; r < 2; ++r)
            for (int s = 0; s < 2; ++s)
              H(s, r) = 0.5 * (col[2 * a + r][b][s] + col[2 * b + s][a][r]);
          block(pts[b], pts[a], H, l * sx_ * sx_);
        }
    }
  }

 private:
  const TargetShapeProblem& pr_;
  double sx_, sf_;
  int m_;
  int n_free_ = 0;
  std::vector<int> var_;
  Polyline2 grad_, scratch_;
};

Eigen::VectorXd times(const std::vector<Row>& rows, const Eigen::VectorXd& x) {  // A x
  Eigen::VectorXd y(static_cast<Eigen::Index>(rows.size()));
  for (std::size_t k = 0; k < rows.size(); ++k) {
    double v = 0.0;
    for (int j = 0; j < 6; ++j)
      if (rows[k].var[j] >= 0) v += rows[k].val[j] * x[rows[k].var[j]];
    y[static_cast<Eigen::Index>(k)] = v;
  }
  return y;
}

Eigen::VectorXd transposed_times(const std::vector<Row>& rows, const Eigen::VectorXd& y, int n) {  // Aᵀ y
  Eigen::VectorXd x = Eigen::VectorXd::Zero(n);
  for (std::size_t k = 0; k < rows.size(); ++k)
    for (int j = 0; j < 6; ++j)
      if (rows[k].var[j] >= 0) x[rows[k].var[j]] += rows[k].val[j] * y[static_cast<Eigen::Index>(k)];
  return x;
}

}  // namespace

NewtonOutcome newton_target_shape(const TargetShapeProblem& problem, const Polyline2& start, double scale_x,
                                  double scale_f, double constraint_tol, int max_iterations,
                                  const ProgressFn& progress, double mu0) {
  NewtonOutcome out;
  out.points = start;
  Wire wire(problem, scale_x, scale_f);
  const int n = wire.variables(), mc = wire.constraints();
  if (n == 0) {
    out.converged = true;
    return out;
  }
  Polyline2 p = start, trial = start;
  Eigen::VectorXd x = wire.to_x(p), g, c, c_trial;
  std::vector<Row> rows;
  double f = wire.objective(p, &g);
  wire.constraint_values(p, c, &rows);
  ++out.evaluations;

  // Slacks s = -c where the start is strictly feasible, else small; λ = μ / s.
  // μ0 = 1e-3 (tried 1e-2 to 1e-8 on the duck's wires: none was faster or changed which optimum
  // is found everywhere; docs/method-target-shape.md).
  double mu = mu0;
  const double mu_min = 0.1 * constraint_tol, tol = constraint_tol, tau_min = 0.99;
  Eigen::VectorXd s(mc), lambda(mc);
  for (int k = 0; k < mc; ++k) {
    s[k] = std::max(-c[k], 1e-4);
    lambda[k] = mu / s[k];
  }
  double nu = 1.0;  // penalty of the merit function on |c + s|
  double delta = 0.0;
  std::vector<Triplet> triplets;
  Eigen::SimplicialLDLT<SparseMatrix> ldlt;
  SparseMatrix K(n, n);
  auto merit = [&](double fv, const Eigen::VectorXd& cv, const Eigen::VectorXd& sv) {
    double barrier = 0.0, infeasibility = 0.0;
    for (int k = 0; k < mc; ++k) barrier += std::log(sv[k]), infeasibility += std::abs(cv[k] + sv[k]);
    return fv - mu * barrier + nu * infeasibility;
  };

  for (int it = 0; it < max_iterations; ++it) {
    report_progress(progress, "target_shape", std::min(1.0, static_cast<double>(it) / max_iterations));
    out.iterations = it + 1;
    const Eigen::VectorXd rd = g + transposed_times(rows, lambda, n);
    const Eigen::VectorXd rp = c + s;
    const double dual = rd.lpNorm<Eigen::Infinity>();
    const double primal = mc ? rp.lpNorm<Eigen::Infinity>() : 0.0;
    double comp = 0.0, comp_mu = 0.0;
    for (int k = 0; k < mc; ++k) {
      comp = std::max(comp, s[k] * lambda[k]);
      comp_mu = std::max(comp_mu, std::abs(s[k] * lambda[k] - mu));
    }
    double violation = 0.0;
    for (int k = 0; k < mc; ++k) violation = std::max(violation, c[k]);
    if (dual <= 1e-9 && violation <= tol && comp <= tol) {
      out.converged = true;
      break;
    }
    // The barrier problem is solved well enough: lower μ (Fiacco-McCormick, superlinear).
    if (std::max({dual, primal, comp_mu}) <= 10.0 * mu && mu > mu_min) {
      mu = std::max(mu_min, std::min(0.2 * mu, std::pow(mu, 1.5)));
      continue;
    }
    // Newton step on the KKT conditions, reduced to the primal variables:
    //   (W + Aᵀ Σ A) dx = -rd - Aᵀ (Σ rp - λ + μ/s),  Σ = λ / s.
    triplets.clear();
    wire.lagrangian_hessian(p, lambda, triplets);
    Eigen::VectorXd sigma(mc), shift(mc);
    for (int k = 0; k < mc; ++k) {
      sigma[k] = lambda[k] / s[k];
      shift[k] = sigma[k] * rp[k] - lambda[k] + mu / s[k];
    }
    for (int k = 0; k < mc; ++k)
      for (int a = 0; a < 6; ++a)
        for (int b = 0; b < 6; ++b)
          if (rows[k].var[a] >= 0 && rows[k].var[b] >= 0)
            triplets.emplace_back(rows[k].var[a], rows[k].var[b], sigma[k] * rows[k].val[a] * rows[k].val[b]);
    const Eigen::VectorXd rhs = -rd - transposed_times(rows, shift, n);
    Eigen::VectorXd dx;
    // Inertia correction: add δI until the reduced matrix is positive definite.
    for (int tries = 0;; ++tries) {
      std::vector<Triplet> all = triplets;
      for (int i = 0; i < n; ++i) all.emplace_back(i, i, delta);
      K.setFromTriplets(all.begin(), all.end());
      ldlt.compute(K);
      const bool ok = ldlt.info() == Eigen::Success && (ldlt.vectorD().array() > 0.0).all();
      if (ok) {
        dx = ldlt.solve(rhs);
        delta = delta > 0.0 ? std::max(1e-8, delta / 3.0) : 0.0;
        if (delta <= 1e-8) delta = 0.0;
        break;
      }
      if (tries > 40) return out;
      delta = delta > 0.0 ? 8.0 * delta : 1e-4;
    }
    const Eigen::VectorXd Adx = times(rows, dx);
    const Eigen::VectorXd ds = -rp - Adx;
    const Eigen::VectorXd dl = sigma.cwiseProduct(Adx) + shift;
    // Fraction to the boundary.
    const double tau = std::max(tau_min, 1.0 - mu);
    double ap = 1.0, ad = 1.0;
    for (int k = 0; k < mc; ++k) {
      if (ds[k] < 0.0) ap = std::min(ap, -tau * s[k] / ds[k]);
      if (dl[k] < 0.0) ad = std::min(ad, -tau * lambda[k] / dl[k]);
    }
    // Backtracking on the merit f - μ Σ log s + ν |c + s|₁ (ν large enough for descent).
    double gdx = g.dot(dx), barrier_slope = 0.0, infeasibility = 0.0;
    for (int k = 0; k < mc; ++k) barrier_slope += ds[k] / s[k], infeasibility += std::abs(rp[k]);
    const double smooth = gdx - mu * barrier_slope;
    if (infeasibility > 0.0) nu = std::max(nu, (smooth + 1e-12) / (0.5 * infeasibility));
    nu = std::max(nu, (lambda + dl).cwiseAbs().maxCoeff() * 1.1);
    const double slope = smooth - nu * infeasibility;
    const double phi0 = merit(f, c, s);
    double alpha = ap;
    bool accepted = false;
    Eigen::VectorXd xt, st;
    for (int ls = 0; ls < 40; ++ls) {
      xt = x + alpha * dx;
      st = s + alpha * ds;
      wire.to_points(xt, trial);
      const double ft = wire.objective(trial, nullptr);
      wire.constraint_values(trial, c_trial, nullptr);
      ++out.evaluations;
      const double phi = std::isfinite(ft) ? merit(ft, c_trial, st) : std::numeric_limits<double>::infinity();
      if (phi <= phi0 + 1e-4 * alpha * std::min(slope, 0.0) ||
          (std::abs(phi - phi0) <= 1e-15 * std::abs(phi0) && alpha * dx.lpNorm<Eigen::Infinity>() < 1e-13)) {
        accepted = true;
        break;
      }
      if (ls == 0) {
        // Second-order correction (the full step was refused, typically because curved active
        // constraints raise the infeasibility: the Maratos effect): the same factorisation with
        // the constraints' residual at the trial point.
        const Eigen::VectorXd r_soc = alpha * rp + (c_trial + st);
        Eigen::VectorXd shift_soc(mc);
        for (int k = 0; k < mc; ++k) shift_soc[k] = sigma[k] * r_soc[k] - lambda[k] + mu / s[k];
        const Eigen::VectorXd dx_soc = ldlt.solve(-rd - transposed_times(rows, shift_soc, n));
        const Eigen::VectorXd ds_soc = -r_soc - times(rows, dx_soc);
        double a_soc = 1.0;
        for (int k = 0; k < mc; ++k)
          if (ds_soc[k] < 0.0) a_soc = std::min(a_soc, -tau * s[k] / ds_soc[k]);
        xt = x + a_soc * dx_soc;
        st = s + a_soc * ds_soc;
        wire.to_points(xt, trial);
        const double fs = wire.objective(trial, nullptr);
        wire.constraint_values(trial, c_trial, nullptr);
        ++out.evaluations;
        const double phis = std::isfinite(fs) ? merit(fs, c_trial, st) : std::numeric_limits<double>::infinity();
        if (phis <= phi0 + 1e-4 * alpha * std::min(slope, 0.0)) {
          accepted = true;
          break;
        }
      }
      alpha *= 0.5;
    }
    if (!accepted) return out;
    x = xt;
    s = st;
    lambda += ad * dl;
    wire.to_points(x, p);
    f = wire.objective(p, &g);
    wire.constraint_values(p, c, &rows);
    ++out.evaluations;
    out.points = p;
  }
  out.points = p;
  return out;
}

NewtonOutcome polish_target_shape(const TargetShapeProblem& problem, const Polyline2& start, double scale_x,
                                  double scale_f, double constraint_tol, int max_iterations,
                                  const ProgressFn& progress) {
  NewtonOutcome out;
  out.points = start;
  Wire wire(problem, scale_x, scale_f);
  const int n = wire.variables(), mc = wire.constraints();
  if (n == 0) {
    out.converged = true;
    return out;
  }
  Polyline2 p = start;
  Eigen::VectorXd x = wire.to_x(p), g, c;
  std::vector<Row> rows;
  wire.objective(p, &g);
  wire.constraint_values(p, c, &rows);
  ++out.evaluations;
  std::vector<int> active;
  for (int k = 0; k < mc; ++k)
    if (c[k] > -1e-4) active.push_back(k);
  const int na = static_cast<int>(active.size());
  Eigen::VectorXd lambda = Eigen::VectorXd::Zero(mc);
  std::vector<Triplet> triplets;
  Eigen::SparseLU<SparseMatrix> lu;
  SparseMatrix K(n + na, n + na);
  for (int it = 0; it < max_iterations; ++it) {
    report_progress(progress, "target_shape", std::min(1.0, static_cast<double>(it) / max_iterations));
    out.iterations = it + 1;
    triplets.clear();
    wire.lagrangian_hessian(p, lambda, triplets);
    Eigen::VectorXd rhs(n + na);
    rhs.head(n) = -g;
    for (int a = 0; a < na; ++a) {
      const Row& r = rows[active[a]];
      for (int j = 0; j < 6; ++j)
        if (r.var[j] >= 0) {
          triplets.emplace_back(n + a, r.var[j], r.val[j]);
          triplets.emplace_back(r.var[j], n + a, r.val[j]);
        }
      rhs[n + a] = -c[active[a]];
    }
    K.setFromTriplets(triplets.begin(), triplets.end());
    lu.compute(K);
    if (lu.info() != Eigen::Success) return out;
    const Eigen::VectorXd sol = lu.solve(rhs);
    if (lu.info() != Eigen::Success || !sol.allFinite()) return out;
    const Eigen::VectorXd dx = sol.head(n);
    if (dx.lpNorm<Eigen::Infinity>() > 1.0) return out;  // more than l_min: not a polish
    x += dx;
    lambda.setZero();
    for (int a = 0; a < na; ++a) lambda[active[a]] = sol[n + a];
    wire.to_points(x, p);
    wire.objective(p, &g);
    wire.constraint_values(p, c, &rows);
    ++out.evaluations;
    const double dual = (g + transposed_times(rows, lambda, n)).lpNorm<Eigen::Infinity>();
    double primal = 0.0;
    for (int k : active) primal = std::max(primal, std::abs(c[k]));
    if (dx.lpNorm<Eigen::Infinity>() <= 1e-9 && dual <= 1e-9 && primal <= constraint_tol) {
      bool ok = lambda.minCoeff() >= -1e-10;
      for (int k = 0; k < mc; ++k) ok = ok && c[k] <= constraint_tol;
      out.converged = ok;
      if (ok) out.points = p;
      return out;
    }
  }
  return out;
}

}  // namespace wiresculpt::detail
