// Eq. 1 with GLPK against hand arguments and against an independent cone test (non-negative least
// squares, Lawson-Hanson, on the paper's full 6P-row system with torques about the origin).
#include <Eigen/Dense>
#include <catch2/catch.hpp>
#include <cmath>
#include <numbers>
#include <random>

#include "wiresculpt/contact.hpp"
#include "wiresculpt/error.hpp"
#include "wiresculpt/stability.hpp"
#include "wire_fixtures.hpp"

using namespace wiresculpt;
using Eigen::MatrixXd;
using Eigen::VectorXd;

namespace {
constexpr double R = 0.1;

Network great_circles(int count) {
  auto cuts = fixtures::great_circle_cuts();
  cuts.resize(count);
  return build_network(fixtures::sphere_wires(cuts, R));
}

// Lawson-Hanson: x >= 0 minimising |A x - b|.
VectorXd nnls(const MatrixXd& A, const VectorXd& b) {
  const Eigen::Index n = A.cols();
  VectorXd x = VectorXd::Zero(n);
  std::vector<char> passive(n, 0);
  for (int outer = 0; outer < 10 * n + 10; ++outer) {
    const VectorXd w = A.transpose() * (b - A * x);
    Eigen::Index j = -1;
    double wmax = 1e-12;
    for (Eigen::Index k = 0; k < n; ++k)
      if (!passive[k] && w[k] > wmax) {
        wmax = w[k];
        j = k;
      }
    if (j < 0) break;
    passive[j] = 1;
    for (int inner = 0; inner < 10 * n + 10; ++inner) {
      std::vector<Eigen::Index> idx;
      for (Eigen::Index k = 0; k < n; ++k)
        if (passive[k]) idx.push_back(k);
      MatrixXd Ap(A.rows(), static_cast<Eigen::Index>(idx.size()));
      for (std::size_t k = 0; k < idx.size(); ++k) Ap.col(static_cast<Eigen::Index>(k)) = A.col(idx[k]);
      const VectorXd zp = Ap.completeOrthogonalDecomposition().solve(b);
      VectorXd z = VectorXd::Zero(n);
      for (std::size_t k = 0; k < idx.size(); ++k) z[idx[k]] = zp[static_cast<Eigen::Index>(k)];
      bool positive = true;
      for (Eigen::Index k : idx) positive = positive && z[k] > 1e-15;
      if (positive) {
        x = z;
        break;
      }
      double alpha = 1.0;
      for (Eigen::Index k : idx)
        if (z[k] <= 1e-15) alpha = std::min(alpha, x[k] / (x[k] - z[k]));
      x += alpha * (z - x);
      for (Eigen::Index k : idx)
        if (x[k] <= 1e-14) {
          x[k] = 0.0;
          passive[k] = 0;
        }
    }
  }
  return x;
}

// The paper's test, written independently: M with torques about the origin, all 6P rows, every
// column of L plus the negative sum, feasibility by NNLS.
bool independent_stable(const Network& net, const std::vector<int>& wires, const std::vector<int>& hooks,
                        bool forces_only) {
  const int P = static_cast<int>(wires.size());
  auto block = [&](int w) {
    for (int k = 0; k < P; ++k)
      if (wires[k] == w) return k;
    return -1;
  };
  MatrixXd M(6 * P, 0);
  for (int c = 0; c < static_cast<int>(net.crossings.size()); ++c) {
    const int b0 = block(net.crossings[c].wires[0]), b1 = block(net.crossings[c].wires[1]);
    if (hooks[c] == 0 || b0 < 0 || b1 < 0) continue;
    for (const Vec3& f : contact_pyramid(net, c, hooks[c])) {
      M.conservativeResize(Eigen::NoChange, M.cols() + 1);
      M.col(M.cols() - 1).setZero();
      const Vec3 t = net.crossings[c].point.cross(f);
      M.block<3, 1>(6 * b0, M.cols() - 1) = f;
      M.block<3, 1>(6 * b0 + 3, M.cols() - 1) = t;
      M.block<3, 1>(6 * b1, M.cols() - 1) = -f;
      M.block<3, 1>(6 * b1 + 3, M.cols() - 1) = -t;
    }
  }
  MatrixXd L = load_basis(P);
  L.conservativeResize(Eigen::NoChange, L.cols() + 1);
  L.col(L.cols() - 1) = -L.leftCols(L.cols() - 1).rowwise().sum();
  if (forces_only) {  // keep the force rows and the loads that act on forces
    std::vector<Eigen::Index> rows, loads;
    for (Eigen::Index r = 0; r < 6 * P; ++r)
      if (r % 6 < 3) rows.push_back(r);
    MatrixXd M3(static_cast<Eigen::Index>(rows.size()), M.cols()), L3(static_cast<Eigen::Index>(rows.size()), L.cols());
    for (std::size_t k = 0; k < rows.size(); ++k) {
      M3.row(static_cast<Eigen::Index>(k)) = M.row(rows[k]);
      L3.row(static_cast<Eigen::Index>(k)) = L.row(rows[k]);
    }
    M = M3;
    L = L3;
  }
  for (Eigen::Index j = 0; j < L.cols(); ++j) {
    const VectorXd b = -L.col(j);
    if (b.norm() == 0) continue;
    if (M.cols() == 0) return false;
    const VectorXd a = nnls(M, b);
    if ((M * a - b).norm() > 1e-7 * b.norm()) return false;
  }
  return true;
}
}  // namespace

