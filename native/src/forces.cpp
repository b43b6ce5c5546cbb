#include "wiresculpt/forces.hpp"

#include <Eigen/SVD>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <nlopt.hpp>
#include <set>
#include <string>

#include "lp.hpp"
#include "nlopt_text.hpp"
#include "wiresculpt/error.hpp"

namespace wiresculpt {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();


std::string wname(const Network& net, int w) { return "wire '" + net.wires[w].name + "'"; }


void validate(const ForceOptions& o) {
  auto finite_pos = [](double v) { return std::isfinite(v) && v > 0; };
  if (!std::isfinite(o.friction) || o.friction < 0) throw InputError("friction must be a finite number >= 0");
  if (!finite_pos(o.max_torque)) throw InputError("max_torque must be a finite number of N m > 0");
  if (!finite_pos(o.torque_fraction) || o.torque_fraction > 1.0)
    throw InputError("torque_fraction must be in (0, 1], not " + std::to_string(o.torque_fraction));
  if (!std::isfinite(o.assembly_weight) || o.assembly_weight < 0)
    throw InputError("assembly_weight must be a finite number >= 0");
  if (o.max_iterations < 1) throw InputError("max_iterations must be at least 1");
  if (!(o.carried_margin >= 0 && o.carried_margin < 1)) throw InputError("carried_margin must be in [0, 1)");
  if (!(o.carried_share >= 0 && o.carried_share <= 1)) throw InputError("carried_share must be in [0, 1]");
  if (!(o.working_set_margin >= 0) || !(o.working_set_margin_3d >= 0) || !std::isfinite(o.working_set_margin) ||
      !std::isfinite(o.working_set_margin_3d))
    throw InputError("working_set_margin and working_set_margin_3d must be finite numbers >= 0");
  if (!finite_pos(o.ftol_rel) || !finite_pos(o.xtol_rel) || !finite_pos(o.constraint_tol))
    throw InputError("ftol_rel, xtol_rel and constraint_tol must be finite numbers > 0");
}

void validate_network(const Network& net, const std::vector<int>& hooks) {
  const int P = static_cast<int>(net.wires.size());
  if (hooks.size() != net.crossings.size())
    throw InputError("forces: expected one hook per crossing (" + std::to_string(net.crossings.size()) + "), got " +
                     std::to_string(hooks.size()));
  for (int w = 0; w < P; ++w) {
    const WireSpec& s = net.wires[w];
    for (const Vec3& p : s.points)
      if (!p.allFinite()) throw InputError(wname(net, w) + " has a non-finite target point");
  }
  for (std::size_t c = 0; c < net.crossings.size(); ++c) {
    const Crossing& x = net.crossings[c];
    const std::string who = "crossing " + std::to_string(c);
    if (hooks[c] < -1 || hooks[c] > 1) throw InputError(who + ": hook must be -1, 0 or 1, not " + std::to_string(hooks[c]));
    for (int k = 0; k < 2; ++k)
      if (x.wires[k] < 0 || x.wires[k] >= P) throw InputError(who + ": wire id " + std::to_string(x.wires[k]) + " does not exist");
    if (x.wires[0] == x.wires[1]) throw InputError(who + " joins a wire to itself");
    for (int k = 0; k < 2; ++k) {
      const WireSpec& s = net.wires[x.wires[k]];
      if (x.vertices[k] < 0 || x.vertices[k] >= static_cast<int>(s.points.size()))
        throw InputError(who + ": vertex " + std::to_string(x.vertices[k]) + " is outside " + wname(net, x.wires[k]) +
                         "'s " + std::to_string(s.points.size()) + " target points");
    }
    const Vec3 d = net.wires[x.wires[0]].plane.normal.cross(net.wires[x.wires[1]].plane.normal);
    if (hooks[c] != 0 && !(d.norm() > 1e-9))
      throw InputError(who + ": the planes of " + wname(net, x.wires[0]) + " and " + wname(net, x.wires[1]) +
                       " are parallel, so they cannot hook");
  }
}

}  // namespace

std::array<Vec3, 4> target_pyramid(const Network& net, int c, int hook, double friction) {
  if (c < 0 || c >= static_cast<int>(net.crossings.size()))
    throw InputError("crossing " + std::to_string(c) + " does not exist");
  if (hook != 1 && hook != -1)
    throw InputError("crossing " + std::to_string(c) + ": only hooks -1 and 1 have a contact pyramid");
  const Crossing& x = net.crossings[c];
  const Vec3 d = net.wires[x.wires[0]].plane.normal.cross(net.wires[x.wires[1]].plane.normal).normalized();
  const double s = static_cast<double>(hook);
  std::array<Vec3, 4> out;
  for (int k = 0; k < 2; ++k) {
    const WireSpec& w = net.wires[x.wires[k]];
    const int n = static_cast<int>(w.points.size());
    const int v = x.vertices[k];
    int prev = v - 1, next = v + 1;
    if (w.closed) {
      prev = (v + n - 1) % n;
      next = (v + 1) % n;
    } else if (prev < 0 || next >= n) {
      throw InputError("crossing " + std::to_string(c) + " is at an end of open " + wname(net, x.wires[k]) +
                       ", which has no kink to hook");
    }
    const Vec3& p = w.points[v];
    const Vec3 h = (k == 0 ? s : -s) * d;
    const Vec3& nrm = w.plane.normal;
    const Vec3 arms[2] = {(w.points[prev] - p).normalized(), (w.points[next] - p).normalized()};
    for (int e = 0; e < 2; ++e) {
      const Vec3& a = arms[e];
      const Vec3& other = arms[1 - e];
      Vec3 m = nrm.cross(a);
      m -= m.dot(nrm) * nrm;  // in plane (a is, up to rounding)
      m.normalize();
      const double side = m.dot(h);
      if (std::abs(side) > 1e-9) {
        if (side > 0) m = -m;
      } else if (m.dot(other) > 0) {
        m = -m;
      }
      if (!m.allFinite() || !a.allFinite())
        throw InputError("crossing " + std::to_string(c) + ": " + wname(net, x.wires[k]) +
                         " has coincident points at the crossing");
      const Vec3 q = (m + friction * a).normalized();
      out[2 * k + e] = k == 0 ? q : Vec3(-q);
    }
  }
  return out;
}

