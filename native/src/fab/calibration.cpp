#include "wiresculpt/fab/calibration.hpp"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <map>
#include <numbers>
#include <sstream>
#include <string>
#include <utility>

#include "wiresculpt/error.hpp"
#include "wiresculpt/rest_shape.hpp"

namespace wiresculpt::fab {
namespace {

std::string at_line(int line) { return line > 0 ? "line " + std::to_string(line) + ": " : ""; }

std::string num(double x, int precision = 4) {
  std::ostringstream o;
  o.precision(precision);
  o << x;
  return o.str();
}

std::string grams(double kg) { return num(kg * 1000.0, 6) + " g"; }

double cross2(const Vec2& a, const Vec2& b) { return a.x() * b.y() - a.y() * b.x(); }

/// A frame's smoothed shape: w(s) = Σ_{k=2..} c_k (s/L)^k, with its positions on a fine grid.
struct Smoothed {
  std::vector<double> c;  // coefficients of u^2, u^3, ...
  double L = 0.0;
  std::vector<double> fine_s;
  Polyline2 fine;  // positions (y up) at fine_s
  double rss = 0.0;       // residual sum of squares of the polynomial fit, m²
  int dof = 0;            // marks - coefficients
  Eigen::MatrixXd cov;    // (AᵀA)⁻¹: the coefficients' covariance per unit noise variance
  double w(double s) const {
    const double u = s / L;
    double out = 0.0, p = u * u;
    for (double ck : c) {
      out += ck * p;
      p *= u;
    }
    return out;
  }
  /// Position at arc length s by linear interpolation on the fine grid.
  Vec2 at(double s) const {
    const double h = fine_s[1] - fine_s[0];
    const int n = static_cast<int>(fine_s.size());
    int k = std::clamp(static_cast<int>(std::floor(s / h)), 0, n - 2);
    const double t = (s - fine_s[k]) / h;
    return (1.0 - t) * fine[k] + t * fine[k + 1];
  }
};

/// Positions by inextensibility on a fine grid: dx = sqrt(ds² - dw²).
void integrate(Smoothed& sm, const CantileverFrame& f) {
  const int fine = 2000;
  const double h = sm.L / fine;
  sm.fine_s.resize(fine + 1);
  sm.fine.resize(fine + 1);
  sm.fine_s[0] = 0.0;
  sm.fine[0] = Vec2::Zero();
  double x = 0.0, w_prev = 0.0;
  for (int k = 1; k <= fine; ++k) {
    const double s = k * h;
    const double wk = sm.w(s);
    const double dw = wk - w_prev;
    if (std::abs(dw) >= h)
      throw InputError(at_line(f.line) + "the " + grams(f.load) + (f.loaded ? " loaded" : " unloaded") +
                       " frame does not describe a wire of the given arc lengths (the smoothed shape "
                       "drops more than its length near s = " + num(s, 3) + " m): check the s and deflection columns");
    x += std::sqrt(h * h - dw * dw);
    sm.fine_s[k] = s;
    sm.fine[k] = Vec2(x, -wk);
    w_prev = wk;
  }
}

/// Least squares of w(s) = Σ_{k=2..terms+1} c_k (s/L)^k through the marks.
Smoothed polynomial(const CantileverFrame& f, double L, int terms) {
  const int n = static_cast<int>(f.s.size());
  Eigen::MatrixXd A(n, terms);
  Eigen::VectorXd y(n);
  for (int i = 0; i < n; ++i) {
    const double u = f.s[i] / L;
    double p = u * u;
    for (int k = 0; k < terms; ++k) {
      A(i, k) = p;
      p *= u;
    }
    y(i) = f.deflection[i];
  }
  const Eigen::VectorXd c = A.colPivHouseholderQr().solve(y);
  Smoothed sm;
  sm.L = L;
  sm.c.assign(c.data(), c.data() + c.size());
  sm.rss = (A * c - y).squaredNorm();
  sm.dof = n - terms;
  sm.cov = (A.transpose() * A).ldlt().solve(Eigen::MatrixXd::Identity(terms, terms));
  return sm;
}

/// The frame's smoothed shape: the cubic (the tip-loaded beam's shape; a parabola when a frame
/// has 3 marks), raised one degree at a time up to `degree` while the next term is significant
/// (F statistic of the residual drop above kSignificance), so a higher degree follows large
/// deflections without fitting the noise of small ones.
Smoothed smooth(const CantileverFrame& f, double L, int degree) {
  constexpr double kSignificance = 10.0;  // F(1, dof) at ~1 % for the usual 5-8 degrees of freedom
  const int n = static_cast<int>(f.s.size());
  const int most = std::max(1, std::min(degree - 1, n - 1));
  Smoothed sm = polynomial(f, L, std::min(2, most));
  for (int terms = 3; terms <= most; ++terms) {
    Smoothed next = polynomial(f, L, terms);
    const double drop = sm.rss - next.rss;
    if (!(next.dof > 0) || !(drop > kSignificance * next.rss / next.dof)) break;
    sm = std::move(next);
  }
  integrate(sm, f);
  return sm;
}

/// External forces (N) at nodes of a rod of `m` equal parts of length h (m+1 nodes): the tip
/// force at the last node plus the lumped weight (the clamp node's half part rests in the clamp).
std::vector<Vec2> node_forces(int m, double h, double tip_force, double weight_per_length) {
  std::vector<Vec2> F(m + 1, Vec2::Zero());
  for (int k = 1; k <= m; ++k) F[k].y() -= weight_per_length * h * (k == m ? 0.5 : 1.0);
  F[m].y() -= tip_force;
  return F;
}

/// t_v = Σ_{k > v} (x_v - x_k) × f_k for every node (suffix sums).
std::vector<double> external_torques(const Polyline2& x, const std::vector<Vec2>& F) {
  const int n = static_cast<int>(x.size());
  std::vector<double> t(n, 0.0);
  Vec2 sum_f = Vec2::Zero();
  double sum_xf = 0.0;
  for (int k = n - 1; k >= 0; --k) {
    t[k] = cross2(x[k], sum_f) - sum_xf;
    sum_f += F[k];
    sum_xf += cross2(x[k], F[k]);
  }
  return t;
}

/// Turning angles with a horizontal ghost edge before node 0 (the clamp), and the Voronoi
/// lengths l̄ (voronoi_length; the clamp vertex has one edge).
void angles_and_lengths(const Polyline2& x, std::vector<double>& alpha, std::vector<double>& l_bar) {
  const int n = static_cast<int>(x.size());
  alpha.assign(n, 0.0);
  l_bar.assign(n, 0.0);
  Vec2 prev(1.0, 0.0);
  double prev_len = 0.0;
  for (int k = 0; k + 1 < n; ++k) {
    const Vec2 e = x[k + 1] - x[k];
    alpha[k] = std::atan2(cross2(prev, e), prev.dot(e));
    l_bar[k] = voronoi_length(prev_len, e.norm());
    prev = e;
    prev_len = e.norm();
  }
}

/// The frame's nodes (uniform in s) on its smoothed shape.
Polyline2 node_points(const Smoothed& sm, int nodes) {
  Polyline2 x(nodes);
  const double h = sm.L / (nodes - 1);
  for (int k = 0; k < nodes; ++k) x[k] = sm.at(k * h);
  return x;
}

/// g_v = elastic_torque(α_v, 0, l̄_v, 1) at every node but the tip: t_int = k_b g_v (Eq. 10).
std::vector<double> node_g(const Polyline2& x) {
  std::vector<double> alpha, l_bar;
  angles_and_lengths(x, alpha, l_bar);
  std::vector<double> g(x.size() - 1);
  for (std::size_t k = 0; k + 1 < x.size(); ++k) g[k] = elastic_torque(alpha[k], 0.0, l_bar[k], 1.0);
  return g;
}

/// Σ_v Var(g_v) per unit variance of the marks' noise: J (AᵀA)⁻¹ Jᵀ summed over the nodes, J the
/// derivative of g_v by the polynomial's coefficients (central differences).
double g_variance_per_noise(const Smoothed& sm, const CantileverFrame& f, int nodes) {
  const int terms = static_cast<int>(sm.c.size());
  Eigen::MatrixXd J(nodes - 1, terms);
  const double eps = 1e-6;  // m
  for (int j = 0; j < terms; ++j) {
    Smoothed plus = sm, minus = sm;
    plus.c[j] += eps;
    minus.c[j] -= eps;
    integrate(plus, f);
    integrate(minus, f);
    const std::vector<double> gp = node_g(node_points(plus, nodes)), gm = node_g(node_points(minus, nodes));
    for (int v = 0; v + 1 < nodes; ++v) J(v, j) = (gp[v] - gm[v]) / (2 * eps);
  }
  return (J * sm.cov * J.transpose()).trace();
}

}  // namespace

Polyline2 simulate_cantilever(double kb, double length, double tip_force, double weight_per_length, int segments) {
  if (!(kb > 0) || !std::isfinite(kb)) throw InputError("cantilever: bending stiffness must be a finite k_b > 0");
  if (!(length > 0) || !std::isfinite(length)) throw InputError("cantilever: length must be > 0");
  if (!std::isfinite(tip_force) || !std::isfinite(weight_per_length))
    throw InputError("cantilever: loads must be finite");
  if (segments < 2 || segments > 100000) throw InputError("cantilever: segments must be from 2 to 100000");
  const int m = segments;
  const double h = length / m;
  std::vector<double> l_bar(m, voronoi_length(h, h));
  l_bar[0] = voronoi_length(0.0, h);  // the clamp: one edge
  Eigen::VectorXd alpha = Eigen::VectorXd::Zero(m);
  Polyline2 x(m + 1);
  const auto positions = [&](const Eigen::VectorXd& a) {
    double theta = 0.0;
    x[0] = Vec2::Zero();
    for (int k = 0; k < m; ++k) {
      theta += a(k);
      x[k + 1] = x[k] + h * Vec2(std::cos(theta), std::sin(theta));
    }
  };
  const auto bend_energy = [&](double a, double lb) {
    const double t = std::tan(0.5 * a);
    return 4.0 * kb / lb * t * t;
  };
  for (double fraction : {0.25, 0.5, 0.75, 1.0}) {
    const std::vector<Vec2> F = node_forces(m, h, fraction * tip_force, fraction * weight_per_length);
    const auto energy = [&](const Eigen::VectorXd& a) {
      positions(a);
      double e = 0.0;
      for (int k = 0; k < m; ++k) {
        if (std::abs(a(k)) >= std::numbers::pi) return 1e300;
        e += bend_energy(a(k), l_bar[k]);
      }
      for (int k = 0; k <= m; ++k) e -= F[k].dot(x[k]);
      return e;
    };
    const double scale = (std::abs(tip_force) + std::abs(weight_per_length) * length) * length + kb / length;
    bool converged = false;
    for (int it = 0; it < 100 && !converged; ++it) {
      positions(alpha);
      const std::vector<double> t_ext = external_torques(x, F);
      Eigen::VectorXd g(m);
      // S_j = Σ_{k>j} (x_k - x_j) · F_k: the load part of the Hessian, H_ij = S_max(i,j).
      Eigen::VectorXd S(m);
      Vec2 sum_f = F[m];
      double sum_xf = x[m].dot(F[m]);
      for (int j = m - 1; j >= 0; --j) {
        S(j) = sum_xf - x[j].dot(sum_f);
        sum_f += F[j];
        sum_xf += x[j].dot(F[j]);
      }
      Eigen::MatrixXd H(m, m);
      for (int i = 0; i < m; ++i) {
        const double tn = std::tan(0.5 * alpha(i));
        // dE/dα = -t_int; the load's gradient is -Σ_{k>i} (x_k - x_i) × F_k = t_ext.
        g(i) = -elastic_torque(alpha(i), 0.0, l_bar[i], kb) + t_ext[i];
        for (int j = 0; j < m; ++j) H(i, j) = S(std::max(i, j));
        H(i, i) += 2.0 * kb / l_bar[i] * (1.0 + tn * tn) * (1.0 + 3.0 * tn * tn);
      }
      if (g.lpNorm<Eigen::Infinity>() < 1e-11 * scale) {
        converged = true;
        break;
      }
      Eigen::LDLT<Eigen::MatrixXd> ldlt(H);
      Eigen::VectorXd step = -ldlt.solve(g);
      if (ldlt.info() != Eigen::Success || !(step.dot(g) < 0) || !step.allFinite()) step = -g / H.diagonal().maxCoeff();
      else if (step.lpNorm<Eigen::Infinity>() < 1e-7) {
        // Close to the optimum the energy's change drowns in rounding: take full Newton steps
        // (quadratic convergence) until the step itself is at rounding level.
        alpha += step;
        converged = step.lpNorm<Eigen::Infinity>() < 1e-13;
        continue;
      }
      const double e0 = energy(alpha);
      double tau = 1.0;
      Eigen::VectorXd next = alpha + step;
      while (energy(next) > e0 + 1e-4 * tau * step.dot(g) && tau > 1e-12) {
        tau *= 0.5;
        next = alpha + tau * step;
      }
      if (tau <= 1e-12) {
        // No decrease at rounding level: accept when the gradient is already tiny.
        converged = g.lpNorm<Eigen::Infinity>() < 1e-9 * scale;
        break;
      }
      alpha = next;
    }
    if (!converged)
      throw SolverError("cantilever simulation did not converge (k_b " + num(kb) + " N m^2, tip force " +
                        num(tip_force) + " N): the load bends the wire too far for the rod model");
  }
  positions(alpha);
  return x;
}

namespace {

void check_options(const CantileverOptions& o) {
  if (!(o.linear_density >= 0) || !std::isfinite(o.linear_density))
    throw InputError("cantilever: the linear density must be >= 0 kg/m");
  if (!(o.gravity > 0) || !std::isfinite(o.gravity)) throw InputError("cantilever: gravity must be > 0");
  if (!(o.plastic_tolerance > 0) || !std::isfinite(o.plastic_tolerance))
    throw InputError("cantilever: the plastic tolerance must be a finite number of metres > 0");
  if (o.smoothing_degree < 2 || o.nodes < 3 || o.simulation_segments < 2)
    throw InputError("cantilever: smoothing_degree >= 2, nodes >= 3 and simulation_segments >= 2 are needed");
  if (o.smoothing_degree > 50 || o.nodes > 1000 || o.simulation_segments > 100000)
    throw InputError("cantilever: smoothing_degree <= 50, nodes <= 1000 and simulation_segments <= 100000 are the limits");
}

// The capture's rows grouped into frames (load, loaded), loads ascending, loaded before
// unloaded, each frame's marks in order along the wire.
std::vector<CantileverFrame> frames_of(const std::vector<CantileverRecord>& records, double L) {
  std::vector<CantileverFrame> frames;
  std::map<std::pair<double, int>, CantileverFrame> groups;
  for (const CantileverRecord& r : records) {
    if (!std::isfinite(r.load) || r.load < 0)
      throw InputError(at_line(r.line) + "load_g must be a number of grams >= 0");
    if (!std::isfinite(r.s) || !(r.s > 0) || r.s > L * (1 + 1e-9))
      throw InputError(at_line(r.line) + "s_m = " + num(r.s) + " is outside the overhang (0, " + num(L) +
                       "] m: arc lengths are measured from the clamp's edge, in metres");
    if (!std::isfinite(r.deflection)) throw InputError(at_line(r.line) + "deflection_m must be a finite number of metres");
    CantileverFrame& f = groups[{r.load, r.loaded ? 0 : 1}];
    if (f.s.empty()) {
      f.load = r.load;
      f.loaded = r.loaded;
      f.line = r.line;
    }
    f.s.push_back(r.s);
    f.deflection.push_back(r.deflection);
  }
  for (auto& entry : groups) {
    CantileverFrame& f = entry.second;  // not a structured binding: lambdas capture it (clang 14)
    std::vector<int> order(f.s.size());
    for (std::size_t i = 0; i < order.size(); ++i) order[i] = static_cast<int>(i);
    std::sort(order.begin(), order.end(), [&](int a, int b) { return f.s[a] < f.s[b]; });
    std::vector<double> s, w;
    for (int i : order) {
      if (!s.empty() && f.s[i] - s.back() < 1e-9)
        throw InputError(at_line(f.line) + "the " + grams(f.load) + (f.loaded ? " loaded" : " unloaded") +
                         " frame has two marks at s = " + num(f.s[i]) + " m");
      s.push_back(f.s[i]);
      w.push_back(f.deflection[i]);
    }
    f.s = s;
    f.deflection = w;
    if (f.s.size() < 3)
      throw InputError(at_line(f.line) + "the " + grams(f.load) + (f.loaded ? " loaded" : " unloaded") +
                       " frame has " + std::to_string(f.s.size()) +
                       (f.s.size() == 1 ? " mark" : " marks") + "; at least 3 along the wire are needed");
    frames.push_back(f);
  }
  return frames;
}

// Plastic limit: the largest load up to which every unloaded shape returns to the 0 g shape
// (the largest loaded frame's load when no frame is unloaded). Sets the fit's plastic_* fields
// and every unloaded frame's return_error.
double plastic_limit(CantileverFit& fit, const CantileverOptions& o) {
  const double L = o.overhang;
  const CantileverFrame* initial = nullptr;
  bool any_unloaded = false;
  for (const CantileverFrame& f : fit.frames) {
    if (f.load == 0.0 && !initial) initial = &f;
    if (!f.loaded && f.load > 0) any_unloaded = true;
  }
  double max_loaded = 0.0;
  for (const CantileverFrame& f : fit.frames)
    if (f.loaded) max_loaded = std::max(max_loaded, f.load);
  double limit_load = max_loaded;
  if (any_unloaded) {
    if (!initial)
      throw InputError("cantilever: unloaded rows need a 0 g frame (the initial shape) to compare with");
    fit.plastic_found = true;
    double last_ok = 0.0;
    bool failed = false;
    // The shapes compared are the frames' smoothing polynomials (the same as for the fit), not the
    // raw marks, and a frame has not returned only when the difference passes the tolerance by
    // more than kNoiseReach standard deviations of the difference that the marks' noise makes
    // (from the polynomials' covariances and the pooled scatter of the two frames). Reading
    // noise of half a millimetre on both frames would otherwise push the largest mark difference
    // past 1 mm on a wire that returned. Noise-free marks: the plain rule.
    constexpr double kNoiseReach = 2.0;
    const Smoothed initial_shape = smooth(*initial, L, o.smoothing_degree);
    const auto powers = [&](const Smoothed& sm, double s) {
      Eigen::VectorXd a(static_cast<Eigen::Index>(sm.c.size()));
      double p = (s / L) * (s / L);
      for (Eigen::Index k = 0; k < a.size(); ++k, p *= s / L) a(k) = p;
      return a;
    };
    double first_noise = 0.0, first_allowance = 0.0;  // m, of the first frame refused
    for (CantileverFrame& f : fit.frames) {
      if (f.loaded || f.load == 0.0) continue;
      const Smoothed shape = smooth(f, L, o.smoothing_degree);
      const int dof = initial_shape.dof + shape.dof;
      const double noise = dof > 0 ? std::sqrt((initial_shape.rss + shape.rss) / dof) : 0.0;
      double beyond = 0.0, allowance = 0.0;  // m: the largest significant excess, and the noise allowance there
      for (std::size_t i = 0; i < f.s.size(); ++i) {
        const double diff = std::abs(shape.w(f.s[i]) - initial_shape.w(f.s[i]));
        const Eigen::VectorXd a = powers(shape, f.s[i]), a0 = powers(initial_shape, f.s[i]);
        const double sd = noise * std::sqrt(std::max(0.0, a.dot(shape.cov * a) + a0.dot(initial_shape.cov * a0)));
        f.return_error = std::max(f.return_error, diff);
        if (i == 0 || diff - kNoiseReach * sd > beyond) {
          beyond = diff - kNoiseReach * sd;
          allowance = kNoiseReach * sd;
        }
      }
      if (failed) continue;
      if (beyond > o.plastic_tolerance) {
        failed = true;
        first_noise = noise;
        first_allowance = allowance;
      } else {
        last_ok = f.load;
      }
    }
    fit.plastic_reached = failed;
    limit_load = last_ok;
    if (limit_load <= 0.0) {
      const CantileverFrame* first = nullptr;
      for (const CantileverFrame& f : fit.frames)
        if (!f.loaded && f.load > 0) {
          first = &f;
          break;
        }
      throw InputError(at_line(first->line) + "the wire did not return after the first load (" + grams(first->load) +
                       ": its smoothed shape is off by up to " + num(first->return_error * 1000.0, 3) +
                       " mm, more than the " + num(o.plastic_tolerance * 1000.0, 3) +
                       " mm return tolerance plus the " + num(first_allowance * 1000.0, 3) + " mm the marks' noise (" +
                       num(first_noise * 1000.0, 3) + " mm RMS) can explain): there is no elastic frame to fit; use "
                       "smaller load steps (or, if the wire did come back, raise Return Tolerance)");
    }
    fit.plastic_load = limit_load;
  }
  return limit_load;
}

// Check: simulate every used frame with the fitted k_b, compare at the marks.
void compare_with_simulation(CantileverFit& fit, const CantileverOptions& o, double weight) {
  const double L = o.overhang;
  double sum_d2 = 0.0;
  int marks = 0;
  for (std::size_t fi = 0; fi < fit.frames.size(); ++fi) {
    CantileverFrame& f = fit.frames[fi];
    if (!f.used) continue;
    const int m = o.simulation_segments;
    const Polyline2 sim = simulate_cantilever(fit.bending_stiffness, L, f.load * o.gravity, weight, m);
    const double hs = L / m;
    double frame_d2 = 0.0;
    for (std::size_t i = 0; i < f.s.size(); ++i) {
      const int k = std::clamp(static_cast<int>(std::floor(f.s[i] / hs)), 0, m - 1);
      const double t = (f.s[i] - k * hs) / hs;
      const Vec2 p = (1.0 - t) * sim[k] + t * sim[k + 1];
      f.simulated.push_back(-p.y());
      const double d2 = (p - Vec2(f.x[i], -f.deflection[i])).squaredNorm();
      frame_d2 += d2;
      fit.position_max = std::max(fit.position_max, std::sqrt(d2));
    }
    f.position_rms = std::sqrt(frame_d2 / static_cast<double>(f.s.size()));
    sum_d2 += frame_d2;
    marks += static_cast<int>(f.s.size());
  }
  fit.position_rms = std::sqrt(sum_d2 / marks);
}

}  // namespace

CantileverFit fit_cantilever(const std::vector<CantileverRecord>& records, const CantileverOptions& o) {
  const double L = o.overhang;
  if (!(L > 0) || !std::isfinite(L)) throw InputError("cantilever: the overhang must be a length > 0 m");
  check_options(o);
  if (records.empty()) throw InputError("cantilever: the capture has no rows");

  CantileverFit fit;
  fit.frames = frames_of(records, L);

  const double limit_load = plastic_limit(fit, o);

  // Eq. 13: k_b = Σ g t / Σ g² over the evaluation nodes of the used frames.
  const int nodes = o.nodes;
  const double h = L / (nodes - 1);
  const double weight = o.linear_density * o.gravity;
  double sum_gt = 0.0, sum_gg = 0.0, sum_tt = 0.0, rss = 0.0, var_per_noise = 0.0;
  int samples = 0, dof = 0;
  std::vector<Smoothed> shapes(fit.frames.size());
  for (std::size_t fi = 0; fi < fit.frames.size(); ++fi) {
    CantileverFrame& f = fit.frames[fi];
    f.used = f.loaded && f.load > 0.0 && f.load <= limit_load;
    shapes[fi] = smooth(f, L, o.smoothing_degree);
    const Smoothed& sm = shapes[fi];
    for (double si : f.s) f.x.push_back(sm.at(si).x());
    const Polyline2 x = node_points(sm, nodes);
    const std::vector<double> t = external_torques(x, node_forces(nodes - 1, h, f.loaded ? f.load * o.gravity : 0.0, weight));
    f.clamp_torque = t[0];
    if (!f.used) continue;
    const std::vector<double> g = node_g(x);
    for (int k = 0; k + 1 < nodes; ++k) {
      sum_gt += g[k] * t[k];
      sum_gg += g[k] * g[k];
      sum_tt += t[k] * t[k];
      ++samples;
    }
    rss += sm.rss;
    dof += sm.dof;
    var_per_noise += g_variance_per_noise(sm, f, nodes);
    ++fit.frames_used;
  }
  if (fit.frames_used == 0)
    throw InputError("cantilever: no loaded frame with a load above 0 g" +
                     std::string(fit.plastic_found ? " within the plastic limit" : "") + " to fit k_b with");
  if (!(sum_gg > 0) || !(sum_gt > 0))
    throw InputError("cantilever: the measured shapes do not bend down under the loads (deflections are "
                     "measured downward, in metres): k_b cannot be fitted");
  // The marks' noise (pooled residual of the smoothing) inflates Σ g² by Σ Var(g_v) and so
  // biases k_b low (errors in the regressor): reported, and removed on request (at most half).
  fit.mark_noise = dof > 0 ? std::sqrt(rss / dof) : 0.0;
  fit.noise_share = dof > 0 ? fit.mark_noise * fit.mark_noise * var_per_noise / sum_gg : 0.0;
  const double denominator = sum_gg * (1.0 - (o.noise_correction ? std::min(fit.noise_share, 0.5) : 0.0));
  fit.bending_stiffness = sum_gt / denominator;
  const double kb = fit.bending_stiffness;
  fit.torque_rms = std::sqrt(std::max(0.0, kb * kb * sum_gg - 2 * kb * sum_gt + sum_tt) / samples);

  // Plastic-limit torque: the clamp torque of that load's loaded frame.
  if (fit.plastic_found) {
    fit.lever_arm = L;
    fit.max_torque = limit_load * o.gravity * L + 0.5 * weight * L * L;
    for (std::size_t fi = 0; fi < fit.frames.size(); ++fi) {
      const CantileverFrame& f = fit.frames[fi];
      if (f.loaded && f.load == limit_load) {
        fit.lever_arm = shapes[fi].at(L).x();
        fit.max_torque = f.clamp_torque;
      }
    }
  }

  compare_with_simulation(fit, o, weight);
  return fit;
}

FrictionFit fit_friction(const std::vector<double>& angles, const std::vector<int>& lines) {
  if (angles.empty()) throw InputError("friction: the capture has no repeats");
  FrictionFit fit;
  fit.repeats = static_cast<int>(angles.size());
  std::vector<double> mu;
  double sum_angle = 0.0;
  for (std::size_t i = 0; i < angles.size(); ++i) {
    const double a = angles[i];
    if (!std::isfinite(a) || !(a > 0) || !(a < 0.5 * std::numbers::pi))
      throw InputError(at_line(i < lines.size() ? lines[i] : 0) + "angle_deg must be between 0 and 90 degrees, got " +
                       num(to_deg(a)));
    mu.push_back(std::tan(a));
    sum_angle += a;
  }
  double sum = 0.0;
  for (double m : mu) sum += m;
  fit.friction = sum / static_cast<double>(mu.size());
  fit.mean_angle = sum_angle / static_cast<double>(mu.size());
  double var = 0.0;
  for (double m : mu) var += (m - fit.friction) * (m - fit.friction);
  fit.spread = mu.size() > 1 ? std::sqrt(var / static_cast<double>(mu.size() - 1)) : 0.0;
  fit.min = *std::min_element(mu.begin(), mu.end());
  fit.max = *std::max_element(mu.begin(), mu.end());
  return fit;
}

SpringbackFit fit_springback(const std::vector<double>& commanded, const std::vector<double>& measured,
                             const std::vector<int>& lines) {
  if (commanded.size() != measured.size())
    throw InputError("spring-back: " + std::to_string(commanded.size()) + " commanded but " +
                     std::to_string(measured.size()) + " measured angles");
  const std::size_t n = commanded.size();
  const auto line = [&](std::size_t i) { return at_line(i < lines.size() ? lines[i] : 0); };
  std::vector<double> c(n), m(n);
  for (std::size_t i = 0; i < n; ++i) {
    if (!std::isfinite(commanded[i]) || !std::isfinite(measured[i]))
      throw InputError(line(i) + "angles must be finite numbers of degrees");
    for (const auto& [angle, what] : {std::pair{commanded[i], "commanded"}, std::pair{measured[i], "measured"}})
      if (std::abs(angle) > 2.0 * std::numbers::pi)  // beyond it the fit's sums overflow (1e300 deg): not a bend
        throw InputError(line(i) + "the " + what + " angle (" + num(to_deg(angle)) +
                         " deg) is beyond a full turn (360 deg); angles are in degrees");
    if (commanded[i] * measured[i] < 0)
      throw InputError(line(i) + "the measured angle (" + num(to_deg(measured[i])) +
                       " deg) bends to the other side than the commanded one (" + num(to_deg(commanded[i])) + " deg)");
    c[i] = std::abs(commanded[i]);
    m[i] = std::abs(measured[i]);
  }
  if (n < 2) throw InputError((n == 1 ? line(0) : std::string()) + "spring-back: at least two rows (two commanded angles) are needed for a line, got " +
                              std::to_string(n));
  double mc = 0.0, mm = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    mc += c[i];
    mm += m[i];
  }
  mc /= static_cast<double>(n);
  mm /= static_cast<double>(n);
  double scc = 0.0, scm = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    scc += (c[i] - mc) * (c[i] - mc);
    scm += (c[i] - mc) * (m[i] - mm);
  }
  if (!(scc > 1e-12 * std::max(1.0, mc * mc)))
    throw InputError("spring-back: every row has the same commanded angle; a line needs at least two different ones");
  SpringbackFit fit;
  fit.samples = static_cast<int>(n);
  fit.a = scm / scc;
  fit.b = mm - fit.a * mc;
  if (!(fit.a > 0))
    throw InputError("spring-back: the measured angles do not grow with the commanded ones (slope " + num(fit.a) +
                     "); check the columns");
  double s2 = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    const double r = m[i] - (fit.a * c[i] + fit.b);
    s2 += r * r;
    fit.max_residual = std::max(fit.max_residual, std::abs(r));
  }
  fit.rms = std::sqrt(s2 / static_cast<double>(n));
  return fit;
}

MachineProfile with_springback(MachineProfile profile, const SpringbackFit& fit) {
  profile.springback_a = fit.a;
  profile.springback_b = fit.b;
  validate(profile);
  return profile;
}

}  // namespace wiresculpt::fab
