// The LP layer over GLPK (native/src/lp.hpp, glpk_guard.hpp): numbers GLPK cannot take are
// refused before it sees them, and an internal GLPK error inside the guard is a failed call, never
// an abort of the process (which would take Blender and the user's scene with it). Before the
// guard covered the problem's construction and scaling, the 1e±300 cases below aborted this
// binary in glp_set_rii / glp_set_sjj ("invalid scale factor").
#include <glpk.h>
#include <unistd.h>

#include <catch2/catch.hpp>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <limits>
#include <random>
#include <map>
#include <set>
#include <thread>
#include <tuple>
#include <vector>

#include "glpk_guard.hpp"  // native/src: private to the core
#include "lp.hpp"
#include "wire_fixtures.hpp"
#include "wiresculpt/forces.hpp"
#include "wiresculpt/torque_bound.hpp"

using namespace wiresculpt::detail;
using Catch::Matchers::Contains;

namespace {

// maximise 3x + 2y  s.t.  x + y <= 4,  x + 3y <= 6,  0 <= x <= 3,  y >= 0.
// By hand: the optimum is the vertex x = 3, x + y = 4, so (3, 1) with objective 11.
LinearProgram textbook() {
  LinearProgram lp;
  const double inf = std::numeric_limits<double>::infinity();
  lp.obj = {3.0, 2.0};
  lp.col_lo = {0.0, 0.0};
  lp.col_hi = {3.0, inf};
  lp.row_lo = {-inf, -inf};
  lp.row_hi = {4.0, 6.0};
  lp.tri_row = {0, 0, 1, 1};
  lp.tri_col = {0, 1, 0, 1};
  lp.tri_val = {1.0, 1.0, 1.0, 3.0};
  return lp;
}

void check_textbook() {
  const LpSolution sol = solve_lp(textbook());
  REQUIRE(sol.status == LpSolution::optimal);
  CHECK(sol.objective == Approx(11.0));
  CHECK(sol.x[0] == Approx(3.0));
  CHECK(sol.x[1] == Approx(1.0));
}

LinearProgram with_entries(double a, double b, double c, double d) {
  LinearProgram lp = textbook();
  lp.tri_val = {a, b, c, d};
  return lp;
}

void bad_glpk_call(void*) {
  glp_prob* p = glp_create_prob();
  glp_add_rows(p, -1);  // GLPK: "glp_add_rows: nrs = -1; invalid number of rows", then abort
}

// A family of small LPs, each different (some infeasible or unbounded through their bounds), from
// a fixed seed: what the two-thread test solves serially and then from two threads at once.
std::vector<LinearProgram> lp_family(int count) {
  std::mt19937 rng(15);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  const double inf = std::numeric_limits<double>::infinity();
  std::vector<LinearProgram> out;
  for (int k = 0; k < count; ++k) {
    LinearProgram lp;
    const int rows = 3 + k % 5, cols = 4 + k % 7;
    lp.maximise = k % 2 == 0;
    for (int j = 0; j < cols; ++j) {
      lp.obj.push_back(u(rng));
      lp.col_lo.push_back(k % 11 == 0 ? -inf : 0.0);  // free columns: some are unbounded
      lp.col_hi.push_back(k % 3 == 0 ? inf : 1.0 + u(rng));
    }
    for (int i = 0; i < rows; ++i) {
      lp.row_lo.push_back(k % 13 == 0 ? 5.0 : -inf);  // a row no x in the box reaches: infeasible
      lp.row_hi.push_back(2.0 + u(rng));
      for (int j = 0; j < cols; ++j) {
        lp.tri_row.push_back(i);
        lp.tri_col.push_back(j);
        lp.tri_val.push_back(u(rng));
      }
    }
    out.push_back(lp);
  }
  return out;
}

struct Answer {
  int status = -1;
  double objective = 0.0;
  std::vector<double> x;
  std::vector<int> warm;  // the equality LP's outcomes over its right-hand sides
  bool operator==(const Answer&) const = default;
};

// Each LP of the family, then a kept-alive equality LP (the stability check's warm-started dual
// simplex) over 40 right-hand sides.
std::vector<Answer> solve_family(const std::vector<LinearProgram>& family) {
  std::vector<Answer> out;
  for (const LinearProgram& lp : family) {
    const LpSolution sol = solve_lp(lp);
    out.push_back({sol.status, sol.objective, sol.x, {}});
  }
  Answer warm;
  EqualityLp eq(2, 4, {0, 0, 0, 1, 1, 1}, {0, 1, 2, 1, 2, 3}, {1.0, 2.0, -1.0, 1.0, -3.0, 1.0}, {1.0, 1.0, 2.0, 0.5});
  for (int k = 0; k < 40; ++k) warm.warm.push_back(static_cast<int>(eq.solve({std::sin(k * 0.7), std::cos(k * 1.3)})));
  out.push_back(warm);
  return out;
}

// solve_family on a thread of its own, which frees its GLPK environment before it ends (GLPK
// does not free a thread's environment when the thread exits; the sanitizer build would report it).
std::vector<Answer> on_own_thread(const std::vector<LinearProgram>& family) {
  std::vector<Answer> out = solve_family(family);
  glp_free_env();
  return out;
}

}  // namespace

