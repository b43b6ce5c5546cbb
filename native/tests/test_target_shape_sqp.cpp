// The target shape's Newton SQP (TargetShapeAlgorithm::sqp, target_shape_sqp.hpp): its convex QP
// against brute force over every active set, and whole solves against SLSQP's on contours with
// known optima (the same distances and crossings, found with fewer evaluations), its fallback on a
// kink that cannot be opened, and cancellation.
#include <catch2/catch.hpp>
#include <Eigen/Dense>
#include <array>
#include <cmath>
#include <limits>
#include <numbers>
#include <nlopt.hpp>
#include <random>
#include <utility>

#include "target_shape_sqp.hpp"
#include "wiresculpt/error.hpp"
#include "wiresculpt/target_shape.hpp"

using namespace wiresculpt;

namespace {
constexpr double pi = std::numbers::pi;

// min ½ dᵀWd + gᵀd s.t. A d + c <= 0 by enumeration: for every subset S of the constraints the
// equality-constrained KKT system; the answer is the one (unique for W positive definite) that is
// primal and dual feasible. False when no subset gives one (the constraints are inconsistent).
bool brute_force_qp(const Eigen::MatrixXd& W, const Eigen::VectorXd& g, const Eigen::MatrixXd& A,
                    const Eigen::VectorXd& c, Eigen::VectorXd& best) {
  const int n = static_cast<int>(W.rows()), m = static_cast<int>(A.rows());
  bool found = false;
  double best_f = 0.0;
  for (int mask = 0; mask < (1 << m); ++mask) {
    std::vector<int> S;
    for (int k = 0; k < m; ++k)
      if (mask & (1 << k)) S.push_back(k);
    const int s = static_cast<int>(S.size());
    if (s > n) continue;
    Eigen::MatrixXd K = Eigen::MatrixXd::Zero(n + s, n + s);
    Eigen::VectorXd rhs(n + s);
    K.topLeftCorner(n, n) = W;
    rhs.head(n) = -g;
    for (int j = 0; j < s; ++j) {
      K.block(0, n + j, n, 1) = A.row(S[j]).transpose();
      K.block(n + j, 0, 1, n) = A.row(S[j]);
      rhs[n + j] = -c[S[j]];
    }
    const Eigen::FullPivLU<Eigen::MatrixXd> lu(K);
    if (lu.rank() < n + s) continue;  // dependent active normals
    const Eigen::VectorXd sol = lu.solve(rhs);
    const Eigen::VectorXd d = sol.head(n), lambda = sol.tail(s);
    if (s && lambda.minCoeff() < -1e-9) continue;
    if (m && (A * d + c).maxCoeff() > 1e-9) continue;
    const double f = 0.5 * d.dot(W * d) + g.dot(d);
    if (!found || f < best_f) best = d, best_f = f, found = true;
  }
  return found;
}

// A rows × cols matrix of standard normal draws, row by row.
Eigen::MatrixXd gaussian(int rows, int cols, std::mt19937& rng) {
  std::normal_distribution<double> N(0.0, 1.0);
  Eigen::MatrixXd M(rows, cols);
  for (int i = 0; i < rows; ++i)
    for (int j = 0; j < cols; ++j) M(i, j) = N(rng);
  return M;
}

// A 2 m wavy loop of n points (radius 0.3 m with a 5-lobe and a 3-lobe ripple).
Polyline2 wavy_loop(int n) {
  Polyline2 loop;
  for (int k = 0; k < n; ++k) {
    const double t = 2 * pi * k / n;
    const double rr = 0.3 + 0.04 * std::cos(5 * t) + 0.02 * std::sin(3 * t);
    loop.emplace_back(rr * std::cos(t), rr * std::sin(t));
  }
  return loop;
}

// Ten active crossings on a closed contour of n points, evenly spaced from point 7, their kinks
// opening alternately inwards and outwards (-p̂, +p̂, ...).
std::vector<TargetCrossing> ten_alternating_kinks(const Polyline2& loop) {
  const int n = static_cast<int>(loop.size());
  std::vector<TargetCrossing> xs;
  for (int k = 0; k < 10; ++k) {
    const int v = k * n / 10 + 7;
    xs.push_back({v, (k % 2 ? 1.0 : -1.0) * loop[v].normalized(), 2 * pi / 3, true});
  }
  return xs;
}

Polyline2 ellipse(double a, double b, int n) {
  Polyline2 pts;
  for (int k = 0; k < n; ++k) pts.emplace_back(a * std::cos(2 * pi * k / n), b * std::sin(2 * pi * k / n));
  return pts;
}

// The largest distance between two results' points (the same resampling, so the same count).
double largest_move(const TargetShapeResult& a, const TargetShapeResult& b) {
  REQUIRE(a.points.size() == b.points.size());
  double worst = 0.0;
  for (std::size_t i = 0; i < a.points.size(); ++i) worst = std::max(worst, (a.points[i] - b.points[i]).norm());
  return worst;
}

void same_optimum(const TargetShapeResult& slsqp, const TargetShapeResult& sqp) {
  // The measure of "the same optimum": distances to the contour within 0.1 mm and the
  // same status at every crossing.
  CHECK(std::abs(sqp.max_distance - slsqp.max_distance) < 1e-4);
  CHECK(std::abs(sqp.rms_distance - slsqp.rms_distance) < 1e-4);
  REQUIRE(sqp.crossings.size() == slsqp.crossings.size());
  for (std::size_t c = 0; c < sqp.crossings.size(); ++c) CHECK(sqp.crossings[c].status == slsqp.crossings[c].status);
  CHECK(sqp.feasible == slsqp.feasible);
}
}  // namespace