TEST_CASE("stability: the load basis is the paper's L and spans the self-equilibrated loads") {
  const MatrixXd L = load_basis(3);
  REQUIRE(L.rows() == 18);
  REQUIRE(L.cols() == 12);
  CHECK(L(0, 0) == 1);
  CHECK(L(12, 0) == -1);
  CHECK(L(17, 11) == -1);
  CHECK(L(12, 1) == 0);
  for (Eigen::Index j = 0; j < L.cols(); ++j)
    for (int comp = 0; comp < 6; ++comp) CHECK(L(comp, j) + L(6 + comp, j) + L(12 + comp, j) == 0);
  CHECK(Eigen::FullPivLU<MatrixXd>(L).rank() == 12);
  CHECK_THROWS_AS(load_basis(1), InputError);
}

TEST_CASE("stability: two interlocked wires are stable under forces only and unstable with torques") {
  // Great circles X and Y cross at the poles on the z axis (d = +z). Opposite hooks at the two
  // poles: the bottom crossing pushes X along +z, the top along -z, and each pyramid has
  // transverse parts along ±x and ±y, so the forces on X positively span R^3. Every contact
  // force acts at a point of the z axis, so no torque about z can be balanced.
  const Network net = great_circles(2);
  REQUIRE(net.crossings.size() == 2);
  REQUIRE(net.crossings[0].point.z() < 0);
  const std::vector<int> hooks{-1, 1};
  StabilityOptions forces;
  forces.forces_only = true;
  const auto f = check_stability(net, {0, 1}, hooks, {}, forces);
  CHECK(f.stable);
  CHECK(f.lp_solves == 4);  // 3 force loads + the negative sum
  const auto t = check_stability(net, {0, 1}, hooks);
  CHECK_FALSE(t.stable);
  CHECK(t.failed_wire == 1);
  CHECK(t.failed_component == 5);  // torque about z
  const WrenchMatrix W = wrench_matrix(net, {0, 1}, hooks);
  CHECK(W.M.row(5).norm() < 1e-15);
  CHECK(W.M.row(11).norm() < 1e-15);
  CHECK(independent_stable(net, {0, 1}, hooks, true));
  CHECK_FALSE(independent_stable(net, {0, 1}, hooks, false));
}

TEST_CASE("stability: flipping one hook of the stable pair makes it unstable") {
  // Both hooks +1: every pyramid vector pushes X along -z (z component -sin(beta) < 0), so no
  // combination can push X sideways with zero z force: the first load (a force along x on Y,
  // i.e. -x on X) already fails.
  const Network net = great_circles(2);
  const std::vector<int> hooks{1, 1};
  const WrenchMatrix W = wrench_matrix(net, {0, 1}, hooks, {}, true);
  for (Eigen::Index j = 0; j < W.M.cols(); ++j) CHECK(W.M(2, j) < 0);
  StabilityOptions forces;
  forces.forces_only = true;
  const auto r = check_stability(net, {0, 1}, hooks, {}, forces);
  CHECK_FALSE(r.stable);
  CHECK(r.failed_wire == 1);
  CHECK(r.failed_component == 0);
  CHECK_FALSE(check_stability(net, {0, 1}, {-1, -1}, {}, forces).stable);
  CHECK(check_stability(net, {0, 1}, {1, -1}, {}, forces).stable);
}