OutOfPlaneShares out_of_plane_shares(const Network& net, const std::vector<int>& hooks, const std::vector<Vec3>& forces) {
  if (hooks.size() != net.crossings.size() || forces.size() != net.crossings.size())
    throw InputError("out-of-plane shares: expected one hook and one force per crossing (" +
                     std::to_string(net.crossings.size()) + "), got " + std::to_string(hooks.size()) + " and " +
                     std::to_string(forces.size()));
  OutOfPlaneShares out;
  out.share.assign(net.crossings.size(), {0.0, 0.0});
  double largest = 0.0;
  for (std::size_t c = 0; c < forces.size(); ++c)
    if (hooks[c] != 0) largest = std::max(largest, forces[c].norm());
  if (!(largest > 0)) return out;
  int counted = 0;
  for (std::size_t c = 0; c < forces.size(); ++c) {
    const double fn = forces[c].norm();
    if (hooks[c] == 0 || !(fn > 0)) continue;
    for (int k = 0; k < 2; ++k) {
      const double along = std::abs(forces[c].dot(net.wires[net.crossings[c].wires[k]].plane.normal));
      out.share[c][k] = along / fn;
      out.mean += out.share[c][k];
      out.max = std::max(out.max, out.share[c][k]);
      out.mean_to_max_force += along / largest;
      out.max_to_max_force = std::max(out.max_to_max_force, along / largest);
      ++counted;
    }
  }
  out.mean /= counted;
  out.mean_to_max_force /= counted;
  return out;
}

std::vector<WireLoad> wire_loads(const Network& net, const std::vector<int>& hooks, const std::vector<Vec3>& forces,
                                 int wire) {
  std::vector<WireLoad> out;
  for (std::size_t c = 0; c < net.crossings.size(); ++c) {
    if (hooks[c] == 0) continue;
    const Crossing& x = net.crossings[c];
    for (int k = 0; k < 2; ++k)
      if (x.wires[k] == wire) out.push_back({x.vertices[k], k == 0 ? forces[c] : Vec3(-forces[c])});
  }
  return out;
}