TEST_CASE("sqp: the convex QP's answer is the KKT point that brute force over active sets finds", "[target][sqp]") {
  std::mt19937 rng(17);
  std::normal_distribution<double> N(0.0, 1.0);
  int solved = 0, inconsistent = 0;
  detail::QpBuffers kept;  // one set for every trial, whose n and m keep changing, as an SQP keeps them
  for (int trial = 0; trial < 400; ++trial) {
    const int n = 1 + trial % 5, m = trial % 7;
    const Eigen::MatrixXd B = gaussian(n, n, rng);
    Eigen::MatrixXd A(m, n);
    Eigen::VectorXd g(n), c(m);
    const Eigen::MatrixXd W = B.transpose() * B + 0.1 * Eigen::MatrixXd::Identity(n, n);
    for (int i = 0; i < n; ++i) g[i] = N(rng);
    for (int k = 0; k < m; ++k) {
      for (int j = 0; j < n; ++j) A(k, j) = N(rng);
      c[k] = N(rng);
    }
    if (trial % 11 == 0 && m >= 2) {  // a parallel pair: sometimes inconsistent, sometimes not
      A.row(1) = -2.0 * A.row(0);
      c[1] = (trial % 22 == 0 ? 3.0 : -3.0) + 2.0 * c[0];
    }
    Eigen::VectorXd d_bf, d, lambda;
    const bool feasible = brute_force_qp(W, g, A, c, d_bf);
    const bool ok = detail::solve_convex_qp(W, g, A, c, d, lambda);
    REQUIRE(ok == feasible);
    {  // the kept buffers give the same bits as fresh ones
      Eigen::VectorXd d2, lambda2;
      REQUIRE(detail::solve_convex_qp(Eigen::LLT<Eigen::MatrixXd>(W), g, A, c, d2, lambda2, kept) == ok);
      if (ok) {
        CHECK(d2 == d);
        CHECK(lambda2 == lambda);
      }
    }
    if (!ok) {
      ++inconsistent;
      continue;
    }
    ++solved;
    CHECK((d - d_bf).norm() <= 1e-8 * (1.0 + d_bf.norm()));
    // Its multipliers satisfy the KKT conditions on their own.
    CHECK(lambda.size() == m);
    if (m) {
      CHECK(lambda.minCoeff() >= 0.0);
      CHECK((A * d + c).maxCoeff() <= 1e-9);
      for (int k = 0; k < m; ++k) CHECK(std::abs(lambda[k] * (A.row(k).dot(d) + c[k])) <= 1e-8);
    }
    CHECK((W * d + g + (m ? Eigen::VectorXd(A.transpose() * lambda) : Eigen::VectorXd::Zero(n))).norm() <= 1e-8);
  }
  CHECK(solved > 300);
  CHECK(inconsistent > 5);
}

TEST_CASE("sqp: the QP reports constraints that contradict each other", "[target][sqp]") {
  // d0 <= -1 and d0 >= 1.
  Eigen::MatrixXd A(2, 2);
  A << 1, 0, -1, 0;
  const Eigen::VectorXd c = (Eigen::VectorXd(2) << 1, 1).finished();
  Eigen::VectorXd d, lambda;
  CHECK_FALSE(detail::solve_convex_qp(Eigen::MatrixXd::Identity(2, 2), Eigen::VectorXd::Zero(2), A, c, d, lambda));
  // Without the second one: d = (-1, 0) with multiplier 1 (the gradient of ½|d|² at d is -a).
  Eigen::VectorXd d1, l1;
  REQUIRE(detail::solve_convex_qp(Eigen::MatrixXd::Identity(2, 2), Eigen::VectorXd::Zero(2), A.topRows(1),
                                  c.head(1), d1, l1));
  CHECK(d1[0] == Approx(-1.0));
  CHECK(d1[1] == Approx(0.0).margin(1e-15));
  CHECK(l1[0] == Approx(1.0));
}

