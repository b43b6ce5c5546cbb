// Target-shape optimisation (Sec. 4.3) on contours whose answers are known by hand: straight
// lines, circles, symmetric kinks, crossings too close to fit a bending point; and finite-difference
// checks of every gradient handed to NLopt.
#include <catch2/catch.hpp>
#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <random>
#include <tuple>
#include <utility>

#include "contour_fixtures.hpp"
#include "wiresculpt/error.hpp"
#include "wiresculpt/target_shape.hpp"

using namespace wiresculpt;
using Catch::Matchers::Contains;
using Catch::Matchers::EndsWith;
using fixtures::hairpin;
using fixtures::line;

namespace {
constexpr double pi = std::numbers::pi;

Polyline2 circle(double r, int n, int start = 0, bool reverse = false) {
  Polyline2 pts;
  for (int k = 0; k < n; ++k) {
    int j = (start + (reverse ? -k : k)) % n;
    if (j < 0) j += n;
    const double t = 2.0 * pi * j / n;
    pts.emplace_back(r * std::cos(t), r * std::sin(t));
  }
  return pts;
}

double angle_between(const Vec2& a, const Vec2& b) {
  return std::atan2(std::abs(a.x() * b.y() - a.y() * b.x()), a.dot(b));
}

// Checks every constraint of the paper on `r` independently of the solver's own bookkeeping.
void check_constraints(const TargetShapeResult& r, bool closed, const std::vector<TargetCrossing>& xs,
                       const TargetShapeOptions& o, double tol) {
  const auto& p = r.points;
  const int m = static_cast<int>(p.size());
  for (int i = 0; i < (closed ? m : m - 1); ++i) CHECK((p[(i + 1) % m] - p[i]).norm() >= o.min_segment - tol);
  for (int i = closed ? 0 : 1; i < (closed ? m : m - 1); ++i)
    CHECK(angle_between(p[i] - p[(i + m - 1) % m], p[(i + 1) % m] - p[i]) <= o.max_bend + tol);
  for (std::size_t c = 0; c < xs.size(); ++c) {
    if (!xs[c].active || !r.crossings[c].realised) continue;
    const int v = r.crossing_vertices[c];
    const Vec2 h = xs[c].bisector.normalized();
    for (int nb : {(v + m - 1) % m, (v + 1) % m})
      CHECK(angle_between(p[nb] - p[v], h) + std::atan(o.friction) <= xs[c].contact_angle / 2 + tol);
  }
}

// Central differences of f at p (all coordinates) against the analytic gradient g.
template <class F>
void check_gradient(F f, const Polyline2& p, const Polyline2& g, double step) {
  Polyline2 q = p;
  double worst = 0.0, scale = 0.0;
  for (std::size_t i = 0; i < p.size(); ++i)
    for (int k = 0; k < 2; ++k) {
      q[i][k] = p[i][k] + step;
      const double fp = f(q);
      q[i][k] = p[i][k] - step;
      const double fm = f(q);
      q[i][k] = p[i][k];
      const double fd = (fp - fm) / (2 * step);
      worst = std::max(worst, std::abs(fd - g[i][k]));
      scale = std::max(scale, std::abs(g[i][k]));
    }
  REQUIRE(scale > 0.0);
  CHECK(worst / scale < 1e-5);
}

// n points of the closed curve r = r0 + amplitude cos(lobes t).
Polyline2 wavy(double r0, double amplitude, int lobes, int n) {
  Polyline2 contour;
  for (int k = 0; k < n; ++k) {
    const double t = 2 * pi * k / n;
    const double rr = r0 + amplitude * std::cos(lobes * t);
    contour.emplace_back(rr * std::cos(t), rr * std::sin(t));
  }
  return contour;
}

// A 1.3 m wavy loop (r = 0.2 + 0.03 cos 5t, 1,300 points) with five active crossings whose
// bisectors alternate outwards and inwards: about 58 optimised points, solved in windows.
std::pair<Polyline2, std::vector<TargetCrossing>> wavy_loop() {
  const int n = 1300;
  const Polyline2 contour = wavy(0.2, 0.03, 5, n);
  std::vector<TargetCrossing> xs;
  for (int k = 0; k < 5; ++k) {
    const int v = k * n / 5 + 11;
    xs.push_back({v, (k % 2 ? -1.0 : 1.0) * contour[v].normalized(), 2 * pi / 3, true});
  }
  return {contour, xs};
}
}  // namespace

TEST_CASE("target shape: a straight contour stays straight", "[target]") {
  const Polyline2 contour = line(0.3, 301);  // 1 mm sampling
  for (bool with_crossing : {false, true}) {
    std::vector<TargetCrossing> xs;
    if (with_crossing) xs.push_back({150, Vec2(0, 1), 2 * pi / 3, false});  // inactive: kept, no kink
    const TargetShapeResult r = optimize_target_shape(contour, false, xs);
    REQUIRE(r.points.size() >= 2);
    for (const Vec2& q : r.points) CHECK(std::abs(q.y()) < 1e-9);
    CHECK(r.max_bend < 1e-6);
    CHECK(r.min_segment >= 0.015 - 1e-9);
    CHECK(r.max_distance < 1e-9);
    CHECK(r.feasible);
    CHECK(r.points.front().x() == Approx(0.0).margin(1e-9));
    CHECK(r.points.back().x() == Approx(0.3).margin(1e-9));
    if (with_crossing) {
      CHECK(r.crossings[0].status == "inactive");
      CHECK((r.points[r.crossing_vertices[0]] - Vec2(0.15, 0)).norm() == 0.0);
    }
  }
}