ForceProblem::ForceProblem(const Network& net, const std::vector<int>& hooks,
                           const std::vector<std::vector<int>>& steps, const std::vector<int>& cuts,
                           const ForceOptions& options)
    : net_(&net), hooks_(hooks) {
  validate(options);
  validate_network(net, hooks);
  const int P = static_cast<int>(net.wires.size());
  if (cuts.size() != static_cast<std::size_t>(P))
    throw InputError("forces: expected one cut per wire (" + std::to_string(P) + "), got " + std::to_string(cuts.size()));
  const int C = static_cast<int>(net.crossings.size());
  pyramid_.resize(C);
  std::vector<int> hooked;
  for (int c = 0; c < C; ++c)
    if (hooks[c] != 0) {
      pyramid_[c] = target_pyramid(net, c, hooks[c], options.friction);
      hooked.push_back(c);
      for (int j = 0; j < 4; ++j) column_crossing_.push_back(c);
    }
  const int K = static_cast<int>(column_crossing_.size());
  // Reference and length scale: centroid and RMS distance of all crossings.
  for (const Crossing& x : net.crossings) reference_ += x.point;
  if (C > 0) reference_ /= static_cast<double>(C);
  double ss = 0.0;
  for (const Crossing& x : net.crossings) ss += (x.point - reference_).squaredNorm();
  L_ = C > 0 ? std::sqrt(ss / C) : 1.0;
  if (!(L_ > 1e-9)) L_ = 1.0;
  t_max_ = options.max_torque * options.torque_fraction;
  w_ = options.assembly_weight * L_ / t_max_;
  bound_ = options.torque_bound;

  // M (6P × K) and the normal weights.
  M_ = Eigen::MatrixXd::Zero(6 * P, K);
  c_ = Eigen::VectorXd::Zero(K);
  Nk_ = Eigen::MatrixXd::Zero(static_cast<Eigen::Index>(hooked.size()), K);
  for (int j = 0; j < K; ++j) {
    const int c = column_crossing_[j];
    const Crossing& x = net.crossings[c];
    const Vec3& b = pyramid_[c][j % 4];
    const Vec3 t = (x.point - reference_).cross(b);
    M_.block<3, 1>(6 * x.wires[0], j) = b;
    M_.block<3, 1>(6 * x.wires[0] + 3, j) = t;
    M_.block<3, 1>(6 * x.wires[1], j) = -b;
    M_.block<3, 1>(6 * x.wires[1] + 3, j) = -t;
    const Vec3 d = net.wires[x.wires[0]].plane.normal.cross(net.wires[x.wires[1]].plane.normal).normalized();
    const double nk = -static_cast<double>(hooks[c]) * b.dot(d);
    Nk_(j / 4, j) = nk;
    c_(j) = 2.0 * nk;
  }

  // Torque rows: walk each wire from its cut; row v holds n·Σ_{k after v} (x_v - x_k) × b_j,
  // and the frame rows its components along n, u and v.
  std::vector<std::vector<std::array<int, 2>>> on_wire(P);  // (column start, side) per hooked crossing
  for (int h = 0; h < static_cast<int>(hooked.size()); ++h)
    for (int k = 0; k < 2; ++k) on_wire[net.crossings[hooked[h]].wires[k]].push_back({4 * h, k});
  std::vector<Eigen::RowVectorXd> rows;
  std::vector<Eigen::MatrixXd> frame_rows;
  for (int w = 0; w < P; ++w) {
    const WireSpec& s = net.wires[w];
    const int n = static_cast<int>(s.points.size());
    const std::vector<int> walk = wire_walk(n, s.closed, cuts[w], s.name);
    std::vector<int> pos(n, -1);
    for (int k = static_cast<int>(walk.size()) - 1; k >= 0; --k) pos[walk[k]] = k;
    const int last = static_cast<int>(walk.size()) - (s.closed ? 1 : 0);  // the repeated cut has no tail
    for (int v = 0; v < last; ++v) {
      Eigen::RowVectorXd row = Eigen::RowVectorXd::Zero(K);
      Eigen::MatrixXd frame = Eigen::MatrixXd::Zero(3, K);
      const Vec3& xv = s.points[walk[v]];
      for (const auto& [col, side] : on_wire[w]) {
        const int c = column_crossing_[col];
        const int vk = net.crossings[c].vertices[side];
        if (pos[vk] <= v) continue;
        const Vec3 lever = xv - s.points[vk];
        for (int j = 0; j < 4; ++j) {
          const Vec3 f = side == 0 ? pyramid_[c][j] : Vec3(-pyramid_[c][j]);
          const Vec3 t = lever.cross(f);
          row(col + j) = t.dot(s.plane.normal);
          frame.col(col + j) << row(col + j), t.dot(s.plane.u), t.dot(s.plane.v);
        }
      }
      rows.push_back(row);
      frame_rows.push_back(frame);
      torque_vertex_.push_back({w, walk[v]});
    }
  }
  T_ = Eigen::MatrixXd::Zero(static_cast<Eigen::Index>(rows.size()), K);
  T3_ = Eigen::MatrixXd::Zero(3 * static_cast<Eigen::Index>(rows.size()), K);
  for (std::size_t r = 0; K > 0 && r < rows.size(); ++r) {  // K = 0: nothing to copy (no data to index)
    T_.row(static_cast<Eigen::Index>(r)) = rows[r];
    T3_.middleRows(3 * static_cast<Eigen::Index>(r), 3) = frame_rows[r];
  }

  // Q = Σ_s R_sᵀ R_s over assembly prefixes (torque rows scaled by 1/L).
  Q_ = Eigen::MatrixXd::Zero(K, K);
  std::vector<char> in(P, 0), seen(P, 0);
  for (const auto& step : steps) {
    for (int w : step) {
      if (w < 0 || w >= P) throw InputError("forces: assembly step names wire id " + std::to_string(w) + ", which does not exist");
      if (seen[w]) throw InputError("forces: " + wname(net, w) + " appears twice in the assembly steps");
      seen[w] = in[w] = 1;
    }
    Eigen::MatrixXd R = Eigen::MatrixXd::Zero(6 * P, K);
    for (int j = 0; j < K; ++j) {
      const Crossing& x = net.crossings[column_crossing_[j]];
      if (!in[x.wires[0]] || !in[x.wires[1]]) continue;
      R.col(j) = M_.col(j);
      for (int w = 0; w < P; ++w) R.block<3, 1>(6 * w + 3, j) /= L_;
    }
    Q_.noalias() += R.transpose() * R;
  }
  if (options.carried_3d && K > 0) carried_rows(net, hooks, cuts, options);
}

// The carried forces F3_ a + W_ (F3_ = R J) and the rows C_ a >= C_lo_ that keep each of them
// in its pyramid shrunk by carried_margin (the facets of the cone its four moved vectors span)
// and its normal force at least carried_share of their mean.
void ForceProblem::carried_rows(const Network& net, const std::vector<int>& hooks, const std::vector<int>& cuts,
                                const ForceOptions& options) {
  const int K = columns(), H = K / 4;
  const CarriedForces carried = carried_forces(net, hooks, cuts, options.carried);
  Eigen::MatrixXd J = Eigen::MatrixXd::Zero(3 * H, K);
  for (int j = 0; j < K; ++j) J.block<3, 1>(3 * (j / 4), j) = pyramid_[column_crossing_[j]][j % 4];
  F3_ = carried.R * J;
  W_ = carried.weight;
  std::vector<Eigen::RowVectorXd> rows;
  std::vector<double> lo;
  for (int h = 0; h < H; ++h) {
    const std::array<Vec3, 4>& b = pyramid_[column_crossing_[4 * h]];
    const Vec3 mean = 0.25 * (b[0] + b[1] + b[2] + b[3]);
    std::array<Vec3, 4> g;
    for (int i = 0; i < 4; ++i) g[i] = (1.0 - options.carried_margin) * b[i] + options.carried_margin * mean;
    for (int i = 0; i < 4; ++i)
      for (int j = i + 1; j < 4; ++j) {
        Vec3 n = g[i].cross(g[j]);
        if (n.norm() < 1e-12) continue;
        n.normalize();
        double below = 0.0, above = 0.0;
        for (int k = 0; k < 4; ++k) below = std::min(below, n.dot(g[k])), above = std::max(above, n.dot(g[k]));
        if (below < -1e-12 && above > 1e-12) continue;  // the other vectors on both sides: not a facet
        if (below < -1e-12) n = -n;
        rows.push_back(n.transpose() * F3_.middleRows<3>(3 * h));
        lo.push_back(-n.dot(W_.segment<3>(3 * h)));
      }
  }
  // Each carried normal force at least carried_share of their mean: a crossing the pre-stress
  // leaves unloaded has nothing to hold the weight's share with.
  Eigen::MatrixXd normal(H, K);
  Eigen::VectorXd weight_normal(H);
  for (int h = 0; h < H; ++h) {
    const int c = column_crossing_[4 * h];
    const Crossing& x = net.crossings[c];
    const Vec3 d = net.wires[x.wires[0]].plane.normal.cross(net.wires[x.wires[1]].plane.normal).normalized();
    normal.row(h) = -static_cast<double>(hooks[c]) * d.transpose() * F3_.middleRows<3>(3 * h);
    weight_normal(h) = -static_cast<double>(hooks[c]) * d.dot(W_.segment<3>(3 * h));
  }
  const Eigen::RowVectorXd mean = normal.colwise().sum() / static_cast<double>(H);
  const double weight_mean = weight_normal.mean();
  for (int h = 0; h < H; ++h) {
    rows.push_back(normal.row(h) - options.carried_share * mean);
    lo.push_back(options.carried_share * weight_mean - weight_normal(h));
  }
  C_ = Eigen::MatrixXd::Zero(static_cast<Eigen::Index>(rows.size()), K);
  for (std::size_t r = 0; r < rows.size(); ++r) C_.row(static_cast<Eigen::Index>(r)) = rows[r];
  C_lo_ = Eigen::Map<const Eigen::VectorXd>(lo.data(), static_cast<Eigen::Index>(lo.size()));
}