TEST_CASE("sqp: reaches SLSQP's optimum with fewer evaluations, in one block and in windows", "[target][sqp]") {
  // An ellipse with four active crossings (two kinks inverted), solved as one block; and the same
  // with windows; and a 2 m wavy loop with ten crossings (windows).
  struct Case {
    Polyline2 contour;
    std::vector<TargetCrossing> xs;
    int window;
  };
  std::vector<Case> cases;
  {
    const Polyline2 e = ellipse(0.15, 0.09, 1200);
    std::vector<TargetCrossing> xs;
    for (int k = 0; k < 4; ++k) {
      const int v = k * 300 + 37;
      xs.push_back({v, (k % 2 ? -1.0 : 1.0) * e[v].normalized(), 2 * pi / 3, true});
    }
    cases.push_back({e, xs, 0});
    cases.push_back({e, xs, 8});
  }
  {
    const Polyline2 loop = wavy_loop(2000);
    cases.push_back({loop, ten_alternating_kinks(loop), 8});
  }
  for (const Case& cs : cases) {
    TargetShapeOptions o;
    o.window = cs.window;
    o.sweep_ftol = 1e-3;  // as the pipeline solves
    const TargetShapeResult a = optimize_target_shape(cs.contour, true, cs.xs, o);
    o.algorithm = TargetShapeAlgorithm::sqp;
    const TargetShapeResult b = optimize_target_shape(cs.contour, true, cs.xs, o);
    same_optimum(a, b);
    CHECK(b.energy == Approx(a.energy).epsilon(1e-3));
    for (const auto& s : b.crossings) CHECK(s.status == "ok");
    CHECK(b.max_length_violation <= 1e-6);
    CHECK(b.max_angle_violation <= 1e-6);
    // The SQP solved the blocks itself (a broken one would leave them all to SLSQP, which would
    // pass the checks above), and in fewer evaluations.
    CHECK(b.sqp_blocks > 0);
    CHECK(b.sqp_fallbacks * 4 <= b.sqp_blocks);
    CHECK(b.iterations < a.iterations);
    CHECK(b.nlopt_result == "SQP_CONVERGED");
    CHECK(a.sqp_blocks == 0);
  }
}

namespace {
// Crossings 31 mm apart on a straight 0.3 m wire leave one free point between them; crossing 0
// wants it above the wire, crossing 1 below: the linearised constraints contradict each other.
std::pair<Polyline2, std::vector<TargetCrossing>> contradicting_kinks() {
  Polyline2 contour;
  for (int k = 0; k <= 300; ++k) contour.emplace_back(0.3 * k / 300.0, 0.0);
  return {contour, {{100, Vec2(0, 1), 2 * pi / 3, true}, {131, Vec2(0, -1), 2 * pi / 3, true}}};
}
}  // namespace

TEST_CASE("sqp: a kink that cannot be opened is left to SLSQP and reported as before", "[target][sqp]") {
  // contradicting_kinks(): no free point can open both kinks.
  const auto [contour, xs] = contradicting_kinks();
  TargetShapeOptions o;
  const TargetShapeResult a = optimize_target_shape(contour, false, xs, o);
  o.algorithm = TargetShapeAlgorithm::sqp;
  const TargetShapeResult b = optimize_target_shape(contour, false, xs, o);
  CHECK(b.sqp_fallbacks >= 1);
  REQUIRE(b.crossings.size() == 2);
  for (std::size_t c = 0; c < 2; ++c) CHECK(b.crossings[c].status == a.crossings[c].status);
  CHECK((a.crossings[0].status != "ok" || a.crossings[1].status != "ok"));
  CHECK(largest_move(a, b) < 1e-4);
}

TEST_CASE("sqp: where NLopt leads a block and the SQP fails, its one run is the fallback", "[target][sqp]") {
  // The wire above in one block: slsqp_block refuses it (the linearised constraints contradict each
  // other), so NLopt's SLSQP leads, and the SQP fails too. SLSQP is deterministic, so the answer
  // must be SLSQP's own, bit for bit, and its first evaluations are not paid twice: besides
  // SLSQP's evaluations only the replica's and the SQP's few (a restart from the block's start
  // would add the lead-in's 10 again).
  const auto [contour, xs] = contradicting_kinks();
  TargetShapeOptions o;
  o.algorithm = TargetShapeAlgorithm::slsqp;
  const TargetShapeResult a = optimize_target_shape(contour, false, xs, o);
  o.algorithm = TargetShapeAlgorithm::sqp;
  const TargetShapeResult b = optimize_target_shape(contour, false, xs, o);
  REQUIRE(b.sqp_blocks == 1);
  REQUIRE(b.sqp_fallbacks == 1);
  CHECK(a.iterations > 10);  // SLSQP ran past the lead-in
  CHECK(largest_move(a, b) == 0.0);
  CHECK(b.energy == a.energy);
  CHECK(b.nlopt_result == a.nlopt_result);
  CHECK(b.iterations > a.iterations);
  CHECK(b.iterations - a.iterations < 10);
}

TEST_CASE("sqp: a cancel while NLopt's lead-in run goes on as the fallback reaches the caller", "[target][sqp]") {
  // The wire above: the progress polls at evaluation 1 (the replica's first) and at 17 and 33
  // (kProgressEvery; in NLopt's run, after the SQP's failed take-over at 11) each cancel the call.
  const auto [contour, xs] = contradicting_kinks();
  TargetShapeOptions o;
  o.algorithm = TargetShapeAlgorithm::sqp;
  for (int stop_at : {2, 3, 4}) {
    int polls = 0;
    const ProgressFn stop = [&](std::string_view, double) { return ++polls < stop_at; };
    CHECK_THROWS_AS(optimize_target_shape(contour, false, xs, o, stop), Cancelled);
    CHECK(polls == stop_at);
  }
}