TEST_CASE("lp: the textbook LP solves to its vertex found by hand", "[lp]") { check_textbook(); }

TEST_CASE("lp: a matrix with 1e+-300 entries is refused with a reason, not an abort", "[lp][robustness]") {
  // Each of these aborted GLPK (scale factors 0, or a zero pivot in its factorisation).
  const std::vector<LinearProgram> cases = {with_entries(1e-300, 1e-300, 1e-300, 1e-300),
                                            with_entries(1e300, 1e300, 1e300, 1e300),
                                            with_entries(1e300, 1e-300, 1.0, 1.0),
                                            with_entries(1e-300, 0.0, 0.0, 1e300)};
  for (const LinearProgram& lp : cases) {
    const LpSolution sol = solve_lp(lp);
    CHECK(sol.status == LpSolution::failed);
    CHECK_THAT(sol.reason, Contains("outside the range the LP solver handles (magnitudes 1e-100 to 1e100)"));
  }
  // Column 0 of only 1e-300 entries: not rounding noise of a larger entry, refused.
  const LpSolution first = solve_lp(with_entries(1e-300, 1.0, 1e-300, 1.0));
  CHECK(first.reason == "a coefficient (row 0, column 0) is 1e-300, outside the range the LP solver handles "
                        "(magnitudes 1e-100 to 1e100)");
  LinearProgram nan = textbook();
  nan.obj[1] = std::numeric_limits<double>::quiet_NaN();
  CHECK_THAT(solve_lp(nan).reason, Contains("objective coefficient 1 is nan"));
  LinearProgram outside = textbook();
  outside.tri_col[3] = 5;
  CHECK(solve_lp(outside).reason == "a coefficient names row 1, column 5, outside the LP");
  // The ends of the range still solve (1e+-100 in one matrix; by hand x + y <= 4 binds no more).
  const LpSolution edge = solve_lp(with_entries(1e-100, 1e-100, 1.0, 3.0));
  CHECK(edge.status == LpSolution::optimal);
  check_textbook();
}

TEST_CASE("lp: entries below 1e-100 that are rounding noise of their column solve as zeros do", "[lp][robustness]") {
  // A plane normal [1e-99, 1, 0] gave a force-LP entry of 9e-101 beside ones of order 1, refused
  // as out of range; [1e-300, 1, 0] stopped GLPK. Such entries are below 1e-13 of their column's
  // largest: zeros in all but representation. By hand, with entry a = 0 the rows are y <= 4 and
  // x + 3y <= 6, 0 <= x <= 3, maximise 3x + 2y: x = 3, then 3y <= 3, y = 1, objective 11.
  const LpSolution zero = solve_lp(with_entries(0.0, 1.0, 1.0, 3.0));
  REQUIRE(zero.status == LpSolution::optimal);
  CHECK(zero.objective == Approx(11.0));
  CHECK(zero.x[0] == Approx(3.0));
  CHECK(zero.x[1] == Approx(1.0));
  for (double tiny : {9e-101, 1e-200, 1e-300, -1e-300, 5e-324}) {
    const LpSolution sol = solve_lp(with_entries(tiny, 1.0, 1.0, 3.0));
    REQUIRE(sol.status == LpSolution::optimal);
    CHECK(sol.objective == zero.objective);
    CHECK(sol.x == zero.x);
  }
  // The stability checks' equality LP: [[1, 1e-300], [1e-300, 1]] x = (1, 2), x >= 0 is the
  // identity's x = (1, 2), feasible (it was an internal error); a column of only tiny entries is
  // still refused.
  EqualityLp noisy(2, 2, {0, 0, 1, 1}, {0, 1, 0, 1}, {1.0, 1e-300, 1e-300, 1.0}, {1.0, 1.0});
  CHECK(noisy.solve({1.0, 2.0}) == EqualityLp::Outcome::feasible);
  CHECK(noisy.solve({1.0, -2.0}) == EqualityLp::Outcome::infeasible);
  EqualityLp lone(2, 2, {0, 1, 1}, {0, 0, 1}, {1.0, 1e-300, 1.0}, {1.0, 1.0});
  CHECK(lone.solve({1.0, 1.0}) == EqualityLp::Outcome::feasible);
  EqualityLp refused(1, 2, {0, 0}, {0, 1}, {1e-300, 1.0}, {1.0, 1.0});  // column 0's only entry
  CHECK(refused.solve({1.0}) == EqualityLp::Outcome::internal_error);
}