double ForceProblem::objective(const Eigen::VectorXd& a, Eigen::VectorXd* grad) const {
  const Eigen::VectorXd Qa = Q_ * a;
  if (grad) *grad = c_ - 2.0 * w_ * Qa;
  return c_.dot(a) - w_ * a.dot(Qa);
}

Eigen::VectorXd ForceProblem::torque_gauges(const Eigen::VectorXd& a) const {
  const Eigen::VectorXd t = T3_ * a;
  Eigen::VectorXd g(T_.rows());
  for (Eigen::Index r = 0; r < g.size(); ++r) g(r) = torque_gauge(polytope(), t.segment<3>(3 * r), t_max_);
  return g;
}

std::vector<Vec3> ForceProblem::forces(const Eigen::VectorXd& a) const {
  std::vector<Vec3> out(net_->crossings.size(), Vec3::Zero());
  for (int j = 0; j < columns(); ++j) out[column_crossing_[j]] += a(j) * pyramid_[column_crossing_[j]][j % 4];
  return out;
}

namespace {

struct SlsqpData {
  const ForceProblem* problem;
  const Eigen::MatrixXd* N;  // K × k null-space basis
  Eigen::MatrixXd G;         // constraint rows in z, m × k (c(z) = G z - h <= 0)
  Eigen::VectorXd h;
  const ProgressFn* progress;
  int evaluations = 0;
  bool cancelled = false;
  std::chrono::steady_clock::time_point polled = std::chrono::steady_clock::now();
};

double slsqp_objective(unsigned n, const double* z, double* grad, void* data) {
  auto* s = static_cast<SlsqpData*>(data);
  // Polled every 20 evaluations, or sooner when evaluations are slow (large C): cancel stays prompt.
  const auto now = std::chrono::steady_clock::now();
  if ((++s->evaluations % 20 == 0 || now - s->polled >= std::chrono::milliseconds(50)) && s->progress &&
      *s->progress) {
    s->polled = now;
    if (!(*s->progress)("forces", 0.6)) {
      s->cancelled = true;
      throw nlopt::forced_stop();
    }
  }
  const Eigen::Map<const Eigen::VectorXd> zv(z, n);
  const Eigen::VectorXd a = *s->N * zv;
  Eigen::VectorXd ga;
  const double g = s->problem->objective(a, grad ? &ga : nullptr);
  if (grad) Eigen::Map<Eigen::VectorXd>(grad, n) = s->N->transpose() * ga;
  return g;
}

void slsqp_constraints(unsigned m, double* result, unsigned n, const double* z, double* grad, void* data) {
  auto* s = static_cast<SlsqpData*>(data);
  const Eigen::Map<const Eigen::VectorXd> zv(z, n);
  Eigen::Map<Eigen::VectorXd>(result, m) = s->G * zv - s->h;
  if (grad) Eigen::Map<Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>>(grad, m, n) = s->G;
}

// Largest violation of a's constraints, relative: torque / t_max, sign and normal / scale.
double violation(const ForceProblem& p, const Eigen::VectorXd& a, double force_scale) {
  double v = 0.0;
  if (a.size() == 0) return 0.0;
  v = std::max(v, -a.minCoeff() / force_scale);
  if (p.torque_rows().rows() > 0) v = std::max(v, p.torque_gauges(a).maxCoeff() - 1.0);
  if (p.normal_rows().rows() > 0) v = std::max(v, -(p.normal_rows() * a).minCoeff() / force_scale);
  return v;
}

// Near the LP's optimum: the forces least out of their wires' planes (ForceOptions::least_out_of_plane),
// from the force LP `lp` (its polytope rows in `added`, its basis in `held`), into a.
void least_out_of_plane(const ForceProblem& problem, const Network& net, const ForceOptions& options,
                        const detail::LinearProgram& lp, const detail::TorqueBlocks& blocks,
                        const std::set<std::pair<int, int>>& added, detail::HeldLp& held, ForceResult& r,
                        Eigen::VectorXd& a) {
  const int K = problem.columns();
  // Near the optimum: minimise Σ s over s_{h,w} >= |f_h · n_w| (2 per hooked crossing h),
  // keeping G_stb within tie_tolerance of the optimum and every other row.
  const int H = K / 4;
  const double best = problem.normal_weights().dot(a);
  detail::LinearProgram tie = lp;
  tie.maximise = false;
  tie.obj.assign(K + 2 * H, 0.0);
  for (int i = 0; i < 2 * H; ++i) tie.obj[K + i] = 1.0;
  tie.col_lo.resize(K + 2 * H, 0.0);
  tie.col_hi.resize(K + 2 * H, kInf);
  int next = static_cast<int>(tie.row_lo.size());
  auto entry = [&](int col, double v) {
    tie.tri_row.push_back(next);
    tie.tri_col.push_back(col);
    tie.tri_val.push_back(v);
  };
  for (int j = 0; j < K; ++j) entry(j, problem.normal_weights()(j));
  tie.row_lo.push_back((1.0 - options.tie_tolerance) * best);
  tie.row_hi.push_back(kInf);
  ++next;
  for (int h = 0; h < H; ++h)
    for (int w = 0; w < 2; ++w)
      for (double sign : {1.0, -1.0}) {
        const Crossing& x = net.crossings[r.column_crossing[4 * h]];
        const Vec3& n = net.wires[x.wires[w]].plane.normal;
        for (int q = 0; q < 4; ++q) entry(4 * h + q, -sign * n.dot(problem.pyramid(r.column_crossing[4 * h])[q]));
        entry(K + 2 * h + w, 1.0);  // s - sign (f·n) >= 0
        tie.row_lo.push_back(0.0);
        tie.row_hi.push_back(kInf);
        ++next;
      }
  detail::TorqueBlocks padded{Eigen::MatrixXd::Zero(blocks.A.rows(), K + 2 * H), blocks.c};
  padded.A.leftCols(K) = blocks.A;
  std::set<std::pair<int, int>> tie_added = added;
  const detail::LpSolution tied =
      detail::solve_lp_with_torque_rows(tie, padded, problem.polytope(), problem.t_max(), tie_added, &r.lp_rounds,
                                      options.lp_warm_start, &held);
  r.lp_iterations += tied.iterations;
  if (tied.status == detail::LpSolution::optimal)
    for (int j = 0; j < K; ++j) a(j) = std::max(0.0, tied.x[j]);
}

// The force LP (Eq. 6-8 with the bound's polytope rows added as they are violated), and the
// least-out-of-plane LP after it when asked: the coefficients into a, the counts into r.
void solve_by_lp(const ForceProblem& problem, const Network& net, const ForceOptions& options, bool least,
                 bool carried, const ProgressFn& progress, ForceResult& r, Eigen::VectorXd& a) {
  const int K = problem.columns();
  const double F_ref = problem.t_max() / problem.length_scale();
  const Eigen::MatrixXd& M = problem.equilibrium();
  const Eigen::MatrixXd& T = problem.torque_rows();
  const Eigen::MatrixXd& Nk = problem.normal_rows();
  const auto t0 = std::chrono::steady_clock::now();
  detail::LinearProgram lp;
  lp.maximise = true;
  lp.obj.assign(problem.normal_weights().data(), problem.normal_weights().data() + K);
  lp.col_lo.assign(K, 0.0);
  lp.col_hi.assign(K, kInf);
  detail::append_rows(lp, M, 0.0, 0.0);
  detail::append_rows(lp, T, -problem.t_max(), problem.t_max());  // |n·t_v| <= t_max: implied by either bound
  detail::append_rows(lp, Nk, 0.0, kInf);
  if (carried) {
    const std::size_t first = lp.row_lo.size();
    detail::append_rows(lp, problem.carried_rows(), 0.0, kInf);
    for (Eigen::Index i = 0; i < problem.carried_lower().size(); ++i) lp.row_lo[first + i] = problem.carried_lower()(i);
  }
  // The other rows of the bound's polytope join as solutions violate them.
  const detail::TorqueBlocks blocks{problem.torque_frame_rows(), Eigen::VectorXd::Zero(problem.torque_frame_rows().rows())};
  std::set<std::pair<int, int>> added;
  // The problem GLPK holds, passed from loop to loop: the least-out-of-plane LP below starts from
  // the force LP's optimal basis.
  detail::HeldLp held;
  detail::LpSolution sol =
      detail::solve_lp_with_torque_rows(lp, blocks, problem.polytope(), problem.t_max(), added, &r.lp_rounds,
                                        options.lp_warm_start, &held);
  r.lp_iterations = sol.iterations;
  if (sol.status == detail::LpSolution::unbounded) {
    // Bound every coefficient: when the optimum then keeps away from the cap, it is the
    // problem's (rows not yet added had left a force free); otherwise name the crossings
    // whose force no torque limits.
    const double cap = 1e6 * F_ref;
    lp.col_hi.assign(K, cap);
    report_progress(progress, "forces", 0.25);  // between the two LPs
    const detail::LpSolution capped =
        detail::solve_lp_with_torque_rows(lp, blocks, problem.polytope(), problem.t_max(), added, &r.lp_rounds,
                                        options.lp_warm_start, &held);
    r.lp_iterations += capped.iterations;
    std::string names;
    if (capped.status == detail::LpSolution::optimal)
      for (int j = 0; j < K; ++j)
        if (capped.x[j] > 0.5 * cap && names.find(" " + std::to_string(r.column_crossing[j]) + ",") == std::string::npos)
          names += " " + std::to_string(r.column_crossing[j]) + ",";
    if (capped.status == detail::LpSolution::optimal && names.empty()) {
      sol = capped;
    } else {
      if (!names.empty()) names.pop_back();
      throw SolverError("the contact forces are unbounded: no wire's bending torque limits the force at crossing" +
                        (names.empty() ? std::string("s") : names) +
                        "; check the cuts and that every wire has more than one crossing");
    }
  }
  if (sol.status != detail::LpSolution::optimal)
    throw SolverError("the force LP could not be solved (" +
                      (sol.status == detail::LpSolution::infeasible ? std::string("GLPK found it infeasible")
                       : sol.reason.empty()                         ? std::string("GLPK failed")
                                                                    : sol.reason) +
                      "); check the material's numbers and the model's size, or report this input");
  for (int j = 0; j < K; ++j) a(j) = std::max(0.0, sol.x[j]);
  if (least) least_out_of_plane(problem, net, options, lp, blocks, added, held, r, a);
  r.method = least ? "lp+least_out_of_plane" : "lp";
  r.lp_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

// SLSQP's answer a_nlp taken when it is feasible and, from the LP's optimum, no worse than
// where it started (g_start); otherwise a warning (from the LP) or an error (SLSQP alone).
void accept_slsqp(const ForceProblem& problem, bool use_lp, Eigen::VectorXd a_nlp, double g_start, ForceResult& r,
                  Eigen::VectorXd& a) {
  const int K = problem.columns();
  const double F_ref = problem.t_max() / problem.length_scale();
  // Rounding-level negatives (SLSQP's constraint tolerance) are set to zero.
  for (int j = 0; j < K; ++j)
    if (a_nlp(j) < 0 && a_nlp(j) > -1e-7 * F_ref) a_nlp(j) = 0.0;
  const double v = violation(problem, a_nlp, F_ref);
  const double g_nlp = problem.objective(a_nlp);
  const bool from_lp = use_lp;
  if (v <= 1e-7 && (!from_lp || g_nlp >= g_start - 1e-9 * std::max(1.0, std::abs(g_start)))) {
    a = a_nlp;
    r.method = from_lp ? "lp+slsqp" : "slsqp";
  } else if (from_lp) {
    r.warnings.push_back("the assembly term could not be improved by SLSQP (" + r.nlopt_result +
                         "); the forces maximise the normal-force sum alone");
  } else {
    throw SolverError("SLSQP found no feasible contact forces (" + r.nlopt_result +
                      "); use the default algorithm");
  }
}

// SLSQP over z, a = N z (N the null space of M), from a, with a working set of the bound's
// torque rows (ForceOptions::working_set): the coefficients into a, the counts into r.
void slsqp_in_null_space(const ForceProblem& problem, const ForceOptions& options, bool use_lp,
                         const Eigen::MatrixXd& N, const ProgressFn& progress, ForceResult& r, Eigen::VectorXd& a) {
  const int K = problem.columns();
  const int k = static_cast<int>(N.cols());
  const double F_ref = problem.t_max() / problem.length_scale();
  const Eigen::MatrixXd& T = problem.torque_rows();
  const Eigen::MatrixXd& Nk = problem.normal_rows();
  // Constraint rows in z (c(z) = G z - h <= 0), scaled to O(1): signs and normal forces by
  // F_ref (always in the set), torque rows e·t_v <= t_max of the bound's polytope by t_max
  // (a working set of them; c = e·t_v / t_max - 1).
  Eigen::MatrixXd G_fixed(K + Nk.rows(), k);
  G_fixed.topRows(K) = -N / F_ref;
  G_fixed.bottomRows(Nk.rows()) = -Nk * N / F_ref;
  const TorquePolytope& poly = problem.polytope();
  const int F = static_cast<int>(poly.rows.size());
  const Eigen::Index V = T.rows();
  const Eigen::MatrixXd TF = problem.torque_frame_rows() * N / problem.t_max();  // 3V × k
  std::vector<double> z(static_cast<std::size_t>(k));
  Eigen::Map<Eigen::VectorXd>(z.data(), k) = N.transpose() * a;
  // c of every torque row at z: F × V.
  auto torque_values = [&]() {
    const Eigen::VectorXd t = TF * Eigen::Map<const Eigen::VectorXd>(z.data(), k);
    Eigen::MatrixXd c(F, V);
    for (Eigen::Index v = 0; v < V; ++v)
      for (int e = 0; e < F; ++e) c(e, v) = poly.rows[e].dot(t.segment<3>(3 * v)) - 1.0;
    return c;
  };
  // The working set, as (polytope row, vertex) pairs: torque rows within the margin of their
  // bound at the start (the LP's optimum sits on many of them), at most kTopRows per vertex
  // (the facets around its torque's direction: a polytope vertex joins 5 or 6), later any
  // row the solution violates. For in_plane (rows ±n) this is every row within the margin.
  constexpr int kTopRows = 6;
  const double kNear =
      -(problem.torque_bound() == TorqueBound::full_3d ? options.working_set_margin_3d : options.working_set_margin);
  std::set<std::pair<int, int>> in_set;
  auto add_near = [&](const Eigen::MatrixXd& c) {
    std::vector<int> order(static_cast<std::size_t>(F));
    for (Eigen::Index v = 0; v < V; ++v) {
      if (c.col(v).maxCoeff() < kNear) continue;
      for (int e = 0; e < F; ++e) order[e] = e;
      const int top = std::min(F, kTopRows);
      std::partial_sort(order.begin(), order.begin() + top, order.end(),
                        [&](int x, int y) { return c(x, v) > c(y, v); });
      for (int i = 0; i < top && c(order[i], v) >= kNear; ++i) in_set.insert({order[i], static_cast<int>(v)});
    }
  };
  // The rows through ±n t_max at every vertex: they bound every torque component (for
  // in_plane they are every row).
  auto add_apex = [&]() {
    for (Eigen::Index v = 0; v < V; ++v)
      for (int e : poly.apex) in_set.insert({e, static_cast<int>(v)});
  };
  bool partial = options.working_set && use_lp;  // from zero nothing is near a bound yet
  if (!options.working_set) {
    for (int e = 0; e < F; ++e)
      for (Eigen::Index v = 0; v < V; ++v) in_set.insert({e, static_cast<int>(v)});
  } else if (partial) {
    add_near(torque_values());
  } else {
    add_apex();
  }
  SlsqpData data{&problem, &N, {}, {}, &progress};
  const Eigen::VectorXd a_start = a;
  const double g_start = problem.objective(a_start);
  double g = 0.0;
  nlopt::result res = nlopt::FAILURE;
  for (int round = 0;; ++round) {
    const Eigen::Index rows = K + static_cast<Eigen::Index>(in_set.size()) + Nk.rows();
    data.G.resize(rows, k);
    data.h = Eigen::VectorXd::Zero(rows);
    data.G.topRows(K) = G_fixed.topRows(K);
    Eigen::Index i = K;
    for (const auto& [e, v] : in_set) {
      data.G.row(i) = poly.rows[e].transpose() * TF.middleRows(3 * v, 3);
      data.h(i++) = 1.0;
    }
    data.G.bottomRows(Nk.rows()) = G_fixed.bottomRows(Nk.rows());
    nlopt::opt opt(nlopt::LD_SLSQP, static_cast<unsigned>(k));
    opt.set_max_objective(slsqp_objective, &data);
    opt.add_inequality_mconstraint(slsqp_constraints, &data,
                                   std::vector<double>(static_cast<std::size_t>(rows), options.constraint_tol));
    opt.set_ftol_rel(options.ftol_rel);
    opt.set_xtol_rel(options.xtol_rel);
    opt.set_maxeval(std::max(1, options.max_iterations - data.evaluations));
    try {
      res = opt.optimize(z, g);
      r.nlopt_result = detail::nlopt_result_text(res);
    } catch (const nlopt::forced_stop&) {
      if (data.cancelled) throw Cancelled();
      r.nlopt_result = "NLOPT_FORCED_STOP";
      break;
    } catch (const std::exception& e) {
      if (data.cancelled) throw Cancelled();
      r.nlopt_result = std::string("NLOPT_FAILURE (") + e.what() + ")";
      if (!partial) break;
      // A partial set may leave the relaxed problem unbounded: start again with the rows
      // that bound every torque (for in_plane: every row).
      partial = false;
      add_apex();
      Eigen::Map<Eigen::VectorXd>(z.data(), k) = N.transpose() * a_start;
      continue;
    }
    r.working_set_rounds = round + 1;
    r.working_set_rows = static_cast<int>(rows);
    // Rows outside the set that the solution violates join it, with their near neighbours
    // in value; none violated: the relaxed optimum is feasible, hence the full optimum.
    const Eigen::MatrixXd c = torque_values();
    std::vector<std::pair<int, int>> violated;
    for (Eigen::Index v = 0; v < V; ++v)
      for (int e = 0; e < F; ++e)
        if (c(e, v) > options.constraint_tol && !in_set.count({e, static_cast<int>(v)}))
          violated.push_back({e, static_cast<int>(v)});
    if (violated.empty() || data.evaluations >= options.max_iterations) break;
    in_set.insert(violated.begin(), violated.end());
    add_near(c);
  }
  if (data.cancelled) throw Cancelled();
  r.iterations = data.evaluations;
  accept_slsqp(problem, use_lp, N * Eigen::Map<const Eigen::VectorXd>(z.data(), k), g_start, r, a);
}

// The result's figures from the coefficients a: forces, normal forces, out-of-plane shares,
// objective terms, residual, and each wire's torques.
void fill_results(const ForceProblem& problem, const Network& net, const std::vector<int>& hooks,
                  const std::vector<int>& cuts, const Eigen::VectorXd& a, const ProgressFn& progress,
                  ForceResult& r) {
  const int K = problem.columns();
  const Eigen::MatrixXd& M = problem.equilibrium();
  r.coefficients = a;
  r.forces = problem.forces(a);
  const int C = static_cast<int>(net.crossings.size());
  r.normal.assign(C, 0.0);
  for (int c = 0; c < C; ++c) {
    if (hooks[c] == 0) continue;
    const Crossing& x = net.crossings[c];
    const Vec3 d = net.wires[x.wires[0]].plane.normal.cross(net.wires[x.wires[1]].plane.normal).normalized();
    r.normal[c] = -static_cast<double>(hooks[c]) * r.forces[c].dot(d);
  }
  const OutOfPlaneShares shares = out_of_plane_shares(net, hooks, r.forces);
  r.out_of_plane = shares.share;
  r.mean_out_of_plane = shares.mean;
  r.max_out_of_plane = shares.max;
  r.mean_out_of_plane_to_max_force = shares.mean_to_max_force;
  r.max_out_of_plane_to_max_force = shares.max_to_max_force;
  r.g_stb = problem.normal_weights().dot(a);
  r.assembly_residual = a.dot(problem.assembly_matrix() * a);
  r.g_asm = -problem.weight() * r.assembly_residual;
  double scale = 0.0;
  for (int j = 0; j < K; ++j) scale += std::abs(a(j)) * M.col(j).norm();
  r.equilibrium_residual = scale > 0 ? (M * a).norm() / scale : 0.0;
  // Per-wire torques, from the 3D sums (the out-of-plane part is reported too).
  r.wires.resize(net.wires.size());
  for (int w = 0; w < static_cast<int>(net.wires.size()); ++w) {
    report_progress(progress, "forces", 0.9 + 0.1 * w / static_cast<double>(net.wires.size()));
    const RestShapeResult rs = rest_shape(net.wires[w], cuts[w], wire_loads(net, hooks, r.forces, w), RestShapeOptions{});
    r.wires[w].max_torque = rs.max_torque;
    r.wires[w].max_torque_vertex = rs.max_torque_vertex;
    for (double t : rs.out_of_plane_torque) r.wires[w].max_out_of_plane = std::max(r.wires[w].max_out_of_plane, t);
    for (std::size_t k = 0; k < rs.torque.size(); ++k)
      r.wires[w].max_torque_3d = std::max(r.wires[w].max_torque_3d, std::hypot(rs.torque[k], rs.out_of_plane_torque[k]));
    if (r.wires[w].max_torque_3d > (1.0 + 1e-6) * r.t_max)
      r.warnings.push_back(wname(net, w) + ": in-plane bending, out-of-plane bending and twist together reach " +
                           std::to_string(r.wires[w].max_torque_3d) + " N m, above t_max = " + std::to_string(r.t_max) +
                           " N m (torque_bound in_plane bounds in-plane bending only; see docs/method-forces.md, §3)");
  }
}

}  // namespace

ForceResult optimize_forces(const Network& net, const std::vector<int>& hooks, const std::vector<std::vector<int>>& steps,
                            const std::vector<int>& cuts, const ForceOptions& options, const ProgressFn& progress) {
  const auto start = std::chrono::steady_clock::now();
  auto since = [](std::chrono::steady_clock::time_point t0) {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  };
  report_progress(progress, "forces", 0.0);
  const ForceProblem problem(net, hooks, steps, cuts, options);
  const int K = problem.columns();
  ForceResult r;
  r.cuts = cuts;
  r.t_max = problem.t_max();
  r.column_crossing = problem.column_crossing();
  Eigen::VectorXd a = Eigen::VectorXd::Zero(K);
  const Eigen::MatrixXd& M = problem.equilibrium();

  const bool use_lp = options.algorithm != ForceAlgorithm::slsqp;
  const bool least = options.least_out_of_plane && options.algorithm != ForceAlgorithm::slsqp;
  bool carried = use_lp && problem.carried_rows().rows() > 0;
  const bool use_nlp = options.algorithm == ForceAlgorithm::slsqp ||
                       (options.algorithm == ForceAlgorithm::lp_then_slsqp && !least && !carried &&
                        problem.weight() > 0 && problem.assembly_matrix().squaredNorm() > 0);
  if (K > 0 && use_lp) {
    bool held = false;
    if (carried) {
      try {
        solve_by_lp(problem, net, options, least, true, progress, r, a);
        held = problem.normal_weights().dot(a) > 1e-9 * problem.t_max() / problem.length_scale();
      } catch (const SolverError&) {
        held = false;  // no forces keep the carried ones in their pyramids
      }
    }
    // Only zero forces, or none, keep the carried ones in their pyramids: the planar model's forces.
    if (!held) solve_by_lp(problem, net, options, least, false, progress, r, a);
    carried = held;
  }
  r.carried_3d = carried;
  report_progress(progress, "forces", 0.5);

  if (K > 0 && use_nlp) {
    const auto t0 = std::chrono::steady_clock::now();
    // Null space of M: a = N z keeps M a = 0 to rounding.
    Eigen::BDCSVD<Eigen::MatrixXd> svd(M, Eigen::ComputeFullV);
    const Eigen::VectorXd& sv = svd.singularValues();
    const double tol = 1e-10 * std::max(1.0, sv.size() ? sv(0) : 1.0);
    int rank = 0;
    for (Eigen::Index i = 0; i < sv.size(); ++i)
      if (sv(i) > tol) ++rank;
    const Eigen::MatrixXd N = svd.matrixV().rightCols(K - rank);
    const int k = static_cast<int>(N.cols());
    if (k > 0) {
      slsqp_in_null_space(problem, options, use_lp, N, progress, r, a);
    } else if (!use_lp) {
      r.method = "slsqp";
    }
    r.nlp_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  }
  if (r.method.empty()) r.method = use_lp ? "lp" : "slsqp";
  report_progress(progress, "forces", 0.9);

  // Every constraint but the torque rows is homogeneous in a (M a = 0, a >= 0, N_k >= 0): forces
  // that a solver's tolerance left outside the 3D bound's polytope (SLSQP's result is accepted
  // up to 1e-7 relative) are scaled into it, so that |t_v| <= t_max holds to rounding.
  Eigen::VectorXd gauges = problem.torque_gauges(a);
  if (options.torque_bound == TorqueBound::full_3d && gauges.size() > 0 && gauges.maxCoeff() > 1.0) {
    a /= gauges.maxCoeff();
    gauges = problem.torque_gauges(a);
  }
  r.torque_bound = options.torque_bound;
  r.torque_active = gauges.size() > 0 && gauges.maxCoeff() >= 1.0 - 1e-6;

  fill_results(problem, net, hooks, cuts, a, progress, r);
  if (problem.carried_map().rows() > 0) {
    r.carried_forces.assign(net.crossings.size(), Vec3::Zero());
    const Eigen::VectorXd f3 = problem.carried_map() * a + problem.carried_weight();
    r.carried_weights.assign(net.crossings.size(), Vec3::Zero());
    for (int h = 0; h < K / 4; ++h) {
      r.carried_forces[r.column_crossing[4 * h]] = f3.segment<3>(3 * h);
      r.carried_weights[r.column_crossing[4 * h]] = problem.carried_weight().segment<3>(3 * h);
    }
  }
  r.seconds = since(start);
  report_progress(progress, "forces", 1.0);
  return r;
}

}  // namespace wiresculpt