TEST_CASE("sqp: the progress callback can cancel it", "[target][sqp]") {
  TargetShapeOptions o;
  o.algorithm = TargetShapeAlgorithm::sqp;
  const Polyline2 e = ellipse(0.15, 0.09, 1200);
  const ProgressFn stop_later = [n = 0](std::string_view, double) mutable { return ++n < 3; };
  CHECK_THROWS_AS(optimize_target_shape(e, true, {{37, e[37].normalized(), 2 * pi / 3, true}}, o, stop_later),
                  Cancelled);
}

namespace {
// The block of free points in [from, to) of `problem`: its energy terms and constraints found here
// from their definitions (a term i reads i-1, i, i+1; a constraint the points of its kind).
struct TestBlock {
  std::vector<int> points, terms, constraints;
};

TestBlock block_of(const TargetShapeProblem& problem, int from, int to) {
  const int m = static_cast<int>(problem.initial().size());
  const bool closed = problem.closed();
  TestBlock b;
  std::vector<char> in(m, 0);
  for (int j = from; j < to; ++j) {  // around the end of a closed wire, [from, to) wraps
    const int i = closed ? (j + m) % m : j;
    if (i >= 0 && i < m && !problem.fixed()[i] && !in[i]) b.points.push_back(i), in[i] = 1;
  }
  auto wrap = [&](int j) { return closed ? (j + m) % m : j; };
  auto inside = [&](int j) { return closed || (j >= 0 && j < m); };
  for (int t = 0; t < m; ++t)
    for (int s : {-1, 0, 1})
      if (inside(t + s) && in[wrap(t + s)]) {
        b.terms.push_back(t);
        break;
      }
  const auto& all = problem.constraints();
  for (std::size_t k = 0; k < all.size(); ++k) {
    const auto& c = all[k];
    std::vector<int> pts;
    if (c.kind == TargetShapeProblem::Kind::length) pts = {c.vertex, (c.vertex + 1) % m};
    if (c.kind == TargetShapeProblem::Kind::bend) pts = {(c.vertex + m - 1) % m, c.vertex, (c.vertex + 1) % m};
    if (c.kind == TargetShapeProblem::Kind::contact) pts = {c.vertex, c.neighbour};
    for (int q : pts)
      if (in[q]) {
        b.constraints.push_back(static_cast<int>(k));
        break;
      }
  }
  return b;
}
}  // namespace

TEST_CASE("sqp: the Hessian of the Lagrangian matches central differences of its gradient", "[target][sqp]") {
  // An open and a closed wire, each with an active crossing; points moved off the resampling by
  // up to 4 h (every IMLS regime); multipliers on a length, a bend and a contact constraint.
  const TargetShapeOptions o;
  const double lmin = o.min_segment, spacing = 1.5 * lmin;
  detail::SqpSettings ss;
  ss.scale_x = lmin;
  ss.scale_f = 2.0 * spacing * lmin * lmin;
  ss.min_segment = lmin;
  ss.regularization = o.regularization;
  std::mt19937 rng(5);
  for (const bool closed : {false, true}) {
    Polyline2 contour;
    for (int k = 0; k < 600; ++k) {
      const double t = k / 600.0;
      contour.emplace_back(closed ? 0.12 * std::cos(2 * pi * t) : 0.4 * t,
                           closed ? 0.08 * std::sin(2 * pi * t) : 0.03 * std::sin(6 * t));
    }
    const std::vector<TargetCrossing> xs{{300, closed ? Vec2(-1, 0) : Vec2(0, 1), 2 * pi / 3, true}};
    const TargetShapeProblem problem(contour, closed, xs, o);
    const int v = problem.statuses()[0].vertex;  // in the resampled polyline
    const TestBlock tb = block_of(problem, v - 4, v + 4);
    const detail::SqpBlock block{&tb.points, &tb.terms, &tb.constraints};
    REQUIRE(tb.points.size() >= 6);
    Eigen::VectorXd lambda = Eigen::VectorXd::Zero(static_cast<Eigen::Index>(tb.constraints.size()));
    bool kinds[3] = {false, false, false};
    for (std::size_t k = 0; k < tb.constraints.size(); ++k) {
      const int kind = static_cast<int>(problem.constraints()[tb.constraints[k]].kind);
      if (!kinds[kind]) kinds[kind] = true, lambda[static_cast<Eigen::Index>(k)] = 0.3 + 0.2 * kind;
    }
    REQUIRE((kinds[0] && kinds[1] && kinds[2]));
    for (double spread : {0.2, 1.0, 4.0}) {
      std::uniform_real_distribution<double> u(-spread * problem.kernel_support(), spread * problem.kernel_support());
      Polyline2 p = problem.initial();
      for (int i : tb.points) p[i] += Vec2(u(rng), u(rng));
      const Eigen::MatrixXd H = detail::sqp_lagrangian_hessian(problem, block, ss, p, lambda);
      // As the SQP takes it, D and ∇D from the evaluation just before: the same bits.
      CHECK(detail::sqp_lagrangian_hessian(problem, block, ss, p, lambda, true) == H);
      const Eigen::Index n = H.rows();
      REQUIRE(n == static_cast<Eigen::Index>(2 * tb.points.size()));
      Eigen::MatrixXd fd(n, n);
      const double h = 1e-6;  // in the solver's units (l_min)
      for (Eigen::Index j = 0; j < n; ++j) {
        const int point = tb.points[static_cast<std::size_t>(j / 2)];
        Polyline2 q = p;
        q[point][static_cast<int>(j % 2)] += h * lmin;
        const Eigen::VectorXd gp = detail::sqp_lagrangian_gradient(problem, block, ss, q, lambda);
        q[point][static_cast<int>(j % 2)] -= 2 * h * lmin;
        const Eigen::VectorXd gm = detail::sqp_lagrangian_gradient(problem, block, ss, q, lambda);
        fd.col(j) = (gp - gm) / (2 * h);
      }
      CHECK((H - fd).cwiseAbs().maxCoeff() <= 1e-4 * std::max(1.0, fd.cwiseAbs().maxCoeff()));
    }
  }
}