TEST_CASE("lp: a GLPK internal error inside the guard returns, frees GLPK's environment, and GLPK works after",
          "[lp][robustness]") {
  const unsigned before = glpk_generation();
  // A warm-started problem made before the error loses its GLPK object with the environment.
  EqualityLp held(1, 2, {0, 0}, {0, 1}, {1.0, 1.0}, {1.0, 1.0});
  REQUIRE(held.solve({1.0}) == EqualityLp::Outcome::feasible);
  // The core never prints: GLPK's error report (it switches its terminal output on to print it)
  // must reach neither stdout (where GLPK writes) nor stderr. Capture fds 1 and 2 around the call.
  std::FILE* capture = std::tmpfile();
  REQUIRE(capture);
  std::fflush(stdout);
  std::fflush(stderr);
  const int saved_out = ::dup(1), saved_err = ::dup(2);
  ::dup2(::fileno(capture), 1);
  ::dup2(::fileno(capture), 2);
  const bool returned = run_guarded(bad_glpk_call, nullptr);
  std::fflush(stdout);
  std::fflush(stderr);
  ::dup2(saved_out, 1);
  ::dup2(saved_err, 2);
  ::close(saved_out);
  ::close(saved_err);
  std::fseek(capture, 0, SEEK_END);
  const long printed = std::ftell(capture);
  std::fclose(capture);
  CHECK_FALSE(returned);
  CHECK(printed == 0);
  CHECK(glpk_generation() == before + 1);
  CHECK(held.solve({2.0}) == EqualityLp::Outcome::internal_error);  // and its destructor must not free it
  check_textbook();
  EqualityLp fresh(1, 2, {0, 0}, {0, 1}, {1.0, 1.0}, {1.0, 1.0});
  CHECK(fresh.solve({2.0}) == EqualityLp::Outcome::feasible);
  CHECK(fresh.solve({-1.0}) == EqualityLp::Outcome::infeasible);  // x >= 0 cannot sum to -1
}

TEST_CASE("lp: an equality LP with numbers GLPK cannot take is an internal error, not an abort",
          "[lp][robustness]") {
  EqualityLp tiny(2, 2, {0, 0, 1, 1}, {0, 1, 0, 1}, {1e-300, 1e-300, 1e-300, 1e-300}, {1.0, 1.0});
  CHECK(tiny.solve({1.0, 1.0}) == EqualityLp::Outcome::internal_error);
  EqualityLp huge(2, 2, {0, 0, 1, 1}, {0, 1, 0, 1}, {1e300, 1e300, 1e300, 1e300}, {1.0, 1.0});
  CHECK(huge.solve({1.0, 1.0}) == EqualityLp::Outcome::internal_error);
  EqualityLp fine(2, 2, {0, 1}, {0, 1}, {1.0, 1.0}, {1.0, 1.0});
  CHECK(fine.solve({1.0, std::numeric_limits<double>::infinity()}) == EqualityLp::Outcome::internal_error);
  CHECK(fine.solve({1.0, 2.0}) == EqualityLp::Outcome::feasible);
}

