// The QP's written-out triangular solves (exact/small_triangular.hpp) against Eigen's own
// triangularView solves, bit for bit, and against the solution itself (L x = b to rounding).
#include <catch2/catch.hpp>
#include <Eigen/Cholesky>
#include <Eigen/Dense>
#include <bit>
#include <cstdint>
#include <random>

#include "exact/small_triangular.hpp"

using wiresculpt::detail::lower_solve_in_place;
using wiresculpt::detail::lower_transpose_solve_in_place;

namespace {

bool same_bits(const Eigen::VectorXd& a, const Eigen::VectorXd& b) {
  if (a.size() != b.size()) return false;
  for (Eigen::Index i = 0; i < a.size(); ++i)
    if (std::bit_cast<std::uint64_t>(a[i]) != std::bit_cast<std::uint64_t>(b[i])) return false;
  return true;
}

// A Cholesky factor of a random symmetric positive definite matrix (as the QP gets it), and a
// right-hand side with some exact zeros (Eigen skips the division and the column update there).
struct Case {
  Eigen::LLT<Eigen::MatrixXd> llt;
  Eigen::VectorXd b;
};

Case random_case(std::mt19937& rng, int n) {
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  Eigen::MatrixXd M(n, n);
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) M(i, j) = u(rng);
  Eigen::MatrixXd W = M * M.transpose() + 0.1 * Eigen::MatrixXd::Identity(n, n);
  Case c{Eigen::LLT<Eigen::MatrixXd>(W), Eigen::VectorXd(n)};
  for (int i = 0; i < n; ++i) c.b[i] = u(rng) < -0.7 ? 0.0 : u(rng) * 1e3;
  return c;
}

}  // namespace

TEST_CASE("the QP's triangular solves give Eigen's results to the bit", "[target][sqp]") {
  std::mt19937 rng(20261204);
  for (int n = 1; n <= 40; ++n)
    for (int trial = 0; trial < 25; ++trial) {
      const Case c = random_case(rng, n);
      REQUIRE(c.llt.info() == Eigen::Success);
      const double* L = c.llt.matrixLLT().data();
      INFO("n = " << n << ", trial " << trial);

      Eigen::VectorXd eigen_l = c.b, ours_l = c.b;
      c.llt.matrixL().solveInPlace(eigen_l);
      lower_solve_in_place(L, n, n, ours_l.data());
      CHECK(same_bits(eigen_l, ours_l));

      Eigen::VectorXd eigen_u = c.b, ours_u = c.b;
      c.llt.matrixU().solveInPlace(eigen_u);
      lower_transpose_solve_in_place(L, n, n, ours_u.data());
      CHECK(same_bits(eigen_u, ours_u));

      Eigen::VectorXd eigen_w = c.b, ours_w = c.b;  // W⁻¹ b, both halves
      c.llt.solveInPlace(eigen_w);
      lower_solve_in_place(L, n, n, ours_w.data());
      lower_transpose_solve_in_place(L, n, n, ours_w.data());
      CHECK(same_bits(eigen_w, ours_w));
    }
}

TEST_CASE("the QP's triangular solves solve their systems", "[target][sqp]") {
  // Independent of Eigen's solvers: the residuals of L x = b and Lᵀ x = b, by plain products.
  std::mt19937 rng(7);
  for (int n : {1, 2, 3, 7, 8, 9, 15, 16, 17, 33}) {
    const Case c = random_case(rng, n);
    const Eigen::MatrixXd L = c.llt.matrixL();
    Eigen::VectorXd x = c.b;
    lower_solve_in_place(c.llt.matrixLLT().data(), n, n, x.data());
    CHECK((L * x - c.b).norm() <= 1e-9 * (1.0 + c.b.norm()) * L.norm() * x.norm() + 1e-12);
    Eigen::VectorXd y = c.b;
    lower_transpose_solve_in_place(c.llt.matrixLLT().data(), n, n, y.data());
    CHECK((L.transpose() * y - c.b).norm() <= 1e-9 * (1.0 + c.b.norm()) * L.norm() * y.norm() + 1e-12);
  }
}