TEST_CASE("sqp: an open wire with crossings reaches SLSQP's optimum", "[target][sqp]") {
  // An open 1.2 m S-curve with four active crossings, kinks alternately to each side: wire ends
  // take their own branches in E_d, E_r and the windows.
  Polyline2 contour;
  for (int k = 0; k <= 1200; ++k) contour.emplace_back(1.2 * k / 1200.0, 0.06 * std::sin(2 * pi * k / 1200.0 * 1.5));
  std::vector<TargetCrossing> xs;
  for (int k = 0; k < 4; ++k) xs.push_back({150 + 300 * k, Vec2(0, k % 2 ? -1.0 : 1.0), 2 * pi / 3, true});
  for (int window : {0, 8}) {
    TargetShapeOptions o;
    o.window = window;
    o.sweep_ftol = 1e-3;
    const TargetShapeResult a = optimize_target_shape(contour, false, xs, o);
    o.algorithm = TargetShapeAlgorithm::sqp;
    const TargetShapeResult b = optimize_target_shape(contour, false, xs, o);
    same_optimum(a, b);
    for (const auto& s : b.crossings) CHECK(s.status == "ok");
    CHECK(b.sqp_fallbacks * 4 <= b.sqp_blocks);
    CHECK(b.iterations < a.iterations);
  }
}

namespace {
// Without friction and with a 120° bend limit, as the pipeline solves.
TargetShapeOptions pipeline_options() {
  TargetShapeOptions o;
  o.friction = 0.0;
  o.max_bend = 2 * pi / 3;
  return o;
}

// The settings optimize_target_shape gives a block's SQP and replica at the default spacing.
detail::SqpSettings block_settings(const TargetShapeOptions& o) {
  detail::SqpSettings ss;
  ss.scale_x = o.min_segment;
  ss.scale_f = 2.0 * 1.5 * o.min_segment * o.min_segment;
  ss.min_segment = o.min_segment;
  ss.regularization = o.regularization;
  ss.constraint_tol = o.constraint_tol;
  ss.ftol_rel = o.ftol_rel;
  return ss;
}

// NLopt's SLSQP on one block, set up here from the problem's definitions (energy and constraint
// values with their gradients, in the solver's units), stopped after `evaluations`: what
// detail::slsqp_block replicates. Returns the wire with the block's points where NLopt left them.
Polyline2 nlopt_slsqp_block(const TargetShapeProblem& problem, const TestBlock& b, const detail::SqpSettings& ss,
                            const TargetShapeOptions& o, int evaluations, int& used, int& result) {
  struct Data {
    const TargetShapeProblem* problem;
    const TestBlock* b;
    const detail::SqpSettings* ss;
    Polyline2 p, grad;
    void unpack(const double* x) {
      for (std::size_t k = 0; k < b->points.size(); ++k) p[b->points[k]] = ss->scale_x * Vec2(x[2 * k], x[2 * k + 1]);
    }
  } data{&problem, &b, &ss, problem.initial(), Polyline2(problem.initial().size(), Vec2::Zero())};
  const unsigned n = static_cast<unsigned>(2 * b.points.size());
  nlopt::opt opt(nlopt::LD_SLSQP, n);
  opt.set_min_objective(
      [](unsigned, const double* x, double* g, void* v) {
        auto* d = static_cast<Data*>(v);
        d->unpack(x);
        std::fill(d->grad.begin(), d->grad.end(), Vec2::Zero());
        const double f = d->problem->energy_terms(d->p, d->b->terms, g ? &d->grad : nullptr) / d->ss->scale_f;
        if (g)
          for (std::size_t k = 0; k < d->b->points.size(); ++k)
            for (int r = 0; r < 2; ++r) g[2 * k + r] = d->ss->scale_x / d->ss->scale_f * d->grad[d->b->points[k]][r];
        return f;
      },
      &data);
  opt.add_inequality_mconstraint(
      [](unsigned m, double* c, unsigned nv, const double* x, double* g, void* v) {
        auto* d = static_cast<Data*>(v);
        d->unpack(x);
        for (unsigned k = 0; k < m; ++k) {
          std::fill(d->grad.begin(), d->grad.end(), Vec2::Zero());
          c[k] = d->problem->constraint(static_cast<std::size_t>(d->b->constraints[k]), d->p, g ? &d->grad : nullptr);
          if (g)
            for (std::size_t j = 0; j < d->b->points.size(); ++j)
              for (int r = 0; r < 2; ++r) g[k * nv + 2 * j + r] = d->ss->scale_x * d->grad[d->b->points[j]][r];
        }
      },
      &data, std::vector<double>(b.constraints.size(), o.constraint_tol));
  opt.set_ftol_rel(o.ftol_rel);
  opt.set_xtol_rel(o.xtol_rel);
  opt.set_maxeval(evaluations);
  std::vector<double> x(n);
  for (std::size_t k = 0; k < b.points.size(); ++k)
    for (int r = 0; r < 2; ++r) x[2 * k + r] = problem.initial()[b.points[k]][r] / ss.scale_x;
  double f = 0.0;
  try {
    result = opt.optimize(x, f);
  } catch (const std::exception&) {  // a stop NLopt reports by throwing: the point it reached
    result = opt.last_optimize_result();
  }
  used = opt.get_numevals();
  Polyline2 p = problem.initial();
  for (std::size_t k = 0; k < b.points.size(); ++k) p[b.points[k]] = ss.scale_x * Vec2(x[2 * k], x[2 * k + 1]);
  return p;
}
}  // namespace