TEST_CASE("lp: two threads solving LPs at once get the serial answers (GLPK's environment is per thread)",
          "[lp][threads]") {
  // The plane assistant screens and solves candidates on two threads; that is sound only when
  // GLPK keeps its environment (problem objects, error hook, terminal hook) per thread. GLPK
  // reports the storage class it was built with; Debian 12's libglpk40 5.0 says _Thread_local.
  const char* tls = glp_config("TLS");
  INFO("glp_config(\"TLS\") is null: this GLPK shares one environment between threads");
  REQUIRE(tls != nullptr);
  const std::vector<LinearProgram> family = lp_family(300);
  const std::vector<Answer> serial = solve_family(family);
  int optimal = 0, other = 0;
  for (std::size_t k = 0; k + 1 < serial.size(); ++k) (serial[k].status == LpSolution::optimal ? optimal : other)++;
  REQUIRE(optimal > 100);  // the family is not trivially all-failed
  REQUIRE(other > 10);     // and exercises the infeasible / unbounded exits too
  for (int round = 0; round < 3; ++round) {
    std::vector<Answer> a, b;
    std::thread first([&] { a = on_own_thread(family); });
    std::thread second([&] { b = on_own_thread(family); });
    first.join();
    second.join();
    CHECK(a == serial);
    CHECK(b == serial);
  }
}

TEST_CASE("lp: a GLPK internal error on one thread leaves another thread's LPs and environment alone",
          "[lp][threads][robustness]") {
  const std::vector<LinearProgram> family = lp_family(200);
  const std::vector<Answer> serial = solve_family(family);
  const unsigned before = glpk_generation();
  std::vector<Answer> solved;
  unsigned errors = 0, generations = 0;
  std::thread solver([&] { solved = on_own_thread(family); });
  std::thread failing([&] {
    const unsigned mine = glpk_generation();
    for (int k = 0; k < 50; ++k) errors += run_guarded(bad_glpk_call, nullptr) ? 0u : 1u;
    generations = glpk_generation() - mine;
    glp_free_env();
  });
  solver.join();
  failing.join();
  CHECK(errors == 50);
  CHECK(generations == 50);  // each error freed the failing thread's own environment
  CHECK(glpk_generation() == before);  // this thread's environment was never freed
  CHECK(solved == serial);
  check_textbook();
}

// ---- The cutting-plane loop (solve_lp_with_torque_rows): warm-started rounds against rebuilt ones.