TEST_CASE("target shape: a finely sampled circle keeps l_min segments within 1 mm of the circle", "[target]") {
  const double R = 0.1;
  const Polyline2 contour = circle(R, 2000);  // 0.3 mm sampling, 50 x finer than l_min
  TargetShapeOptions o;
  const TargetShapeResult r = optimize_target_shape(contour, true, {}, o);
  CHECK(r.feasible);
  check_constraints(r, true, {}, o, 1e-6);
  const int m = static_cast<int>(r.points.size());
  for (int i = 0; i < m; ++i) {
    CHECK(std::abs(r.points[i].norm() - R) < 1e-3);
    const Vec2 mid = 0.5 * (r.points[i] + r.points[(i + 1) % m]);
    CHECK(std::abs(mid.norm() - R) < 1e-3);  // the chords sag less than 1 mm too
  }
  CHECK(r.max_distance < 1e-3);
  CHECK(r.min_segment >= 0.015 - 1e-6);
}

TEST_CASE("target shape: every constraint holds to 1e-6 at the optimum", "[target]") {
  // An ellipse with four active crossings, two opening outwards (inverting the kink) and two
  // inwards, on a dense contour.
  Polyline2 contour;
  const int n = 1200;
  for (int k = 0; k < n; ++k) {
    const double t = 2 * pi * k / n;
    contour.emplace_back(0.15 * std::cos(t), 0.09 * std::sin(t));
  }
  std::vector<TargetCrossing> xs;
  for (int k = 0; k < 4; ++k) {
    const int v = k * n / 4 + 37;
    const Vec2 radial = contour[v].normalized();
    xs.push_back({v, (k % 2 ? -1.0 : 1.0) * radial, 2 * pi / 3, true});
  }
  TargetShapeOptions o;
  const TargetShapeResult r = optimize_target_shape(contour, true, xs, o);
  for (const auto& s : r.crossings) CHECK(s.status == "ok");
  CHECK(r.feasible);
  CHECK(r.max_length_violation <= 1e-6);
  CHECK(r.max_angle_violation <= 1e-6);
  check_constraints(r, true, xs, o, 1e-6);
  for (std::size_t c = 0; c < xs.size(); ++c)  // crossing points are exactly kept
    CHECK((r.points[r.crossing_vertices[c]] - contour[xs[c].vertex]).norm() == 0.0);
}

TEST_CASE("target shape: the kink opens the way h* says, for +d and -d", "[target]") {
  TargetShapeOptions o;
  const double alpha_mu = std::atan(o.friction);
  SECTION("straight wire, crossing in the middle") {
    const Polyline2 contour = line(0.3, 301);
    for (double sign : {1.0, -1.0}) {
      const Vec2 d(0, sign);
      const std::vector<TargetCrossing> xs{{150, d, 2 * pi / 3, true}};
      const TargetShapeResult r = optimize_target_shape(contour, false, xs, o);
      REQUIRE(r.crossings[0].status == "ok");
      const Vec2 h = r.crossings[0].bisector;
      CHECK(h.dot(d) > 0);
      CHECK(angle_between(h, d) <= alpha_mu + 1e-6);  // by symmetry h = h* here
      // Both edges within α*/2 - atan μ of h*: the opening is at most α* - 2 atan μ (84.5°).
      CHECK(r.crossings[0].contact_angle <= 2 * pi / 3 - 2 * alpha_mu + 1e-6);
      check_constraints(r, false, xs, o, 1e-6);
    }
  }
  SECTION("circle, crossing opening inwards (as it is) and outwards (inverted)") {
    const Polyline2 contour = circle(0.1, 1000);
    for (double sign : {1.0, -1.0}) {
      const Vec2 d = sign * Vec2(-1, 0);  // at vertex 0 = (0.1, 0): -x points to the centre
      const std::vector<TargetCrossing> xs{{0, d, 2 * pi / 3, true}};
      const TargetShapeResult r = optimize_target_shape(contour, true, xs, o);
      REQUIRE(r.crossings[0].status == "ok");
      const Vec2 h = r.crossings[0].bisector;
      CHECK(h.dot(d) > 0);
      CHECK(angle_between(h, d) <= alpha_mu + 1e-6);
      check_constraints(r, true, xs, o, 1e-6);
      CHECK(r.feasible);
    }
  }
}

TEST_CASE("target shape: independent of the contour's starting point and direction", "[target]") {
  const int n = 900;
  Polyline2 base;
  for (int k = 0; k < n; ++k) {  // an irregular closed curve (no symmetry to hide mistakes)
    const double t = 2 * pi * k / n;
    const double rr = 0.1 + 0.02 * std::cos(3 * t) + 0.01 * std::sin(2 * t);
    base.emplace_back(rr * std::cos(t), rr * std::sin(t));
  }
  const std::vector<int> xv{40, 400, 610};
  const std::vector<Vec2> hs{Vec2(1, 0.3).normalized(), Vec2(-0.2, -1).normalized(), Vec2(0.5, 1).normalized()};
  auto solve = [&](int start, bool reverse) {
    Polyline2 c(n);
    std::vector<TargetCrossing> xs;
    auto new_index = [&](int j) { return reverse ? ((start - j) % n + n) % n : ((j - start) % n + n) % n; };
    for (int j = 0; j < n; ++j) c[new_index(j)] = base[j];
    for (std::size_t k = 0; k < xv.size(); ++k) xs.push_back({new_index(xv[k]), hs[k], 2 * pi / 3, k != 2});
    return optimize_target_shape(c, true, xs);
  };
  const TargetShapeResult ref = solve(0, false);
  for (auto [start, reverse] : {std::pair{0, true}, std::pair{123, false}, std::pair{517, true}}) {
    const TargetShapeResult r = solve(start, reverse);
    REQUIRE(r.points.size() == ref.points.size());
    const int m = static_cast<int>(r.points.size());
    const int a0 = ref.crossing_vertices[0], b0 = r.crossing_vertices[0];
    double worst = 0.0;
    for (int k = 0; k < m; ++k) {
      const int j = reverse ? ((b0 - k) % m + m) % m : (b0 + k) % m;
      worst = std::max(worst, (ref.points[(a0 + k) % m] - r.points[j]).norm());
    }
    CHECK(worst < 1e-5);  // 10 µm: see "windows reach the optimum of one global solve"
    for (std::size_t c = 0; c < xv.size(); ++c) CHECK(r.crossings[c].status == ref.crossings[c].status);
  }
}

