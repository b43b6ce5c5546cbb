#include "wiresculpt/stability.hpp"

#include <cmath>
#include <string>

#include "lp.hpp"
#include "wiresculpt/error.hpp"

namespace wiresculpt {
namespace {

std::string wire_name(const Network& net, int w) { return "'" + net.wires[w].name + "'"; }

void validate_set(const Network& net, const std::vector<int>& wires, const std::vector<int>& hooks,
                  bool allow_both = false) {
  const int P = static_cast<int>(net.wires.size());
  if (hooks.size() != net.crossings.size())
    throw InputError("stability: expected one hook per crossing (" + std::to_string(net.crossings.size()) +
                     "), got " + std::to_string(hooks.size()));
  for (std::size_t c = 0; c < hooks.size(); ++c)
    if (hooks[c] < -1 || hooks[c] > (allow_both ? 2 : 1))
      throw InputError("crossing " + std::to_string(c) + ": hook must be -1, 0 or 1, not " + std::to_string(hooks[c]));
  std::vector<char> seen(P, 0);
  for (int w : wires) {
    if (w < 0 || w >= P) throw InputError("stability: wire id " + std::to_string(w) + " does not exist");
    if (seen[w]) throw InputError("stability: wire " + wire_name(net, w) + " is listed twice");
    seen[w] = 1;
  }
}

Vec3 crossing_centroid(const Network& net) {
  Vec3 s = Vec3::Zero();
  for (const auto& c : net.crossings) s += c.point;
  return net.crossings.empty() ? s : Vec3(s / static_cast<double>(net.crossings.size()));
}

}  // namespace

Eigen::MatrixXd load_basis(int P) {
  if (P < 2) throw InputError("load_basis needs at least two polylines");
  Eigen::MatrixXd L = Eigen::MatrixXd::Zero(6 * P, 6 * (P - 1));
  for (int i = 0; i < 6 * P; ++i)
    for (int j = 0; j < 6 * (P - 1); ++j) {
      if (i == j) L(i, j) = 1.0;
      else if (i % 6 == j % 6 && i >= 6 * (P - 1)) L(i, j) = -1.0;
    }
  return L;
}

WrenchMatrix wrench_matrix(const Network& net, const std::vector<int>& wires, const std::vector<int>& hooks,
                           const ContactOptions& contact, bool forces_only) {
  validate(contact);
  validate_set(net, wires, hooks);
  const int q = forces_only ? 3 : 6;
  std::vector<int> pos(net.wires.size(), -1);
  for (std::size_t k = 0; k < wires.size(); ++k) pos[wires[k]] = static_cast<int>(k);
  WrenchMatrix out;
  out.reference = crossing_centroid(net);
  std::vector<int> used;
  for (int c = 0; c < static_cast<int>(net.crossings.size()); ++c) {
    const auto& x = net.crossings[c];
    if (hooks[c] != 0 && pos[x.wires[0]] >= 0 && pos[x.wires[1]] >= 0) used.push_back(c);
  }
  out.M = Eigen::MatrixXd::Zero(q * static_cast<Eigen::Index>(wires.size()), 4 * static_cast<Eigen::Index>(used.size()));
  Eigen::Index col = 0;
  for (int c : used) {
    const auto& x = net.crossings[c];
    const auto pyr = contact_pyramid(net, c, hooks[c], contact);
    for (const Vec3& b : pyr) {
      Eigen::Matrix<double, 6, 1> w;
      w << b, (x.point - out.reference).cross(b);
      out.M.block(q * pos[x.wires[0]], col, q, 1) = w.head(q);
      out.M.block(q * pos[x.wires[1]], col, q, 1) = -w.head(q);
      out.column_crossing.push_back(c);
      ++col;
    }
  }
  return out;
}

StabilityChecker::StabilityChecker(const Network& net, const ContactOptions& contact, bool minimise_sum)
    : net_(&net), minimise_sum_(minimise_sum) {
  validate(contact);
  reference_ = crossing_centroid(net);
  double ss = 0.0;
  for (const auto& c : net.crossings) ss += (c.point - reference_).squaredNorm();
  length_scale_ = net.crossings.empty() ? 1.0 : std::sqrt(ss / static_cast<double>(net.crossings.size()));
  if (!(length_scale_ > 1e-12)) length_scale_ = 1.0;
  for (int c = 0; c < static_cast<int>(net.crossings.size()); ++c) {
    const auto& x = net.crossings[c];
    const int P = static_cast<int>(net.wires.size());
    if (x.wires[0] < 0 || x.wires[0] >= P || x.wires[1] < 0 || x.wires[1] >= P || x.wires[0] == x.wires[1] ||
        !x.point.allFinite())
      throw InputError("crossing " + std::to_string(c) + " is malformed (wire ids or point); build the network "
                       "with build_network");
  }
  columns_.resize(net.crossings.size());
  for (int c = 0; c < static_cast<int>(net.crossings.size()); ++c)
    for (int h = 0; h < 2; ++h) {
      const auto pyr = contact_pyramid(net, c, h == 0 ? -1 : 1, contact);
      for (int k = 0; k < 4; ++k) {
        columns_[c][h][k].head<3>() = pyr[k];
        columns_[c][h][k].tail<3>() = (net.crossings[c].point - reference_).cross(pyr[k]) / length_scale_;
        if (!columns_[c][h][k].allFinite())
          throw InputError("crossing " + std::to_string(c) + ": its wires' planes give no finite contact direction "
                           "(parallel planes?)");
      }
    }
}

StabilityResult StabilityChecker::check(const std::vector<int>& wires, const std::vector<int>& hooks,
                                        bool forces_only) {
  const Network& net = *net_;
  validate_set(net, wires, hooks, true);
  StabilityResult result;
  const int P = static_cast<int>(wires.size());
  if (P <= 1) {
    result.stable = true;  // a single body: the only self-equilibrated load is zero
    return result;
  }
  const int q = forces_only ? 3 : 6;
  const int R = q * (P - 1);
  std::vector<int> pos(net.wires.size(), -1);
  for (int k = 0; k < P; ++k) pos[wires[k]] = k;

  // Sparse columns; rows of wires[0] (the reference) are dropped.
  std::vector<int> tri_row, tri_col;
  std::vector<double> tri_val;
  int K = 0;
  for (int c = 0; c < static_cast<int>(net.crossings.size()); ++c) {
    const auto& x = net.crossings[c];
    const int p0 = pos[x.wires[0]], p1 = pos[x.wires[1]];
    if (hooks[c] == 0 || p0 < 0 || p1 < 0) continue;
    const bool both = hooks[c] == 2;
    for (int k = 0; k < (both ? 8 : 4); ++k) {
      const auto& column = columns_[c][both ? k / 4 : (hooks[c] > 0 ? 1 : 0)][k % 4];
      for (int side = 0; side < 2; ++side) {
        const int p = side == 0 ? p0 : p1;
        if (p == 0) continue;
        const double sign = side == 0 ? 1.0 : -1.0;
        for (int r = 0; r < q; ++r) {
          const double v = sign * column[r];
          if (v == 0.0) continue;
          tri_row.push_back((p - 1) * q + r);
          tri_col.push_back(K);
          tri_val.push_back(v);
        }
      }
      ++K;
    }
  }
  if (K == 0) {  // nothing holds the wires together: no load but zero can be balanced
    result.failed_wire = wires.back();
    result.failed_component = 0;
    return result;
  }

  // Eq. 1 minimises Σ a; the verdict only needs feasibility (see stability.hpp).
  detail::EqualityLp lp(R, K, tri_row, tri_col, tri_val, std::vector<double>(K, minimise_sum_ ? 1.0 : 0.0));
  auto solve = [&](const std::vector<double>& want) -> bool {
    int attempts = 0;
    const detail::EqualityLp::Outcome outcome = lp.solve(want, &attempts);
    result.lp_solves += attempts;
    lp_solves_ += attempts;
    switch (outcome) {
      case detail::EqualityLp::Outcome::feasible:
        return true;
      case detail::EqualityLp::Outcome::infeasible:
        return false;
      case detail::EqualityLp::Outcome::internal_error:
        throw SolverError("GLPK stopped with an internal error while checking the stability of wire " +
                          wire_name(net, wires.back()) + "; please report this input");
      case detail::EqualityLp::Outcome::failed:
        break;
    }
    throw SolverError("the stability LP could not be solved (GLPK failed twice) while checking wire " +
                      wire_name(net, wires.back()));
  };

  // Eq. 1 has M a = -l: a basis load e_r asks for -1 in row r; the negative sum -Σ e_r for +1.
  std::vector<double> want(R, 0.0);
  for (int k = P - 1; k >= 1; --k)
    for (int comp = 0; comp < q; ++comp) {
      const int r = (k - 1) * q + comp;
      want[r] = -1.0;
      const bool ok = solve(want);
      want[r] = 0.0;
      if (!ok) {
        result.failed_wire = wires[k];
        result.failed_component = comp;
        return result;
      }
    }
  std::fill(want.begin(), want.end(), 1.0);
  if (!solve(want)) return result;
  result.stable = true;
  return result;
}

StabilityResult check_stability(const Network& net, const std::vector<int>& wires, const std::vector<int>& hooks,
                                const ContactOptions& contact, const StabilityOptions& options) {
  validate_set(net, wires, hooks);  // hooks = 2 (both pyramids) is for the search only
  StabilityChecker checker(net, contact, options.minimise_sum);
  return checker.check(wires, hooks, options.forces_only);
}

}  // namespace wiresculpt