namespace {

const double kInf = std::numeric_limits<double>::infinity();

// Warm and cold solves of one loop, from copies of the same LP.
struct Both {
  LpSolution warm, cold;
  int warm_rounds = 0, cold_rounds = 0;
  LinearProgram warm_lp;  // as the warm loop left it (its rows added)
};

Both solve_both(const LinearProgram& lp, const TorqueBlocks& blocks, const wiresculpt::TorquePolytope& polytope,
                double t_max) {
  Both b;
  b.warm_lp = lp;
  LinearProgram cold_lp = lp;
  std::set<std::pair<int, int>> warm_added, cold_added;
  b.warm = solve_lp_with_torque_rows(b.warm_lp, blocks, polytope, t_max, warm_added, &b.warm_rounds, true);
  b.cold = solve_lp_with_torque_rows(cold_lp, blocks, polytope, t_max, cold_added, &b.cold_rounds, false);
  return b;
}

// The force LP of optimize_forces without its cuts: maximise c·a subject to M a = 0,
// |n·t_v| <= t_max, N_k a >= 0, a >= 0.
LinearProgram force_lp(const wiresculpt::ForceProblem& problem) {
  const int K = problem.columns();
  LinearProgram lp;
  lp.obj.assign(problem.normal_weights().data(), problem.normal_weights().data() + K);
  lp.col_lo.assign(K, 0.0);
  lp.col_hi.assign(K, kInf);
  append_rows(lp, problem.equilibrium(), 0.0, 0.0);
  append_rows(lp, problem.torque_rows(), -problem.t_max(), problem.t_max());
  append_rows(lp, problem.normal_rows(), 0.0, kInf);
  return lp;
}

// Calls test(problem, force_lp(problem)) on the force problems of random hooked spheres drawn
// from `seed` (torque fraction 0.5, at least one column; each within INFO "attempt k") until it
// has returned true `wanted` times or 200 attempts are spent; returns how many times it did.
template <class Test>
int on_force_lps(unsigned seed, int wanted, Test test) {
  std::mt19937 rng(seed);
  int counted = 0;
  for (int attempt = 0; attempt < 200 && counted < wanted; ++attempt) {
    fixtures::HookedNetwork h;
    if (!fixtures::random_hooked_sphere(rng, attempt, 32, h)) continue;
    const auto cuts = wiresculpt::choose_cuts(h.net);
    wiresculpt::ForceOptions fo;
    fo.torque_fraction = 0.5;
    const wiresculpt::ForceProblem problem(h.net, h.hooks, h.steps, cuts, fo);
    if (problem.columns() == 0) continue;
    INFO("attempt " << attempt);
    if (test(problem, force_lp(problem))) ++counted;
  }
  return counted;
}

// The largest gauge of the blocks' torques at x (<= 1: every row of the polytope holds).
double worst_gauge(const TorqueBlocks& blocks, const wiresculpt::TorquePolytope& polytope, double t_max,
                   const std::vector<double>& x) {
  const Eigen::VectorXd t = blocks.A * Eigen::Map<const Eigen::VectorXd>(x.data(), blocks.A.cols()) + blocks.c;
  double worst = 0.0;
  for (Eigen::Index v = 0; v < t.size() / 3; ++v)
    worst = std::max(worst, wiresculpt::torque_gauge(polytope, t.segment<3>(3 * v), t_max));
  return worst;
}

// The textbook LP (maximise 3x + 2y, 0 <= x <= 3, y capped at 10) without its rows, and its
// rows x + y <= 4, x + 3y <= 6 as torque blocks of the slab polytope (rows ±n, t_max 4): block
// 0's n component is x + y, block 1's is (x + 3y) 4/6.
void textbook_as_cuts(LinearProgram& lp, TorqueBlocks& blocks) {
  lp.obj = {3.0, 2.0};
  lp.col_lo = {0.0, 0.0};
  lp.col_hi = {3.0, 10.0};
  blocks.A = Eigen::MatrixXd::Zero(6, 2);
  blocks.A.row(0) << 1.0, 1.0;
  blocks.A.row(3) << 4.0 / 6.0, 3.0 * 4.0 / 6.0;
  blocks.c = Eigen::VectorXd::Zero(6);
}

}  // namespace

TEST_CASE("lp: torque rows added as cuts reach the textbook vertex found by hand, warm from the first basis",
          "[lp][warm]") {
  // The textbook LP (maximise 3x + 2y, x + y <= 4, x + 3y <= 6, 0 <= x <= 3, y >= 0) with its two
  // rows as torque blocks of the slab polytope (rows ±n, t_max 4): block 0's n component is
  // x + y, block 1's is (x + 3y) 4/6. The LP starts without rows (y capped at 10): round 1 is the
  // box corner (3, 10), which violates both; round 2 adds both rows and must land on (3, 1), 11.
  LinearProgram lp;
  TorqueBlocks blocks;
  textbook_as_cuts(lp, blocks);
  const auto& slab = wiresculpt::torque_polytope(wiresculpt::TorqueBound::in_plane);
  const Both b = solve_both(lp, blocks, slab, 4.0);
  REQUIRE(b.warm.status == LpSolution::optimal);
  CHECK(b.warm.objective == Approx(11.0).epsilon(1e-12));
  CHECK(b.warm.x[0] == Approx(3.0).epsilon(1e-12));
  CHECK(b.warm.x[1] == Approx(1.0).epsilon(1e-12));
  CHECK(b.warm_rounds == 2);
  CHECK(b.warm.builds == 1);       // the second round added the rows to the problem GLPK held
  CHECK(b.warm.warm_solves == 1);
  CHECK(b.warm_lp.row_lo.size() == 2);
  REQUIRE(b.cold.status == LpSolution::optimal);
  CHECK(b.cold.objective == Approx(11.0).epsilon(1e-12));
  CHECK(b.cold.builds == 2);  // the rebuilding loop, for comparison
  CHECK(b.cold.warm_solves == 0);
}