TEST_CASE("sqp: slsqp_block takes SLSQP's first steps", "[target][sqp]") {
  // A one-block ellipse with inverted kinks, windows around a crossing of a flat ellipse, of a 2 m
  // loop and of an open S-curve: after every evaluation count from 1 to 12 the replica's point and
  // stop are NLopt's.
  const TargetShapeOptions o = pipeline_options();
  const detail::SqpSettings ss = block_settings(o);
  struct Case {
    Polyline2 contour;
    bool closed;
    std::vector<TargetCrossing> xs;
    int around;  // -1: one block for the whole wire, else a window of 8 points around this crossing
  };
  std::vector<Case> cases;
  {
    const Polyline2 e = ellipse(0.09, 0.06, 1200);
    std::vector<TargetCrossing> xs;
    for (int k = 0; k < 3; ++k) {
      const int v = k * 400 + 37;
      xs.push_back({v, (k % 2 ? -1.0 : 1.0) * e[v].normalized(), 2 * pi / 3, true});
    }
    cases.push_back({e, true, xs, -1});
  }
  {
    // A flat ellipse, kinks alternately in and out: the window around its second crossing takes
    // SLSQP's line search back (the test function rose at the full step).
    const Polyline2 e = ellipse(0.09, 0.027, 1200);
    std::vector<TargetCrossing> xs;
    for (int k = 0; k < 3; ++k) {
      const int v = k * 400 + 17;
      xs.push_back({v, (k % 2 ? 1.0 : -1.0) * e[v].normalized(), 2 * pi / 3, true});
    }
    cases.push_back({e, true, xs, 1});
  }
  {
    const Polyline2 loop = wavy_loop(2000);
    cases.push_back({loop, true, {{207, -loop[207].normalized(), 2 * pi / 3, true}}, 0});
  }
  {
    Polyline2 s;
    for (int k = 0; k <= 1200; ++k) s.emplace_back(1.2 * k / 1200.0, 0.06 * std::sin(2 * pi * k / 1200.0 * 1.5));
    cases.push_back({s, false, {{450, Vec2(0, -1), 2 * pi / 3, true}}, 0});
  }

  for (const Case& cs : cases) {
    const TargetShapeProblem problem(cs.contour, cs.closed, cs.xs, o);
    const int m = static_cast<int>(problem.initial().size());
    const int v = problem.statuses()[static_cast<std::size_t>(std::max(cs.around, 0))].vertex;
    const TestBlock tb = cs.around < 0 ? block_of(problem, 0, m) : block_of(problem, v - 4, v + 4);
    const detail::SqpBlock block{&tb.points, &tb.terms, &tb.constraints};
    double moved = 0.0;
    for (int k = 1; k <= 12; ++k) {
      int used = 0, result = 0;
      const Polyline2 want = nlopt_slsqp_block(problem, tb, ss, o, k, used, result);
      Polyline2 got = problem.initial();
      const detail::SlsqpOutcome lead = detail::slsqp_block(problem, block, got, ss, k, o.xtol_rel);
      REQUIRE(lead.done);
      CHECK(lead.evaluations == used);
      CHECK(lead.result == result);
      double worst = 0.0;
      for (int i = 0; i < m; ++i) {
        worst = std::max(worst, (got[i] - want[i]).norm());
        moved = std::max(moved, (want[i] - problem.initial()[i]).norm());
      }
      CHECK(worst <= 1e-9 * o.min_segment);
    }
    CHECK(moved > 1e-3 * o.min_segment);  // the steps compared are not nothing
    // Run to NLopt's own stop (ftol or xtol, well within 400 evaluations): the same stop, the
    // same point.
    int used = 0, result = 0;
    const Polyline2 want = nlopt_slsqp_block(problem, tb, ss, o, 400, used, result);
    Polyline2 got = problem.initial();
    const detail::SlsqpOutcome full = detail::slsqp_block(problem, block, got, ss, 400, o.xtol_rel);
    REQUIRE(full.done);
    CHECK(used < 400);
    CHECK(full.result == result);
    CHECK(full.evaluations == used);
    double worst = 0.0;
    for (int i = 0; i < m; ++i) worst = std::max(worst, (got[i] - want[i]).norm());
    CHECK(worst <= 1e-8 * o.min_segment);
  }
  // Crossings 45 mm apart on a straight wire, kinks to opposite sides: the linearised constraints
  // are inconsistent, SLSQP would solve its augmented problem, and the replica says it did not.
  Polyline2 line;
  for (int k = 0; k <= 300; ++k) line.emplace_back(0.3 * k / 300.0, 0.0);
  const TargetShapeProblem problem(line, false, {{100, Vec2(0, 1), 2 * pi / 3, true}, {145, Vec2(0, -1), 2 * pi / 3, true}}, o);
  const TestBlock tb = block_of(problem, 0, static_cast<int>(problem.initial().size()));
  const detail::SqpBlock block{&tb.points, &tb.terms, &tb.constraints};
  Polyline2 p = problem.initial();
  CHECK_FALSE(detail::slsqp_block(problem, block, p, ss, 10, o.xtol_rel).done);
  CHECK(p == problem.initial());
}