TEST_CASE("stability: three great circles interlocked at all six crossings are stable") {
  const Network net = great_circles(3);
  REQUIRE(net.crossings.size() == 6);
  // Crossings come in diametric pairs (0,1), (2,3), (4,5) of one wire pair each, sorted along d.
  const std::vector<int> hooks{1, -1, 1, -1, 1, -1};
  // Independent argument: each crossing's four vectors sum to -4 s sin(beta) d, and opposite
  // hooks at the two ends of a diameter cancel in force and torque, so a = 1 is a strictly
  // positive solution of M a = 0. Then the cone of the columns is their whole span, and the
  // structure is stable iff that span is the 12-dimensional space of self-equilibrated loads.
  const WrenchMatrix W = wrench_matrix(net, {0, 1, 2}, hooks);
  CHECK((W.M * VectorXd::Ones(W.M.cols())).norm() < 1e-12);
  CHECK(Eigen::FullPivLU<MatrixXd>(W.M).setThreshold(1e-9).rank() == 12);
  const auto r = check_stability(net, {0, 1, 2}, hooks);
  CHECK(r.stable);
  CHECK(r.lp_solves == 13);
  CHECK(independent_stable(net, {0, 1, 2}, hooks, false));
  // Any order of the wires gives the same verdict.
  CHECK(check_stability(net, {2, 0, 1}, hooks).stable);
}

TEST_CASE("stability: three great circles with four null crossings are not stable") {
  // Two hooked crossings give 8 columns; a cone of 8 vectors cannot contain the 12-dimensional
  // space of self-equilibrated loads of three wires (that needs at least 13).
  const Network net = great_circles(3);
  const std::vector<int> full{1, -1, 1, -1, 1, -1};
  for (int a = 0; a < 6; ++a)
    for (int b = a + 1; b < 6; ++b) {
      std::vector<int> hooks(6, 0);
      hooks[a] = full[a];
      hooks[b] = full[b];
      CHECK_FALSE(check_stability(net, {0, 1, 2}, hooks).stable);
    }
}

TEST_CASE("stability: GLPK agrees with an independent cone test on every hook configuration") {
  const Network net = great_circles(3);
  std::vector<int> hooks(6);
  int stable = 0, total = 0;
  StabilityChecker checker(net);
  for (int code = 0; code < 729; ++code) {
    int rest = code;
    for (int c = 0; c < 6; ++c) {
      hooks[c] = rest % 3 - 1;
      rest /= 3;
    }
    const bool mine = checker.check({0, 1, 2}, hooks, false).stable;
    CHECK(mine == independent_stable(net, {0, 1, 2}, hooks, false));
    stable += mine;
    ++total;
    // Forces only on a pair, too.
    const bool pair = checker.check({0, 2}, hooks, true).stable;
    CHECK(pair == independent_stable(net, {0, 2}, hooks, true));
  }
  CHECK(stable > 0);
  CHECK(stable < total);
  CHECK(checker.lp_solves() > 0);
}

TEST_CASE("stability: the objective of Eq. 1 never changes the verdict") {
  const Network net = great_circles(3);
  StabilityChecker feasibility(net, {}, false), paper(net, {}, true);
  std::vector<int> hooks(6);
  for (int code = 0; code < 729; ++code) {
    int rest = code;
    for (int c = 0; c < 6; ++c) {
      hooks[c] = rest % 3 - 1;
      rest /= 3;
    }
    CHECK(feasibility.check({0, 1, 2}, hooks, false).stable == paper.check({0, 1, 2}, hooks, false).stable);
  }
}

TEST_CASE("stability: every column of M is self-equilibrated (Newton's third law)") {
  const Network net = great_circles(3);
  const WrenchMatrix W = wrench_matrix(net, {0, 1, 2}, {1, 1, -1, 0, 1, -1});
  REQUIRE(W.M.cols() == 20);
  for (Eigen::Index j = 0; j < W.M.cols(); ++j) {
    Eigen::Matrix<double, 6, 1> total = Eigen::Matrix<double, 6, 1>::Zero();
    for (int w = 0; w < 3; ++w) total += W.M.block<6, 1>(6 * w, j);
    CHECK(total.norm() < 1e-15);
    // Unit force on the crossing's first wire.
    const int c = W.column_crossing[j];
    CHECK(W.M.block<3, 1>(6 * net.crossings[c].wires[0], j).norm() == Approx(1.0));
  }
}

TEST_CASE("stability: inputs are validated") {
  const Network net = great_circles(2);
  CHECK_THROWS_AS(check_stability(net, {0, 1}, {1}), InputError);
  CHECK_THROWS_AS(check_stability(net, {0, 0}, {1, -1}), InputError);
  CHECK_THROWS_AS(check_stability(net, {0, 5}, {1, -1}), InputError);
  CHECK_THROWS_AS(check_stability(net, {0, 1}, {2, -1}), InputError);
  CHECK(check_stability(net, {0}, {1, -1}).stable);  // one body: only the zero load
  CHECK_FALSE(check_stability(net, {0, 1}, {0, 0}).stable);
}