TEST_CASE("target shape: crossings 9 mm apart cannot be realised and ask for a scale-up", "[target]") {
  const Polyline2 contour = line(0.3, 301);
  std::vector<TargetCrossing> xs{{100, Vec2(0, 1), 2 * pi / 3, true}, {109, Vec2(0, -1), 2 * pi / 3, true}};
  TargetShapeOptions o;
  o.model_size = 0.093;
  o.wire_name = "B";
  const TargetShapeResult r = optimize_target_shape(contour, false, xs, o);
  for (const auto& s : r.crossings) {
    CHECK(s.status == "too_close");
    CHECK_FALSE(s.realised);
    CHECK(s.scale == Approx(30.0 / 9.0).epsilon(1e-9));  // 2 l_min / 9 mm
    CHECK_THAT(s.message, Contains("wire B") && Contains("9 mm") && Contains("0.31 m"));
  }
  // The 9 mm straight piece is itself shorter than l_min: reported, not hidden.
  CHECK_FALSE(r.feasible);
  CHECK(r.max_length_violation == Approx(0.006).margin(1e-9));
}

TEST_CASE("target shape: crossings 25 mm apart keep the realisable one", "[target]") {
  // 25 mm < 2 l_min: no free point between them; 25 mm >= l_min so the straight piece is fine.
  // The straight piece is perpendicular to h* = ±y: its fixed edge is 90° from h*, outside the
  // 42.3° cone, so both active crossings are too close; an inactive neighbour stays fine.
  const Polyline2 contour = line(0.3, 301);
  std::vector<TargetCrossing> xs{{100, Vec2(0, 1), 2 * pi / 3, true}, {125, Vec2(0, -1), 2 * pi / 3, false}};
  const TargetShapeResult r = optimize_target_shape(contour, false, xs);
  CHECK(r.crossings[0].status == "too_close");
  CHECK(r.crossings[0].scale == Approx(1.2).epsilon(1e-9));
  CHECK(r.crossings[1].status == "inactive");
  CHECK(r.crossing_vertices[1] == r.crossing_vertices[0] + 1);
}

TEST_CASE("target shape: impossible contact angles and open ends are reported", "[target]") {
  const Polyline2 contour = line(0.3, 301);
  TargetShapeOptions o;  // μ = 0.32: twice the friction angle is 35.5°
  SECTION("narrower than twice the friction angle") {
    const TargetShapeResult r = optimize_target_shape(contour, false, {{150, Vec2(0, 1), pi / 6, true}}, o);
    CHECK(r.crossings[0].status == "infeasible");
    CHECK_THAT(r.crossings[0].message, Contains("friction"));
  }
  SECTION("needs a bend beyond the machine's maximum") {
    // α* = 50°: each edge within 25° - 17.7° = 7.3° of h*, a bend of at least 165.4° > 120°.
    const TargetShapeResult r = optimize_target_shape(contour, false, {{150, Vec2(0, 1), 50 * pi / 180, true}}, o);
    CHECK(r.crossings[0].status == "infeasible");
    CHECK_THAT(r.crossings[0].message, Contains("bends at most 120"));
    // the figures add up as written: 180 - 50 + 2 x 17.7 = 165.4; 180 - 120 + 35.5 = 95.5
    CHECK_THAT(r.crossings[0].message, Contains("needs a bend of at least 165° (180° less the contact angle 50°, plus "
                                                "twice the friction angle 17.7°) but the machine bends at most 120°: "
                                                "a contact angle of at least 95.5° fits"));
    CHECK(r.feasible);  // that crossing's constraint was dropped; the wire itself is fine
  }
  SECTION("the contact angle that fits is rounded up, and not offered when none fits") {
    // 180 - 68.075 + 35.485 = 147.41: shown as 148, which fits (147 would not)
    o.max_bend = 68.075 * pi / 180;
    TargetShapeResult r = optimize_target_shape(contour, false, {{150, Vec2(0, 1), 50 * pi / 180, true}}, o);
    CHECK_THAT(r.crossings[0].message, EndsWith("but the machine bends at most 68.1°: a contact angle of at least 148° fits"));
    // 180 - 30 + 35.5 = 185.5: no contact angle does
    o.max_bend = 30 * pi / 180;
    r = optimize_target_shape(contour, false, {{150, Vec2(0, 1), 50 * pi / 180, true}}, o);
    CHECK_THAT(r.crossings[0].message, EndsWith("but the machine bends at most 30°"));
  }
  SECTION("active crossing at an open end") {
    const TargetShapeResult r = optimize_target_shape(contour, false, {{0, Vec2(0, 1), 2 * pi / 3, true}}, o);
    CHECK(r.crossings[0].status == "open_end");
    CHECK(r.crossing_vertices[0] == 0);
  }
}