TEST_CASE("lp: a torque along a direction grows to t_max over its gauge in the 3D polytope", "[lp][warm][torque]") {
  // maximise λ, t = λ d (one block, λ capped far above): the optimum is λ = t_max / max_k e_k·d,
  // taken over every row of the polytope directly (the loop sees only the rows it adds). d = n is
  // the polytope's vertex ±n t_max: λ = t_max exactly.
  const auto& poly = wiresculpt::torque_polytope(wiresculpt::TorqueBound::full_3d);
  const double t_max = 1.5;
  std::mt19937 rng(17);
  std::normal_distribution<double> gauss;
  std::vector<wiresculpt::Vec3> directions{wiresculpt::Vec3(1, 0, 0), wiresculpt::Vec3(-1, 0, 0)};
  for (int k = 0; k < 30; ++k) directions.push_back(wiresculpt::Vec3(gauss(rng), gauss(rng), gauss(rng)).normalized());
  for (const wiresculpt::Vec3& d : directions) {
    INFO("d = " << d.transpose());
    double largest = 0.0;
    for (const wiresculpt::Vec3& e : poly.rows) largest = std::max(largest, e.dot(d));
    const double expected = t_max / largest;
    LinearProgram lp;
    lp.obj = {1.0};
    lp.col_lo = {0.0};
    lp.col_hi = {1e3 * t_max};
    TorqueBlocks blocks{d, Eigen::VectorXd::Zero(3)};
    const Both b = solve_both(lp, blocks, poly, t_max);
    REQUIRE(b.warm.status == LpSolution::optimal);
    CHECK(b.warm.objective == Approx(expected).epsilon(1e-9));
    CHECK(b.cold.objective == Approx(expected).epsilon(1e-9));
    CHECK(worst_gauge(blocks, poly, t_max, b.warm.x) <= 1.0 + 1e-9);
    CHECK(b.warm_rounds >= 2);  // round 1 stops at the cap, far outside the polytope
    CHECK(b.warm.builds == 1);
    CHECK(b.warm.warm_solves == b.warm_rounds - 1);
  }
}

TEST_CASE("lp: warm-started torque rows reach the rebuilt optimum on generated force LPs", "[lp][warm][torque]") {
  // The force LP of optimize_forces on random hooked spheres: maximise c·a subject to M a = 0,
  // |n·t_v| <= t_max, N_k a >= 0, a >= 0, and the 3D polytope's rows as cuts. Warm and rebuilt
  // loops must agree on the optimum (relative 1e-7) and both satisfy every row of the polytope.
  int cut = 0, warm_taken = 0;
  long warm_iterations = 0, cold_iterations = 0;
  const int compared = on_force_lps(23, 12, [&](const wiresculpt::ForceProblem& problem, const LinearProgram& lp) {
    const TorqueBlocks blocks{problem.torque_frame_rows(), Eigen::VectorXd::Zero(problem.torque_frame_rows().rows())};
    const Both b = solve_both(lp, blocks, problem.polytope(), problem.t_max());
    REQUIRE(b.cold.status == b.warm.status);
    if (b.warm.status != LpSolution::optimal) return false;
    CHECK(b.warm.objective == Approx(b.cold.objective).epsilon(1e-7));
    CHECK(worst_gauge(blocks, problem.polytope(), problem.t_max(), b.warm.x) <= 1.0 + 1e-7);
    CHECK(worst_gauge(blocks, problem.polytope(), problem.t_max(), b.cold.x) <= 1.0 + 1e-7);
    CHECK(b.warm.warm_solves + b.warm.builds == b.warm_rounds);
    if (b.warm_rounds > 1) ++cut;
    if (b.warm_rounds > 1 && b.warm.builds == 1 && b.warm.warm_solves == b.warm_rounds - 1) ++warm_taken;
    warm_iterations += b.warm.iterations;
    cold_iterations += b.cold.iterations;
    return true;
  });
  CHECK(compared >= 10);
  CHECK(cut >= 5);  // LPs that needed cuts
  CHECK(warm_taken == cut);  // and every round after the first re-solved the problem GLPK held
  CHECK(warm_iterations < cold_iterations);  // and took fewer simplex steps than rebuilding
}

