// The LP layer over GLPK (native/src/lp.hpp, glpk_guard.hpp): numbers GLPK cannot take are
// refused before it sees them, and an internal GLPK error inside the guard is a failed call, never
// an abort of the process (which would take Blender and the user's scene with it). Before the
// guard covered the problem's construction and scaling, the 1e±300 cases below aborted this
// binary in glp_set_rii / glp_set_sjj ("invalid scale factor").
#include <glpk.h>
#include <unistd.h>

#include <catch2/catch.hpp>
#include <cstdio>
#include <limits>
#include <vector>

#include "glpk_guard.hpp"  // native/src: private to the core
#include "lp.hpp"

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
  const LpSolution first = solve_lp(with_entries(1e-300, 1.0, 1.0, 1.0));
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