TEST_CASE("target shape: bad input is rejected with the wire and crossing named", "[target]") {
  const Polyline2 contour = line(0.3, 31);
  TargetShapeOptions o;
  o.wire_name = "W7";
  CHECK_THROWS_AS(optimize_target_shape(contour, false, {{31, Vec2(0, 1), 2, true}}, o), InputError);
  CHECK_THROWS_WITH(optimize_target_shape(contour, false, {{3, Vec2(0, 1), 2, true}, {3, Vec2(0, 1), 2, true}}, o),
                    Contains("W7") && Contains("crossing 1"));
  CHECK_THROWS_WITH(optimize_target_shape(contour, false, {{3, Vec2(0, 0), 2, true}}, o), Contains("bisector"));
  Polyline2 bad = contour;
  bad[4].x() = std::nan("");
  CHECK_THROWS_WITH(optimize_target_shape(bad, false, {}, o), Contains("point 4"));
  o.max_bend = 4.0;
  CHECK_THROWS_WITH(optimize_target_shape(contour, false, {}, o), Contains("max_bend"));
  o.max_bend = 2.0;
  for (double v : {-1e-3, 1.0, std::nan("")}) {
    o.sweep_ftol = v;
    CHECK_THROWS_WITH(optimize_target_shape(contour, false, {}, o), Contains("sweep_ftol"));
  }
}

TEST_CASE("target shape: the progress callback can cancel", "[target]") {
  const ProgressFn stop_later = [n = 0](std::string_view, double) mutable { return ++n < 5; };
  CHECK_THROWS_AS(optimize_target_shape(circle(0.1, 500), true, {{0, Vec2(1, 0), 2 * pi / 3, true}}, {}, stop_later),
                  Cancelled);
}

TEST_CASE("target shape: analytic gradients match central differences", "[target]") {
  const Polyline2 contour = wavy(0.1, 0.02, 3, 700);
  const std::vector<TargetCrossing> xs{{10, Vec2(1, 0), 2 * pi / 3, true}, {300, Vec2(0, 1), 1.8, true}};
  TargetShapeProblem problem(contour, true, xs);
  std::mt19937 rng(7);
  const double step = 1e-7;
  // Random points around the initial guess: displacements of up to 4 h reach every regime of
  // the IMLS (full kernel, blend, nearest-point fallback).
  for (double spread : {0.1, 1.0, 4.0}) {
    std::uniform_real_distribution<double> u(-spread * problem.kernel_support(), spread * problem.kernel_support());
    Polyline2 p = problem.initial();
    for (Vec2& q : p) q += Vec2(u(rng), u(rng));
    Polyline2 g;
    problem.distance_energy(p, &g);
    check_gradient([&](const Polyline2& q) { return problem.distance_energy(q); }, p, g, step);
    g.clear();
    problem.regularization_energy(p, &g);
    check_gradient([&](const Polyline2& q) { return problem.regularization_energy(q); }, p, g, step);
    g.clear();
    problem.energy(p, &g);
    check_gradient([&](const Polyline2& q) { return problem.energy(q); }, p, g, step);
    for (std::size_t k = 0; k < problem.constraints().size(); ++k) {
      g.clear();
      problem.constraint(k, p, &g);
      check_gradient([&](const Polyline2& q) { return problem.constraint(k, q); }, p, g, step);
    }
  }
  SECTION("the IMLS distance in each regime") {
    const double hh = problem.kernel_support();
    int regimes = 0;
    for (double off : {0.0, 0.2, 0.45, 0.6, 0.9, 1.5, 5.0}) {
      const Vec2 q = contour[123] + off * hh * Vec2(0.6, 0.8);
      Vec2 g;
      problem.imls(q, &g);
      Vec2 fd;
      for (int k = 0; k < 2; ++k) {
        Vec2 a = q, b = q;
        a[k] += step;
        b[k] -= step;
        fd[k] = (problem.imls(a) - problem.imls(b)) / (2 * step);
      }
      if (g.norm() > 0) {
        CHECK((fd - g).norm() / g.norm() < 1e-5);
        ++regimes;
      }
    }
    CHECK(regimes >= 6);
    // Far from the target the fallback is the squared distance to the contour.
    const Vec2 far = contour[123] * 1.5;
    CHECK(problem.imls(far) == Approx(std::pow(problem.distance_to_contour(far), 2)).epsilon(1e-12));
  }
}

TEST_CASE("target shape: energy_terms gives each term's IMLS sample, and the same energy and gradient", "[target]") {
  const Polyline2 contour = wavy(0.1, 0.02, 3, 700);
  const std::vector<TargetCrossing> xs{{10, Vec2(1, 0), 2 * pi / 3, true}};
  TargetShapeProblem problem(contour, true, xs);
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(-2 * problem.kernel_support(), 2 * problem.kernel_support());
  Polyline2 p = problem.initial();
  for (Vec2& q : p) q += Vec2(u(rng), u(rng));
  const std::vector<int> terms{0, 3, 4, 5, static_cast<int>(p.size()) - 1};
  Polyline2 g0(p.size(), Vec2::Zero()), g1(p.size(), Vec2::Zero());
  std::vector<TargetShapeProblem::ImlsSample> samples;
  const double e0 = problem.energy_terms(p, terms, &g0);
  const double e1 = problem.energy_terms(p, terms, &g1, &samples);
  CHECK(e1 == e0);  // asking for the samples changes nothing
  for (std::size_t i = 0; i < p.size(); ++i) CHECK(g1[i] == g0[i]);
  REQUIRE(samples.size() == terms.size());
  for (std::size_t k = 0; k < terms.size(); ++k) {
    const Vec2& q = p[static_cast<std::size_t>(terms[k])];
    Vec2 dD;
    const double D = problem.imls(q, &dD);
    CHECK(samples[k].q == q);
    CHECK(samples[k].value == D);  // the very numbers imls gives there
    CHECK(samples[k].gradient == dD);
  }
  // Without the gradient nothing is sampled.
  std::vector<TargetShapeProblem::ImlsSample> none;
  problem.energy_terms(p, terms, nullptr, &none);
  CHECK(none.empty());
}