TEST_CASE("lp: the cutting-plane loop reaches the optimum of the LP that holds every row of the 3D polytope",
          "[lp][torque]") {
  // An independent answer: the force LP of random hooked spheres with all 180 rows of the 3D
  // polytope at every vertex loaded from the start (one plain solve_lp, no cuts). The loop must
  // reach its optimal value (relative 1e-7) with a small part of those rows, adding either the
  // violated neighbour rows too (the forces) or one row per vertex and round (the load capacity).
  int cut = 0;  // the networks of the warm-start test above (seed 23), 5 of which need cuts
  const int compared = on_force_lps(23, 12, [&](const wiresculpt::ForceProblem& problem, const LinearProgram& lp) {
    const Eigen::MatrixXd& T3 = problem.torque_frame_rows();
    const auto& poly = problem.polytope();
    LinearProgram full = lp;
    Eigen::MatrixXd every(static_cast<Eigen::Index>(poly.rows.size()) * (T3.rows() / 3), problem.columns());
    for (Eigen::Index v = 0; v < T3.rows() / 3; ++v)
      for (std::size_t k = 0; k < poly.rows.size(); ++k)
        every.row(v * static_cast<Eigen::Index>(poly.rows.size()) + static_cast<Eigen::Index>(k)) =
            poly.rows[k].transpose() * T3.middleRows(3 * v, 3);
    append_rows(full, every, -kInf, problem.t_max());
    const LpSolution all = solve_lp(full);
    const TorqueBlocks blocks{T3, Eigen::VectorXd::Zero(T3.rows())};
    INFO(every.rows() << " rows in all");
    for (const CutRows rule : {CutRows::with_neighbours, CutRows::most_violated}) {
      INFO((rule == CutRows::most_violated ? "most violated only" : "with neighbours"));
      LinearProgram grown = lp;
      std::set<std::pair<int, int>> added;
      int rounds = 0;
      const LpSolution loop =
          solve_lp_with_torque_rows(grown, blocks, poly, problem.t_max(), added, &rounds, true, nullptr, rule);
      REQUIRE(loop.status == all.status);
      if (all.status != LpSolution::optimal) continue;
      CHECK(loop.objective == Approx(all.objective).epsilon(1e-7));
      CHECK(worst_gauge(blocks, poly, problem.t_max(), loop.x) <= 1.0 + 1e-7);
      CHECK(added.size() * 10 < static_cast<std::size_t>(every.rows()));
      if (rule == CutRows::most_violated) {  // one row per vertex and round: rounds - 1 at most
        std::map<int, int> per_vertex;
        for (const auto& [v, _row] : added) ++per_vertex[v];
        for (const auto& [v, n] : per_vertex) CHECK(n <= rounds - 1);
        if (rounds > 1) ++cut;
      }
    }
    return all.status == LpSolution::optimal;
  });
  CHECK(compared >= 10);
  CHECK(cut >= 5);
}

TEST_CASE("lp: rows a round adds are checked as solve_lp checks them", "[lp][warm][robustness]") {
  // One column x in [0, 10] with the row x <= 8, maximise x; the block's torque is x a (frame n),
  // slab polytope, so round 1 (x = 8) adds the row a x <= t_max when a x > t_max.
  auto run = [](double a, double t_max, LpSolution* cold = nullptr) {
    LinearProgram lp;
    lp.obj = {1.0};
    lp.col_lo = {0.0};
    lp.col_hi = {10.0};
    lp.row_lo = {-kInf};
    lp.row_hi = {8.0};
    lp.tri_row = {0};
    lp.tri_col = {0};
    lp.tri_val = {1.0};
    TorqueBlocks blocks{Eigen::Vector3d(a, 0.0, 0.0), Eigen::VectorXd::Zero(3)};
    const auto& slab = wiresculpt::torque_polytope(wiresculpt::TorqueBound::in_plane);
    const Both b = solve_both(lp, blocks, slab, t_max);
    if (cold) *cold = b.cold;
    return b.warm;
  };
  // A coefficient GLPK cannot take: refused with solve_lp's reason, naming the added row.
  const LpSolution huge = run(1e200, 1.0);
  CHECK(huge.status == LpSolution::failed);
  CHECK(huge.reason == "a coefficient (row 1, column 0) is 1e+200, outside the range the LP solver handles "
                       "(magnitudes 1e-100 to 1e100)");
  // An added entry 1e14 times the held one makes that held entry rounding noise (below 1e-13 of
  // its column's largest), which a rebuild of the whole LP drops: the loop rebuilds rather than
  // keep it. By hand: 1e14 x <= 1e14 binds, x = 1.
  LpSolution cold;
  const LpSolution noisy = run(1e14, 1e14, &cold);
  REQUIRE(noisy.status == LpSolution::optimal);
  CHECK(noisy.builds == 2);
  CHECK(noisy.warm_solves == 0);
  CHECK(noisy.x[0] == Approx(1.0).epsilon(1e-9));
  CHECK(cold.x[0] == Approx(1.0).epsilon(1e-9));
  // An ordinary factor stays warm: 0.5 x <= 1, x = 2.
  const LpSolution fine = run(0.5, 1.0);
  REQUIRE(fine.status == LpSolution::optimal);
  CHECK(fine.builds == 1);
  CHECK(fine.warm_solves == 1);
  CHECK(fine.x[0] == Approx(2.0).epsilon(1e-12));
}