TEST_CASE("sqp: a settled step ends the block within that step of the confirmed optimum", "[target][sqp]") {
  // settle_step stops after a full Newton step of at most that size (scaled) to a feasible point,
  // without the QP that would confirm it. Against the same blocks run until the QP's own step
  // vanishes (settle_step 0, the reference): every point within a hundredth of settle_step (the
  // step after a settled one is about its square; 1.5e-8 m here, where a 1.5e-6 m settled step
  // could move it), never more iterations, and fewer in most (or the test would compare nothing).
  // The blocks: every window of 8 points of the 2 m wavy loop with ten crossings, and the whole
  // of a small ellipse, each started with its points pushed up to 2 mm off the contour so that it
  // has somewhere to go.
  const TargetShapeOptions o = pipeline_options();
  const detail::SqpSettings ss = block_settings(o);
  REQUIRE(ss.settle_step > ss.step_tol);  // the default settles
  int fewer = 0, blocks = 0;
  std::vector<std::pair<Polyline2, std::vector<TargetCrossing>>> wires;
  {
    const Polyline2 loop = wavy_loop(2000);
    wires.emplace_back(loop, ten_alternating_kinks(loop));
    wires.emplace_back(ellipse(0.06, 0.04, 1200), std::vector<TargetCrossing>{});
  }
  for (const auto& [contour, xs] : wires) {
    const TargetShapeProblem problem(contour, true, xs, o);
    const int m = static_cast<int>(problem.initial().size());
    Polyline2 start = problem.initial();
    for (int i = 0; i < m; ++i)
      if (!problem.fixed()[i]) start[i] += 1e-3 * Vec2(1.0 + std::sin(0.7 * i), std::cos(1.3 * i));
    std::vector<TestBlock> tbs;
    if (xs.empty()) tbs.push_back(block_of(problem, 0, m));
    for (int from = 0; !xs.empty() && from < m; from += 4) tbs.push_back(block_of(problem, from, from + 8));
    for (const TestBlock& tb : tbs) {
      const detail::SqpBlock block{&tb.points, &tb.terms, &tb.constraints};
      detail::SqpSettings confirmed = ss;
      confirmed.settle_step = 0.0;
      Polyline2 want = start, got = start;
      const detail::SqpOutcome a = detail::sqp_block(problem, block, want, confirmed);
      const detail::SqpOutcome r = detail::sqp_block(problem, block, got, ss);
      if (!a.converged) continue;  // a kink the SQP leaves to SLSQP
      ++blocks;
      REQUIRE(r.converged);
      CHECK(r.iterations <= a.iterations);
      fewer += r.iterations < a.iterations;
      double worst = 0.0;
      for (int i = 0; i < m; ++i) worst = std::max(worst, (got[i] - want[i]).norm());
      CHECK(worst <= 1e-2 * ss.settle_step * ss.scale_x);
    }
  }
  CHECK(blocks > 15);
  CHECK(fewer * 2 > blocks);
}