TEST_CASE("target shape: the distance to the contour is the nearest of all its segments", "[target]") {
  // Brute force over the input contour's segments (the solver's target subdivides them, on the
  // same lines), at random points near it, beyond its bounding box (where the grid's rings start
  // from the nearest cell) and far away, for a closed wavy loop and an open S-curve.
  auto brute = [](const Polyline2& c, bool closed, const Vec2& q) {
    double best = std::numeric_limits<double>::infinity();
    const std::size_t n = c.size(), edges = closed ? n : n - 1;
    for (std::size_t k = 0; k < edges; ++k) {
      const Vec2 a = c[k], d = c[(k + 1) % n] - a;
      const double t = std::clamp((q - a).dot(d) / d.squaredNorm(), 0.0, 1.0);
      best = std::min(best, (q - (a + t * d)).norm());
    }
    return best;
  };
  Polyline2 s_curve;
  for (int k = 0; k <= 400; ++k) {
    const double t = k / 400.0;
    s_curve.emplace_back(0.8 * t, 0.1 * std::sin(2 * pi * t));
  }
  std::mt19937 rng(11);
  int outside = 0, checked = 0;
  for (const auto& [contour, closed] : {std::pair{wavy(0.1, 0.02, 3, 700), true}, std::pair{s_curve, false}}) {
    const TargetShapeProblem problem(contour, closed, {});
    Vec2 lo = contour[0], hi = contour[0];
    for (const Vec2& p : contour) lo = lo.cwiseMin(p), hi = hi.cwiseMax(p);
    for (double spread : {0.2, 1.0, 5.0, 40.0}) {  // multiples of the kernel support h
      std::uniform_real_distribution<double> u(-spread * problem.kernel_support(), spread * problem.kernel_support());
      std::uniform_int_distribution<std::size_t> at(0, contour.size() - 1);
      for (int i = 0; i < 400; ++i) {
        const Vec2 q = contour[at(rng)] + Vec2(u(rng), u(rng));
        outside += (q.array() < lo.array()).any() || (q.array() > hi.array()).any();
        CHECK(problem.distance_to_contour(q) == Approx(brute(contour, closed, q)).epsilon(0).margin(1e-12));
        ++checked;
      }
    }
    for (const Vec2& q : {Vec2(3.0, -2.0), Vec2(-50.0, 0.01), Vec2(0.0, 1e3)}) {
      CHECK(problem.distance_to_contour(q) == Approx(brute(contour, closed, q)).epsilon(1e-12));
      ++outside;
    }
  }
  CHECK(checked == 3200);
  CHECK(outside > 100);
}

TEST_CASE("target shape: windows reach the optimum of one global solve", "[target]") {
  const auto [contour, xs] = wavy_loop();
  TargetShapeOptions windowed, global;
  global.window = 0;
  const TargetShapeResult a = optimize_target_shape(contour, true, xs, windowed);
  const TargetShapeResult b = optimize_target_shape(contour, true, xs, global);
  REQUIRE(a.points.size() == b.points.size());
  CHECK(a.sweeps > 1);
  CHECK(b.sweeps == 1);
  CHECK(a.energy == Approx(b.energy).epsilon(1e-8));
  // The optimum is flat along the wire (only E_r holds points tangentially): two solvers that
  // stop at ftol_rel 1e-12 agree to about a micrometre; 10 µm is far below the machine's accuracy.
  double worst = 0.0;
  for (std::size_t i = 0; i < a.points.size(); ++i) worst = std::max(worst, (a.points[i] - b.points[i]).norm());
  CHECK(worst < 1e-5);
  check_constraints(a, true, xs, windowed, 1e-6);
  for (const auto& s : a.crossings) CHECK(s.status == "ok");
}

TEST_CASE("target shape: the default sweep tolerance stops where 1 nm sweeps stop", "[target]") {
  // The wavy loop, solved in windows with the default sweep_tol (0.1 µm) and with sweeps
  // continued until nothing moves by 1 nm: the same optimum (energy to 1e-8, every point within the
  // 10 µm to which realised segments are checked), for fewer evaluations.
  const auto [contour, xs] = wavy_loop();
  TargetShapeOptions standard, fine;
  fine.sweep_tol = 1e-9;
  REQUIRE(standard.sweep_tol > fine.sweep_tol);
  const TargetShapeResult a = optimize_target_shape(contour, true, xs, standard);
  const TargetShapeResult b = optimize_target_shape(contour, true, xs, fine);
  REQUIRE(a.points.size() == b.points.size());
  CHECK(a.sweeps > 1);
  CHECK(a.iterations < b.iterations);
  CHECK(a.energy == Approx(b.energy).epsilon(1e-8));
  double worst = 0.0;
  for (std::size_t i = 0; i < a.points.size(); ++i) worst = std::max(worst, (a.points[i] - b.points[i]).norm());
  CHECK(worst < 1e-5);
  check_constraints(a, true, xs, standard, 1e-6);
  for (const auto& s : a.crossings) CHECK(s.status == "ok");
}

TEST_CASE("target shape: a 2 m wire with ten crossings, half of them inverted", "[target]") {
  Polyline2 contour;
  const int n = 2000;  // 1 mm sampling
  for (int k = 0; k < n; ++k) {
    const double t = 2 * pi * k / n;
    const double rr = 0.3 + 0.04 * std::cos(5 * t) + 0.02 * std::sin(3 * t);
    contour.emplace_back(rr * std::cos(t), rr * std::sin(t));
  }
  std::vector<TargetCrossing> xs;
  for (int k = 0; k < 10; ++k) {
    const int v = k * n / 10 + 7;
    xs.push_back({v, (k % 2 ? 1.0 : -1.0) * contour[v].normalized(), 2 * pi / 3, true});
  }
  TargetShapeOptions o;
  const TargetShapeResult r = optimize_target_shape(contour, true, xs, o);
  CHECK(r.feasible);
  for (const auto& s : r.crossings) {
    CHECK(s.status == "ok");
    CHECK(s.contact_violation <= 1e-6);
  }
  check_constraints(r, true, xs, o, 1e-6);
  // Away from the kinks the wire stays on the contour: the median point is within 1 mm.
  std::vector<double> d;
  for (const Vec2& q : r.points) {
    double best = 1e9;
    for (const Vec2& c : contour) best = std::min(best, (q - c).norm());
    d.push_back(best);
  }
  std::nth_element(d.begin(), d.begin() + d.size() / 2, d.end());
  CHECK(d[d.size() / 2] < 1e-3);
}