TEST_CASE("lp: a second loop over the program grown by rows, a column and a new objective starts from the first's basis",
          "[lp][warm]") {
  // First the textbook LP through cuts (as above): (3, 1), 11. Then, as the forces' least-out-of-
  // plane LP does, the same rows plus a column s >= 0, the rows 3x + 2y >= 10 and s - x >= -2,
  // and the objective minimise s + y. By hand: s = max(0, x - 2), y >= (10 - 3x) / 2 (inside
  // x + 3y <= 6 only for x > 2.4), so s + y = 3 - x/2, least at x = 3: (3, 0.5, 1), objective 1.5.
  LinearProgram lp;
  TorqueBlocks blocks;
  textbook_as_cuts(lp, blocks);
  const auto& slab = wiresculpt::torque_polytope(wiresculpt::TorqueBound::in_plane);
  std::set<std::pair<int, int>> added;
  HeldLp held;
  const LpSolution first = solve_lp_with_torque_rows(lp, blocks, slab, 4.0, added, nullptr, true, &held);
  REQUIRE(first.status == LpSolution::optimal);
  CHECK(first.objective == Approx(11.0).epsilon(1e-12));
  REQUIRE(held.held());
  LinearProgram tie = lp;
  tie.maximise = false;
  tie.obj = {0.0, 1.0, 1.0};
  tie.col_lo.push_back(0.0);
  tie.col_hi.push_back(kInf);
  const int r = static_cast<int>(tie.row_lo.size());
  for (auto [row, col, val] : {std::tuple{r, 0, 3.0}, std::tuple{r, 1, 2.0}, std::tuple{r + 1, 0, -1.0}, std::tuple{r + 1, 2, 1.0}}) {
    tie.tri_row.push_back(row);
    tie.tri_col.push_back(col);
    tie.tri_val.push_back(val);
  }
  tie.row_lo.insert(tie.row_lo.end(), {10.0, -2.0});
  tie.row_hi.insert(tie.row_hi.end(), {kInf, kInf});
  TorqueBlocks padded{Eigen::MatrixXd::Zero(6, 3), blocks.c};
  padded.A.leftCols(2) = blocks.A;
  int rounds = 0;
  const LinearProgram tie_before = tie;
  const LpSolution second = solve_lp_with_torque_rows(tie, padded, slab, 4.0, added, &rounds, true, &held);
  REQUIRE(second.status == LpSolution::optimal);
  CHECK(second.objective == Approx(1.5).epsilon(1e-12));
  CHECK(second.x[0] == Approx(3.0).epsilon(1e-12));
  CHECK(second.x[1] == Approx(0.5).epsilon(1e-12));
  CHECK(second.x[2] == Approx(1.0).epsilon(1e-12));
  CHECK(second.builds == 0);  // extended the held problem, did not rebuild
  CHECK(second.warm_solves == rounds);
  const LpSolution rebuilt = solve_lp(tie_before);
  REQUIRE(rebuilt.status == LpSolution::optimal);
  CHECK(rebuilt.objective == Approx(1.5).epsilon(1e-12));
  // A program whose held columns' bounds changed is no growth of the held one: it is rebuilt.
  LinearProgram capped = tie_before;
  capped.col_hi[1] = 5.0;
  std::set<std::pair<int, int>> none;
  const LpSolution again = solve_lp_with_torque_rows(capped, padded, slab, 4.0, none, nullptr, true, &held);
  REQUIRE(again.status == LpSolution::optimal);
  CHECK(again.builds == 1);
  CHECK(again.objective == Approx(1.5).epsilon(1e-12));
}