TEST_CASE("sqp: convexify takes the first shift of its sequence that makes W positive definite", "[target][sqp]") {
  // Against the plain scan of the sequence (none; ρ = 4^k d for k = 0..10 when some λ > 0; then
  // δ = 4^j 1e-8 d with ρ at its last value), from every kind of starting guess: the same matrix,
  // its factor, and the δ it reports.
  std::mt19937 rng(11);
  int with_rho = 0, with_delta = 0;
  detail::ShiftBuffers kept;  // one set for every call, as an SQP keeps them
  for (int trial = 0; trial < 300; ++trial) {
    const int n = 4 + trial % 9, m = trial % 7;
    const Eigen::MatrixXd B = gaussian(n, n, rng), A = gaussian(m, n, rng);
    Eigen::MatrixXd W = B * B.transpose();
    W.diagonal().array() -= std::pow(10.0, -3.0 + 4.0 * (trial % 5) / 4.0) * (trial % 3);  // up to indefinite
    Eigen::VectorXd lambda = Eigen::VectorXd::Zero(m);
    for (int i = 0; i < m; ++i) lambda[i] = (i + trial) % 2 ? 0.5 : 0.0;
    bool any = false;
    Eigen::MatrixXd AtA = Eigen::MatrixXd::Zero(n, n);
    for (int i = 0; i < m; ++i)
      if (lambda[i] > 0) AtA += A.row(i).transpose() * A.row(i), any = true;
    const double d = std::max(1e-12, W.diagonal().cwiseAbs().maxCoeff());
    double rho = 0.0, delta = 0.0;
    Eigen::MatrixXd want;
    for (int tries = 0; tries <= 60; ++tries) {
      Eigen::MatrixXd Wd = W + rho * AtA;
      Wd.diagonal().array() += delta;
      if (Eigen::LLT<Eigen::MatrixXd>(Wd).info() == Eigen::Success) {
        want = Wd;
        break;
      }
      if (any && rho < 1e6 * d) rho = rho > 0.0 ? 4.0 * rho : d;
      else delta = delta > 0.0 ? 4.0 * delta : 1e-8 * d;
    }
    REQUIRE(want.size() > 0);
    with_rho += rho > 0.0 && delta == 0.0;
    with_delta += delta > 0.0;
    for (int g : {-5, 0, 1, 7, 12, 30, 60, 100}) {
      std::array<int, 2> guess{g, g};
      Eigen::MatrixXd got = W;
      Eigen::LLT<Eigen::MatrixXd> factor(n);
      double delta_taken = -1.0;
      REQUIRE(detail::convexify(got, A, lambda, factor, guess, &delta_taken));
      CHECK(got == want);
      CHECK(delta_taken == delta);  // what settle_step asks: was W's curvature shifted by δI
      std::array<int, 2> guess2{g, g};  // the kept buffers give the same bits as fresh ones
      Eigen::MatrixXd got2 = W;
      Eigen::LLT<Eigen::MatrixXd> factor2(n);
      double delta2 = -1.0;
      REQUIRE(detail::convexify(got2, A, lambda, factor2, guess2, &delta2, kept));
      CHECK(got2 == got);
      CHECK(factor2.matrixLLT() == factor.matrixLLT());
      CHECK(delta2 == delta_taken);
      CHECK(guess2 == guess);
      CHECK((factor.matrixL().toDenseMatrix() * factor.matrixU().toDenseMatrix() - want).cwiseAbs().maxCoeff() <=
            1e-9 * want.cwiseAbs().maxCoeff());
    }
  }
  CHECK(with_rho > 10);  // both parts of the sequence were exercised
  CHECK(with_delta > 10);
  // No shift makes a matrix with a NaN definite: false, W as it was (its NaN included).
  Eigen::MatrixXd W = Eigen::MatrixXd::Identity(3, 3);
  W(1, 1) = std::numeric_limits<double>::quiet_NaN();
  Eigen::LLT<Eigen::MatrixXd> factor(3);
  std::array<int, 2> guess{0, 0};
  CHECK_FALSE(detail::convexify(W, Eigen::MatrixXd(0, 3), Eigen::VectorXd(0), factor, guess));
  CHECK(W(0, 0) == 1.0);
  CHECK(W(2, 2) == 1.0);
  CHECK(std::isnan(W(1, 1)));
}

TEST_CASE("sqp: a block solved in a workspace another block used gives a fresh workspace's result", "[target][sqp]") {
  // SqpWorkspace: a run keeps one across its blocks, whose sizes differ. Here blocks of three
  // sizes, around the crossing and away from it, solved by the SLSQP replica and by the SQP, in a
  // shared workspace in turn and each in a fresh one: the same points, to the bit.
  const TargetShapeOptions o;
  const detail::SqpSettings fresh = block_settings(o);
  detail::SqpWorkspace shared;
  detail::SqpSettings reused = fresh;
  reused.workspace = &shared;
  Polyline2 contour;
  for (int k = 0; k < 900; ++k) {
    const double t = k / 900.0;
    contour.emplace_back(0.15 * std::cos(2 * pi * t), 0.09 * std::sin(2 * pi * t));
  }
  const TargetShapeProblem problem(contour, true, {{450, Vec2(1, 0), 2 * pi / 3, true}}, o);
  const int v = problem.statuses()[0].vertex;
  std::vector<TestBlock> blocks{block_of(problem, v - 4, v + 4), block_of(problem, v + 6, v + 10),
                                block_of(problem, v - 12, v - 1), block_of(problem, v - 4, v + 4)};
  int solved = 0;
  for (const TestBlock& tb : blocks) {
    const detail::SqpBlock block{&tb.points, &tb.terms, &tb.constraints};
    Polyline2 a = problem.initial(), b = problem.initial();
    const detail::SlsqpOutcome la = detail::slsqp_block(problem, block, a, fresh, 10, o.xtol_rel);
    const detail::SlsqpOutcome lb = detail::slsqp_block(problem, block, b, reused, 10, o.xtol_rel);
    CHECK(la.done == lb.done);
    CHECK(la.evaluations == lb.evaluations);
    CHECK(a == b);
    const detail::SqpOutcome sa = detail::sqp_block(problem, block, a, fresh);
    const detail::SqpOutcome sb = detail::sqp_block(problem, block, b, reused);
    CHECK(sa.converged == sb.converged);
    CHECK(sa.evaluations == sb.evaluations);
    CHECK(a == b);
    solved += sa.converged ? 1 : 0;
  }
  CHECK(solved > 0);  // the comparison covers solves that moved points
}