TEST_CASE("target shape: contact constraints that cannot hold together are reported per crossing", "[target]") {
  // Crossings 31 mm apart on a straight wire leave one free point between them; crossing 0 wants
  // it above the wire (h* = +y, within 42.3°), crossing 1 below (h* = -y): impossible.
  const Polyline2 contour = line(0.3, 301);
  const std::vector<TargetCrossing> xs{{100, Vec2(0, 1), 2 * pi / 3, true}, {131, Vec2(0, -1), 2 * pi / 3, true}};
  TargetShapeOptions o;
  o.wire_name = "C";
  const TargetShapeResult r = optimize_target_shape(contour, false, xs, o);
  REQUIRE(r.crossing_vertices[1] == r.crossing_vertices[0] + 2);  // exactly one free point
  int failed = 0;
  for (std::size_t c = 0; c < xs.size(); ++c) {
    const auto& s = r.crossings[c];
    if (s.status == "ok") continue;
    ++failed;
    CHECK(s.status == "infeasible");
    CHECK_FALSE(s.realised);
    CHECK(s.contact_violation > o.angle_tolerance);
    CHECK_THAT(s.message, Contains("crossing " + std::to_string(c)) && Contains("wire C"));
  }
  CHECK(failed >= 1);
  CHECK_FALSE(r.feasible);
}

TEST_CASE("target shape: a per-point bend limit holds at that point, the others keep max_bend", "[target]") {
  // A square of side 0.1 m: its corners are the sharpest bends of the target.
  Polyline2 contour;
  const Vec2 corner[4] = {{0, 0}, {0.1, 0}, {0.1, 0.1}, {0, 0.1}};
  for (int s = 0; s < 4; ++s)
    for (int k = 0; k < 50; ++k) contour.push_back(corner[s] + (corner[(s + 1) % 4] - corner[s]) * (k / 50.0));
  TargetShapeOptions o;
  const TargetShapeResult free = optimize_target_shape(contour, true, {}, o);
  const int m = static_cast<int>(free.points.size());
  auto bend = [&](const Polyline2& p, int i) {
    return angle_between(p[i] - p[(i + m - 1) % m], p[(i + 1) % m] - p[i]);
  };
  int sharpest = 0;
  for (int i = 0; i < m; ++i)
    if (bend(free.points, i) > bend(free.points, sharpest)) sharpest = i;
  const double before = bend(free.points, sharpest);
  REQUIRE(before > 20.0 * pi / 180.0);

  o.vertex_max_bend.assign(static_cast<std::size_t>(m), 0.0);
  o.vertex_max_bend[static_cast<std::size_t>(sharpest)] = before - 10.0 * pi / 180.0;
  const TargetShapeResult limited = optimize_target_shape(contour, true, {}, o);
  REQUIRE(static_cast<int>(limited.points.size()) == m);  // the same points, so the index still means it
  CHECK(limited.feasible);
  CHECK(bend(limited.points, sharpest) <= before - 10.0 * pi / 180.0 + 1e-6);
  for (int i = 0; i < m; ++i) CHECK(bend(limited.points, i) <= o.max_bend + 1e-6);
  CHECK(bend_limit(o, sharpest) == Approx(before - 10.0 * pi / 180.0));
  CHECK(bend_limit(o, m + 5) == o.max_bend);

  o.vertex_max_bend = {std::nan("")};
  CHECK_THROWS_WITH(optimize_target_shape(contour, true, {}, o), Contains("vertex_max_bend[0]"));
}

TEST_CASE("target shape: a kink whose neighbour breaks the bend limit is not realised", "[target]") {
  // A hairpin right after an active crossing A at the origin (kink opening towards +y): the wire
  // runs along +x for 18 mm, turns back by 140° and meets a fixed (null) crossing B 21 mm later.
  // Between them there is one free point, and with the kink's cone, 15 mm segments and B fixed,
  // the solver meets the cone at the cost of a bend over 120° at that point: the kink cannot be
  // made, so A is reported, not passed on as realised beside an unbendable wire.
  const auto [contour, a_vertex, b_vertex] = hairpin(0.06);
  REQUIRE(a_vertex == 60);
  REQUIRE(b_vertex == 99);
  REQUIRE(contour[60].norm() < 1e-12);
  TargetShapeOptions o;
  o.friction = 0.0;
  o.angle_tolerance = 0.1 * pi / 180.0;
  o.length_tolerance = 1e-5;
  const std::vector<TargetCrossing> xs{{60, Vec2(0, 1), 2 * pi / 3, true}, {99, Vec2(0, 1), 2 * pi / 3, false}};
  const TargetShapeResult r = optimize_target_shape(contour, false, xs, o);
  // Independently of the solver's bookkeeping: some free point next to A bends over 120°.
  const auto& p = r.points;
  const int v = r.crossing_vertices[0];
  double worst = 0.0;
  int at = -1;
  for (int nb : {v - 1, v + 1}) {
    const double bend = angle_between(p[nb] - p[nb - 1], p[nb + 1] - p[nb]);
    if (bend > worst) worst = bend, at = nb;
  }
  REQUIRE(worst > o.max_bend + o.angle_tolerance);
  CHECK(r.crossings[0].status == "infeasible");
  CHECK_FALSE(r.crossings[0].realised);
  CHECK_THAT(r.crossings[0].message, Contains("its kink cannot be made") && Contains("point " + std::to_string(at)));
  // the bend and the limit with one decimal each (the bend is over by more than 0.1°), not "121°, more than 120°"
  CHECK_THAT(r.crossings[0].message, Contains("°, more than 120.0°"));
  CHECK_FALSE(r.feasible);
  CHECK(r.crossings[1].status == "inactive");
}

namespace {
// A closed loop r = r0 + 0.04 cos 5t + 0.02 sin 3t at 1 mm sampling with `count` active crossings
// whose bisectors alternate inwards and outwards (the 2 m wire above for r0 = 0.3).
std::pair<Polyline2, std::vector<TargetCrossing>> long_loop(double r0, int count) {
  Polyline2 contour;
  const int n = static_cast<int>(2 * pi * r0 / 1e-3);
  for (int k = 0; k < n; ++k) {
    const double t = 2 * pi * k / n;
    const double rr = r0 + 0.04 * std::cos(5 * t) + 0.02 * std::sin(3 * t);
    contour.emplace_back(rr * std::cos(t), rr * std::sin(t));
  }
  std::vector<TargetCrossing> xs;
  for (int k = 0; k < count; ++k) {
    const int v = k * n / count + 7;
    xs.push_back({v, (k % 2 ? 1.0 : -1.0) * contour[v].normalized(), 2 * pi / 3, true});
  }
  return {contour, xs};
}
}  // namespace

TEST_CASE("target shape: sweep_ftol stops the sweeps with the distances and crossings of converged sweeps",
          "[target]") {
  // The reference runs the sweeps until no window moves a point by 1 nm (sweep_ftol off); the
  // energy-based stop must give the same distances to the contour (within 0.1 mm, the tolerance the
  // method note's tests use) and the same realised crossings, for fewer sweeps.
  const auto wavy = wavy_loop();
  const auto two_metres = long_loop(0.3, 10);
  const auto three_metres = long_loop(0.47, 6);
  for (const auto* c : {&wavy, &two_metres, &three_metres}) {
    const auto& [contour, xs] = *c;
    TargetShapeOptions reference, fast;
    reference.sweep_tol = 1e-9;
    reference.max_iterations = 1'000'000;
    fast.sweep_ftol = 1e-3;
    const TargetShapeResult a = optimize_target_shape(contour, true, xs, fast);
    const TargetShapeResult b = optimize_target_shape(contour, true, xs, reference);
    INFO(contour.size() << " contour points, " << a.sweeps << " / " << b.sweeps << " sweeps");
    REQUIRE(a.points.size() == b.points.size());
    CHECK(b.nlopt_result != "NLOPT_MAXEVAL_REACHED");
    CHECK(a.sweeps < b.sweeps);
    CHECK(a.iterations < b.iterations);
    CHECK(std::abs(a.max_distance - b.max_distance) < 1e-4);
    CHECK(std::abs(a.rms_distance - b.rms_distance) < 1e-4);
    // What is left after the stop lowers the energy by less than a percent.
    CHECK(a.energy == Approx(b.energy).epsilon(1e-2));
    CHECK(a.feasible == b.feasible);
    for (std::size_t k = 0; k < xs.size(); ++k) {
      CHECK(a.crossings[k].status == b.crossings[k].status);
      CHECK(a.crossings[k].realised == b.crossings[k].realised);
    }
    check_constraints(a, true, xs, fast, 1e-6);
  }
}

TEST_CASE("target shape: a 3 m wire converges within the default evaluation budget with sweep_ftol", "[target]") {
  // Without the energy-based stop, each sweep of a 3 m wire moves points along it by more than
  // sweep_tol, and the sweeps used up the 20,000 evaluations (scripts/bench, length-3.0m).
  const auto [contour, xs] = long_loop(0.47, 6);
  TargetShapeOptions o;
  o.sweep_ftol = 1e-3;
  const TargetShapeResult r = optimize_target_shape(contour, true, xs, o);
  CHECK(r.nlopt_result != "NLOPT_MAXEVAL_REACHED");
  CHECK(r.iterations < o.max_iterations);
  CHECK(r.feasible);
  for (const auto& s : r.crossings) CHECK(s.status == "ok");
}

TEST_CASE("target shape: a warm start from the looser limit's optimum reaches the cold solve's optimum", "[target]") {
  // The coupling (Sec. 4.3) lowers one vertex's bend limit and solves again. Started from the
  // previous optimum (`start`), the solve must end where a cold start ends: the same distances to
  // the contour (0.1 mm, the method note's tolerance), the same crossings realised, every constraint
  // held, and with fewer evaluations (what the start is for). One windowed loop with crossings
  // (2 m, ten crossings) and one one-block wire with a crossing.
  const auto two_metres = long_loop(0.3, 10);
  const auto wavy = wavy_loop();
  for (const auto* c : {&two_metres, &wavy}) {
    const auto& [contour, xs] = *c;
    TargetShapeOptions o;
    o.sweep_ftol = 1e-3;
    const TargetShapeResult loose = optimize_target_shape(contour, true, xs, o);
    const int m = static_cast<int>(loose.points.size());
    auto bend = [&](const Polyline2& p, int i) {
      return angle_between(p[i] - p[(i + m - 1) % m], p[(i + 1) % m] - p[i]);
    };
    std::vector<char> fixed(static_cast<std::size_t>(m), 0);
    for (int v : loose.crossing_vertices) fixed[static_cast<std::size_t>(v)] = 1;
    int sharpest = -1;  // the sharpest bend at a point whose neighbours are both free
    for (int i = 0; i < m; ++i)
      if (!fixed[i] && !fixed[(i + 1) % m] && !fixed[(i + m - 1) % m] &&
          (sharpest < 0 || bend(loose.points, i) > bend(loose.points, sharpest)))
        sharpest = i;
    REQUIRE(sharpest >= 0);
    const double limit = 0.5 * bend(loose.points, sharpest);
    REQUIRE(limit > 2.0 * pi / 180.0);
    o.vertex_max_bend.assign(static_cast<std::size_t>(m), 0.0);
    o.vertex_max_bend[static_cast<std::size_t>(sharpest)] = limit;
    const TargetShapeResult cold = optimize_target_shape(contour, true, xs, o);
    o.start = loose.points;
    const TargetShapeResult warm = optimize_target_shape(contour, true, xs, o);
    INFO(contour.size() << " contour points, " << m << " target points; evaluations cold " << cold.iterations
                        << ", warm " << warm.iterations);
    REQUIRE(warm.points.size() == cold.points.size());
    CHECK(bend(warm.points, sharpest) <= limit + 1e-6);
    CHECK(std::abs(warm.max_distance - cold.max_distance) < 1e-4);
    CHECK(std::abs(warm.rms_distance - cold.rms_distance) < 1e-4);
    CHECK(warm.feasible == cold.feasible);
    for (std::size_t k = 0; k < xs.size(); ++k) {
      CHECK(warm.crossings[k].status == cold.crossings[k].status);
      CHECK(warm.crossings[k].realised == cold.crossings[k].realised);
    }
    for (int v : warm.crossing_vertices) CHECK((warm.points[v] - cold.points[v]).norm() == 0.0);  // the contour's own
    check_constraints(warm, true, xs, o, 1e-6);
    CHECK(warm.iterations < cold.iterations);
  }
}

TEST_CASE("target shape: a start of the wrong size or not finite is refused, naming the wire", "[target]") {
  const auto [contour, xs] = wavy_loop();
  TargetShapeOptions o;
  o.wire_name = "W";
  const TargetShapeResult r = optimize_target_shape(contour, true, xs, o);
  o.start = r.points;
  o.start.pop_back();
  CHECK_THROWS_WITH(optimize_target_shape(contour, true, xs, o), Contains("wire W") && Contains("start has"));
  o.start = r.points;
  o.start[1].x() = std::nan("");
  CHECK_THROWS_WITH(optimize_target_shape(contour, true, xs, o), Contains("wire W") && Contains("start point 1"));
}

TEST_CASE("target shape: one_block_points decides between one block and windows", "[target]") {
  // The wavy loop's result (65 points) with windows of 20: at the default (4 x window = 80) one
  // block; with one_block_points below its size, windows (more than one sweep). Both end at the
  // same distances (0.1 mm) with the same crossings.
  const auto [contour, xs] = wavy_loop();
  TargetShapeOptions o;
  o.sweep_ftol = 1e-3;
  o.window = 20;
  const TargetShapeResult block = optimize_target_shape(contour, true, xs, o);
  const int m = static_cast<int>(block.points.size());
  REQUIRE(m > 20);
  REQUIRE(m <= 4 * o.window);
  CHECK(block.sweeps == 1);
  o.one_block_points = 20;
  const TargetShapeResult windows = optimize_target_shape(contour, true, xs, o);
  CHECK(windows.sweeps > 1);
  CHECK(std::abs(windows.max_distance - block.max_distance) < 1e-4);
  CHECK(std::abs(windows.rms_distance - block.rms_distance) < 1e-4);
  for (std::size_t k = 0; k < xs.size(); ++k) CHECK(windows.crossings[k].status == block.crossings[k].status);
  o.one_block_points = m;  // at most this many points: one block again
  CHECK(optimize_target_shape(contour, true, xs, o).sweeps == 1);
  o.one_block_points = -2;
  CHECK_THROWS_WITH(optimize_target_shape(contour, true, xs, o), Contains("one_block_points"));
}

TEST_CASE("target shape: sweep_ftol also stops the sweeps of a wire stuck on a kink it cannot open", "[target]") {
  // The hairpin of "a kink whose neighbour breaks the bend limit is not realised" with 0.5 m tails,
  // so that the wire is solved in windows: the kink at A cannot be made, the wire stays
  // infeasible and the energy stop of sweep_ftol alone never fires. Sweeps run to 1 nm creep on
  // to the 200-sweep cap (115,000 evaluations), lowering the violation a little each time; the
  // stuck stop ends after a few with the same verdict per crossing, which is what the caller
  // uses (it nulls the crossing and solves the wire again without it). The shape of a wire
  // stuck infeasible is no optimum, so its distances are not compared.
  const auto [contour, a_vertex, b_vertex] = hairpin(0.5);
  TargetShapeOptions reference, fast;
  for (TargetShapeOptions* o : {&reference, &fast}) {
    o->friction = 0.0;
    o->angle_tolerance = 0.1 * pi / 180.0;
    o->length_tolerance = 1e-5;
  }
  reference.sweep_tol = 1e-9;
  reference.max_iterations = 1'000'000;
  fast.sweep_ftol = 1e-3;
  const std::vector<TargetCrossing> xs{{a_vertex, Vec2(0, 1), 2 * pi / 3, true}, {b_vertex, Vec2(0, 1), 2 * pi / 3, false}};
  const TargetShapeResult a = optimize_target_shape(contour, false, xs, fast);
  const TargetShapeResult r = optimize_target_shape(contour, false, xs, reference);
  INFO(a.sweeps << " / " << r.sweeps << " sweeps, " << a.iterations << " / " << r.iterations << " evaluations, "
                << a.points.size() << " points");
  REQUIRE(a.points.size() > 32);  // windows
  REQUIRE(r.crossings[0].status == "infeasible");
  REQUIRE_FALSE(r.feasible);
  CHECK_FALSE(a.feasible);
  CHECK(a.sweeps <= 10);
  CHECK(10 * a.iterations < r.iterations);
  for (std::size_t k = 0; k < xs.size(); ++k) CHECK(a.crossings[k].status == r.crossings[k].status);
  CHECK(a.max_angle_violation > fast.angle_tolerance);
}
