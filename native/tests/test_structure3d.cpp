// The sculpture as it would stand (structure3d.hpp): the nonlinear 3D rods against closed forms
// and independent computations written here (elastica by shooting, Castigliano, free bodies).
#include <catch2/catch.hpp>
#include <cmath>
#include <numbers>
#include <random>
#include <vector>

#include "structure3d_fixtures.hpp"
#include "structure3d_model.hpp"
#include "wiresculpt/error.hpp"
#include "wiresculpt/structure3d.hpp"

using namespace wiresculpt;
using fixtures::weightless;

namespace {

constexpr double pi = std::numbers::pi;

Structure3dWire wire(const std::string& name, const Polyline3& points, const Vec3& normal) {
  return {name, points, points, normal};
}

/// Nodes s_k = -h/2 + k h, k = 0..n, h = L / (n - 1/2), along x: the clamped first edge is centred
/// on the clamp point (the origin), so the first bend's Voronoi length starts exactly there and
/// the discrete rod integrates the curvature by the midpoint rule.
Polyline3 cantilever_points(double length, int n) {
  const double h = length / (n - 0.5);
  Polyline3 p;
  for (int k = 0; k <= n; ++k) p.emplace_back(-0.5 * h + k * h, 0.0, 0.0);
  return p;
}

/// The elastica of a cantilever (clamped at s = 0, tangent +x, tip force P along -z), solved
/// independently: θ'' = -(P/EI) cos θ, θ(0) = 0, θ'(L) = 0, by RK4 and bisection on θ'(0). Returns
/// the tip's (vertical deflection, horizontal shortening).
std::pair<double, double> elastica_tip(double alpha, double length) {
  const double k = alpha / (length * length);  // P / EI
  const int steps = 4000;
  const double ds = length / steps;
  auto shoot = [&](double w0, double& down, double& along) {
    Eigen::Vector4d y(0.0, w0, 0.0, 0.0);  // θ, θ', x, z(down)
    auto f = [&](const Eigen::Vector4d& s) { return Eigen::Vector4d(s(1), -k * std::cos(s(0)), std::cos(s(0)), std::sin(s(0))); };
    for (int i = 0; i < steps; ++i) {
      const Eigen::Vector4d k1 = f(y), k2 = f(y + 0.5 * ds * k1), k3 = f(y + 0.5 * ds * k2), k4 = f(y + ds * k3);
      y += ds / 6.0 * (k1 + 2 * k2 + 2 * k3 + k4);
    }
    down = y(3), along = y(2);
    return y(1);
  };
  // θ'(L) < 0 for θ'(0) = 0 (θ' only falls), >= 0 for θ'(0) = P L / EI (the largest moment).
  double lo = 0.0, hi = k * length, down = 0.0, along = 0.0;
  for (int i = 0; i < 80; ++i) {
    const double mid = 0.5 * (lo + hi);
    (shoot(mid, down, along) < 0 ? lo : hi) = mid;
  }
  shoot(0.5 * (lo + hi), down, along);
  return {down, length - along};
}

}  // namespace

TEST_CASE("structure3d: the shooting reference agrees with Bisshopp and Drucker's table", "[structure3d]") {
  // The reference itself, against the classical large-deflection cantilever (Bisshopp & Drucker
  // 1945): P L²/EI = 1: δv/L 0.30172, δh/L 0.05643; 2: 0.49346, 0.16064 (5 digits printed).
  CHECK(elastica_tip(1.0, 1.0).first == Approx(0.30172).margin(2e-5));
  CHECK(elastica_tip(1.0, 1.0).second == Approx(0.05643).margin(2e-5));
  CHECK(elastica_tip(2.0, 1.0).first == Approx(0.49346).margin(2e-5));
  CHECK(elastica_tip(2.0, 1.0).second == Approx(0.16064).margin(2e-5));
}

TEST_CASE("structure3d: cantilever under a large tip load follows the elastica", "[structure3d]") {
  // E·I = 0.73, L = 0.3 m; a thin wire (d = 1 mm, E A = 16 E I / d²) keeps the stretch 1e-5 of L
  // at the largest load, well below the discretisation error measured here. The midpoint rule of
  // cantilever_points converges at second order in h: the error at 2n must be under 0.3 of that
  // at n (a quarter expected; measured 0.24-0.25), under 0.25% of L at 20 edges and 0.07% at 40
  // (measured at P L²/EI = 1, 2, 5: 0.033, 0.083, 0.17% and 0.008, 0.020, 0.041%).
  const double L = 0.3;
  Structure3dOptions o = weightless();
  o.wire_diameter = 0.001;
  for (double alpha : {1.0, 2.0, 5.0}) {
    const auto [down, shortening] = elastica_tip(alpha, L);
    double previous = 0.0;
    for (int n : {20, 40}) {
      Structure3dInput in;
      in.wires.push_back(wire("cantilever", cantilever_points(L, n), Vec3::UnitY()));
      in.clamps.push_back({0, 0});
      in.loads.push_back({{0, n}, Vec3(0, 0, -alpha * o.bending_stiffness / (L * L))});
      const Structure3dResult r = solve_structure3d(in, o);
      INFO("alpha " << alpha << ", " << n << " edges: " << describe(r.cause, r.cause_figure));
      REQUIRE(r.converged);
      const Vec3 tip = r.wires[0].points.back();
      const double error = std::max(std::abs(-tip.z() - down), std::abs(L - tip.x() - shortening));
      CHECK(std::abs(tip.y()) < 1e-12);
      if (n == 20) CHECK(error < 0.0025 * L);
      if (n == 40) CHECK(error < 0.0007 * L);
      if (n == 40) CHECK(error < 0.3 * previous);
      previous = error;
    }
  }
}

TEST_CASE("structure3d: quarter ring under an out-of-plane tip force against Castigliano", "[structure3d]") {
  // A quarter ring of radius R in z = 0, clamped at θ = 0 (tangent +y), force P along z at θ = π/2.
  // Castigliano (bending M = P R sin ψ, torsion T = P R (1 - cos ψ), ψ the angle back from the
  // tip): δ = P R³ [π/(4 E I) + (3π/4 - 2)/(G J)]. The nodes sit on the circle at angles
  // -Δ/2 + kΔ (the clamped chord centred on θ = 0, as the cantilever): second order in Δ, so the
  // error at 40 edges must be under 0.3 of that at 20 (a quarter expected; measured 0.31% and
  // 0.075%). P makes δ/R ~ 2e-4, so the nonlinear part, ~(δ/R)², is 1e-7 of δ: halving P must
  // halve δ to 1e-6 (measured 5e-9).
  const double R = 0.1, P = 0.01;
  const Structure3dOptions o = weightless();
  const double d = o.wire_diameter, GJ = o.shear_modulus * pi * d * d * d * d / 32.0;
  const double expected = P * R * R * R * (pi / (4.0 * o.bending_stiffness) + (0.75 * pi - 2.0) / GJ);
  double previous = 0.0;
  for (int n : {20, 40}) {
    const double step = 0.5 * pi / (n - 0.5);
    Polyline3 pts;
    for (int k = 0; k <= n; ++k) pts.emplace_back(R * std::cos(-0.5 * step + k * step), R * std::sin(-0.5 * step + k * step), 0.0);
    auto solve = [&](double force) {
      Structure3dInput in;
      in.wires.push_back(wire("ring", pts, Vec3::UnitZ()));
      in.clamps.push_back({0, 0});
      in.loads.push_back({{0, n}, Vec3(0, 0, force)});
      const Structure3dResult r = solve_structure3d(in, o);
      INFO(n << " edges: " << describe(r.cause, r.cause_figure));
      REQUIRE(r.converged);
      return r.wires[0].points.back().z() - pts.back().z();
    };
    const double delta = solve(P), error = std::abs(delta / expected - 1.0);
    INFO(n << " edges: delta " << delta << " expected " << expected);
    CHECK(error < 0.005);
    if (n == 40) CHECK(error < 0.3 * previous);
    CHECK(solve(0.5 * P) / delta == Approx(0.5).epsilon(1e-6));
    previous = error;
  }
}

TEST_CASE("structure3d: an arc held straight needs the end moment E I / R", "[structure3d]") {
  // Rest: an arc of radius R (turning Δ per vertex, edges the chords 2 R sin(Δ/2)) in z = 0,
  // curving towards +y. Start: straight along x with the same edges, both end edges clamped. Held
  // straight, the rod's moment is E I / R everywhere and nothing pushes: the clamps' forces vanish
  // and their moments are ±E I / R about z. The discrete rod bends by 2 tan(Δ/2) over l̄ = 2 × chord,
  // giving E I / (R cos(Δ/2)): relative error Δ²/8 (1.4e-3 at 10 edges over 60°), shrinking.
  const double R = 0.1, span = pi / 3.0;
  const Structure3dOptions o = weightless();
  double previous = 0.0;
  for (int n : {10, 20}) {
    const double step = span / n, chord = 2.0 * R * std::sin(0.5 * step);
    Polyline3 rest, start;
    for (int k = 0; k <= n; ++k) {
      rest.emplace_back(R * std::sin(k * step), R * (1.0 - std::cos(k * step)), 0.0);
      start.emplace_back(k * chord, 0.0, 0.0);
    }
    Structure3dInput in;
    in.wires.push_back({"arc", rest, start, Vec3::UnitZ()});
    in.clamps = {{0, 0}, {0, n}};
    const Structure3dResult r = solve_structure3d(in, o);
    INFO(n << " edges: " << describe(r.cause, r.cause_figure));
    REQUIRE(r.converged);
    const double M = o.bending_stiffness / R, error = std::abs(std::abs(r.clamps[0].moment.z()) / M - 1.0);
    INFO("moment " << r.clamps[0].moment.transpose() << " against " << M);
    CHECK(error < 1.05 * step * step / 8.0);
    if (n == 20) CHECK(error < 0.3 * previous);
    CHECK(std::hypot(r.clamps[0].moment.x(), r.clamps[0].moment.y()) < 1e-9 * M);
    CHECK(r.clamps[0].force.norm() < 1e-7 * M / R);
    CHECK(r.clamps[1].force.norm() < 1e-7 * M / R);
    CHECK((r.clamps[0].moment + r.clamps[1].moment).norm() < 1e-7 * M);
    CHECK(r.wires[0].max_distance < 1e-9 * R);
    previous = error;
  }
}

namespace {

/// Two rods in perpendicular planes: A straight along x (z = 0 plane's normal z), 8 edges of
/// 2.5 cm, clamped at x = 0; B an arc of radius 8 cm in the plane x = 0.1 hanging below A, its
/// middle vertex tied to A's vertex 4 (both at (0.1, 0, 0)), pinned at both ends.
Structure3dInput tied_pair() {
  Structure3dInput in;
  Polyline3 a, b;
  const double r = 0.08;
  for (int k = 0; k <= 8; ++k) {
    a.emplace_back(0.025 * k, 0.0, 0.0);
    const double phi = -0.5 * pi + k * pi / 8.0;
    b.emplace_back(0.1, r * std::sin(phi), r * std::cos(phi) - r);
  }
  in.wires = {wire("A", a, Vec3::UnitZ()), wire("B", b, Vec3::UnitX())};
  in.ties.push_back({{0, 4}, {1, 4}, Vec3::Zero()});
  in.clamps.push_back({0, 0});
  in.pins = {{1, 0}, {1, 8}};
  in.loads = {{{0, 8}, Vec3(0.0, 0.1, -0.2)}, {{1, 2}, Vec3(0.1, 0.0, -0.1)}};
  return in;
}

/// The weight lumped as the model states it: half of each edge's rest weight at either end.
std::vector<std::vector<Vec3>> lumped_weight(const Structure3dInput& in, const Structure3dOptions& o) {
  std::vector<std::vector<Vec3>> w;
  for (const Structure3dWire& wire : in.wires) {
    w.emplace_back(wire.rest.size(), Vec3::Zero());
    for (std::size_t e = 0; e + 1 < wire.rest.size(); ++e) {
      const Vec3 half = 0.5 * o.linear_density * (wire.rest[e + 1] - wire.rest[e]).norm() * o.gravity;
      w.back()[e] += half, w.back()[e + 1] += half;
    }
  }
  return w;
}

}  // namespace

TEST_CASE("structure3d: two rods tied at a point: equal and opposite tie forces, equilibrium closes", "[structure3d]") {
  const Structure3dInput in = tied_pair();
  const Structure3dOptions o;  // with weight
  const Structure3dResult r = solve_structure3d(in, o);
  INFO(describe(r.cause, r.cause_figure));
  REQUIRE(r.converged);
  const std::vector<std::vector<Vec3>> weight = lumped_weight(in, o);
  // Free bodies: every external force on a wire, its supports' reactions and the tie (on A: T,
  // on B: -T) must sum to 0, and so must their moments about the origin (at the deformed nodes).
  std::vector<Vec3> force(2, Vec3::Zero()), moment(2, Vec3::Zero());
  auto add = [&](int w, int v, const Vec3& f) {
    force[w] += f;
    moment[w] += r.wires[w].points[v].cross(f);
  };
  for (int w = 0; w < 2; ++w)
    for (int v = 0; v < 9; ++v) add(w, v, weight[w][v]);
  for (const Structure3dLoad& l : in.loads) add(l.node.wire, l.node.vertex, l.force);
  add(0, 0, r.clamps[0].force);
  moment[0] += r.clamps[0].moment;
  for (const Structure3dReaction& p : r.pins) add(p.node.wire, p.node.vertex, p.force);
  const Vec3 tie = r.tie_forces[0];
  add(0, 4, tie);
  add(1, 4, -tie);
  // The residual is 1e-8 of the load scale (about 0.9 N here) per node; 9 nodes a wire, arms
  // under 0.2 m.
  const double scale = r.load_scale;
  CHECK(tie.norm() > 0.05);  // the tie carries B's load: not a trivial zero
  for (int w = 0; w < 2; ++w) {
    INFO("wire " << w << ": force " << force[w].transpose() << ", moment " << moment[w].transpose());
    CHECK(force[w].norm() < 1e-7 * scale);
    CHECK(moment[w].norm() < 1e-7 * scale * 0.2);
  }
  CHECK((r.wires[0].points[4] - r.wires[1].points[4]).norm() < 1e-12);
  CHECK(r.wires[0].max_distance > 1e-4);  // A's tip sags
}

TEST_CASE("structure3d: a tie with an offset holds its offset and still balances", "[structure3d]") {
  // tied_pair with the tie's nodes to be 3 mm apart along z (A's above B's, as two wires' axes at
  // a crossing), from a start where they coincide: the start is made to hold the tie, the result
  // holds it to rounding, and each wire's forces balance with ±T.
  Structure3dInput in = tied_pair();
  in.ties[0].offset = Vec3(0.0, 0.0, 0.003);
  const Structure3dOptions o;
  const Structure3dResult r = solve_structure3d(in, o);
  INFO(describe(r.cause, r.cause_figure));
  REQUIRE(r.converged);
  CHECK((r.wires[0].points[4] - r.wires[1].points[4] - in.ties[0].offset).norm() < 1e-12);
  const std::vector<std::vector<Vec3>> weight = lumped_weight(in, o);
  Vec3 on_a = r.clamps[0].force + in.loads[0].force + r.tie_forces[0];
  Vec3 on_b = r.pins[0].force + r.pins[1].force + in.loads[1].force - r.tie_forces[0];
  for (int v = 0; v < 9; ++v) on_a += weight[0][v], on_b += weight[1][v];
  CHECK(on_a.norm() < 1e-7 * r.load_scale);
  CHECK(on_b.norm() < 1e-7 * r.load_scale);
}

TEST_CASE("structure3d: a wire held at one point does not stand", "[structure3d]") {
  // A and B as tied_pair, but B straight along y (plane x = 0.1) and held by its one tie alone.
  Polyline3 a;
  for (int k = 0; k <= 8; ++k) a.emplace_back(0.025 * k, 0.0, 0.0);
  auto structure = [&](double y0, int tied_vertex) {
    Polyline3 b;
    for (int k = 0; k <= 8; ++k) b.emplace_back(0.1, y0 + 0.025 * k, 0.0);
    Structure3dInput in;
    in.wires = {wire("A", a, Vec3::UnitZ()), wire("B", b, Vec3::UnitX())};
    in.clamps.push_back({0, 0});
    in.ties.push_back({{0, 4}, {1, tied_vertex}, Vec3::Zero()});
    return in;
  };
  SECTION("off its centre of mass: it swings away") {
    const Structure3dResult r = solve_structure3d(structure(-0.05, 2));
    INFO(describe(r.cause, r.cause_figure));
    CHECK_FALSE(r.converged);
    CHECK((r.cause == Structure3dCause::moved_away || r.cause == Structure3dCause::no_equilibrium ||
           r.cause == Structure3dCause::mechanism));
  }
  SECTION("at its centre of mass: it balances but turns freely about the vertical") {
    const Structure3dResult r = solve_structure3d(structure(-0.1, 4));
    INFO(describe(r.cause, r.cause_figure));
    CHECK_FALSE(r.converged);
    CHECK(r.cause == Structure3dCause::mechanism);
  }
  SECTION("held at two points by two cantilevers it stands") {
    Polyline3 a2;
    for (int k = 0; k <= 8; ++k) a2.emplace_back(0.025 * k, 0.05, 0.0);
    Structure3dInput in = structure(-0.1, 4);
    in.wires[0].rest = in.wires[0].start = a;
    for (Vec3& p : in.wires[0].rest) p.y() = -0.05;
    in.wires[0].start = in.wires[0].rest;
    in.wires.push_back(wire("A2", a2, Vec3::UnitZ()));
    in.clamps = {{0, 0}, {2, 0}};
    in.ties = {{{0, 4}, {1, 2}, Vec3::Zero()}, {{2, 4}, {1, 6}, Vec3::Zero()}};
    const Structure3dResult r = solve_structure3d(in);
    INFO(describe(r.cause, r.cause_figure));
    CHECK(r.converged);
  }
}

TEST_CASE("structure3d: a heavy rod lifted at one end off the table", "[structure3d]") {
  // A straight steel rod (weight w per metre) lying on the table z = 0, every node a table node,
  // lifted at its end x = 0 by P upwards. Linear beam theory on a rigid floor: it leaves the table
  // where its moment vanishes, a = 2 P / w from the end (a concentrated push there), and the end
  // rises δ = P a³/(3 E I) - w a⁴/(8 E I) = (2/3) P⁴ / (w³ E I). Here a = 0.37 m, δ = 0.57 mm
  // (δ/a 0.15%: linear). The table's sink (under 1 µm) is common to both ends; the edges (5 mm)
  // resolve the lift-off point well enough for 0.5% (measured 0.03%). The table pushes only: the
  // lifted nodes get 0 and the pushes sum to the weight - P.
  const Structure3dOptions o;
  const double w = o.linear_density * -o.gravity.z(), P = 0.1, length = 0.8;
  const int n = 160;
  Polyline3 pts;
  for (int k = 0; k <= n; ++k) pts.emplace_back(length * k / n, 0.0, 0.0);
  Structure3dInput in;
  in.wires.push_back(wire("rod", pts, Vec3::UnitY()));
  in.table.enabled = true;
  in.loads.push_back({{0, 0}, Vec3(0, 0, P)});
  const Structure3dResult r = solve_structure3d(in, o);
  INFO(describe(r.cause, r.cause_figure));
  REQUIRE(r.converged);
  const double delta = r.wires[0].points[0].z() - r.wires[0].points[n].z();
  const double expected = 2.0 / 3.0 * std::pow(P, 4) / (std::pow(w, 3) * o.bending_stiffness);
  INFO("end rise " << delta << " against " << expected);
  CHECK(delta == Approx(expected).epsilon(0.005));
  double push = 0.0;
  for (const Structure3dReaction& t : r.table) push += t.force.z();
  CHECK(push == Approx(w * length - P).epsilon(1e-7));
  CHECK(r.table[0].force.z() == 0.0);
  CHECK(r.table[10].force.z() == 0.0);  // 5 cm from the lifted end, well inside a
  CHECK(r.table[n].force.z() > 0.0);
  for (const Structure3dReaction& t : r.table) CHECK(std::hypot(t.force.x(), t.force.y()) < 1e-9);
}

TEST_CASE("structure3d: gradient and Hessian against finite differences", "[structure3d]") {
  // A bent, twisted rod away from both its rest and its reference frames: a zigzag rest polyline in
  // z = 0, nodes moved at random by up to 1 cm, angles at random in ±0.5 rad, frames based on yet
  // another shape (so the time-parallel transport is exercised), one node 2 mm under the table.
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  Polyline3 rest;
  for (int k = 0; k < 7; ++k) rest.emplace_back(0.03 * k, 0.01 * (k % 2) + 0.002 * k * k, 0.0);
  Structure3dInput in;
  in.wires.push_back({"zigzag", rest, rest, Vec3(0.1, 0.2, 1.0)});
  in.table.enabled = true;
  in.table.z0 = 0.0;
  in.table.nodes = {{0, 3}};
  in.table.hold_horizontal = false;
  in.loads.push_back({{0, 6}, Vec3(0.3, -0.2, 0.1)});
  detail::Model m = detail::build_model(in, Structure3dOptions{});
  Eigen::VectorXd base = m.start;
  for (int i = 0; i < 21; ++i) base(i) += 0.005 * u(rng);
  detail::rebase_frames(m, base);
  Eigen::VectorXd q = m.start;
  for (int i = 0; i < 21; ++i) q(i) += 0.01 * u(rng);
  for (int e = 0; e < 6; ++e) q(21 + e) = 0.5 * u(rng);
  q(3 * 3 + 2) = -0.002;
  REQUIRE(m.reduced_dofs == m.full_dofs);  // nothing held: the reduced Hessian is the full one
  Eigen::VectorXd g;
  std::vector<Eigen::Triplet<double>> triplets;
  detail::assemble(m, q, g, triplets);
  Eigen::SparseMatrix<double> h(m.full_dofs, m.full_dofs);
  h.setFromTriplets(triplets.begin(), triplets.end());
  const Eigen::MatrixXd H = Eigen::MatrixXd(h);
  // Central differences, step 1e-6 (m or rad): truncation ~ (1e-6)² × the third derivative over
  // the first, rounding ~ 1e-16 × |Π| / 1e-6; both under 1e-6 of the largest entry.
  const double step = 1e-6;
  Eigen::VectorXd g_fd(m.full_dofs);
  Eigen::MatrixXd h_fd(m.full_dofs, m.full_dofs);
  for (int i = 0; i < m.full_dofs; ++i) {
    Eigen::VectorXd qp = q, qm = q, gp, gm;
    qp(i) += step, qm(i) -= step;
    g_fd(i) = (detail::total_energy(m, qp) - detail::total_energy(m, qm)) / (2 * step);
    std::vector<Eigen::Triplet<double>> unused;
    detail::assemble(m, qp, gp, unused);
    detail::assemble(m, qm, gm, unused);
    h_fd.col(i) = (gp - gm) / (2 * step);
  }
  INFO("gradient error " << (g_fd - g).cwiseAbs().maxCoeff() << " of " << g.cwiseAbs().maxCoeff());
  CHECK((g_fd - g).cwiseAbs().maxCoeff() < 1e-6 * g.cwiseAbs().maxCoeff());
  INFO("Hessian error " << (h_fd - H).cwiseAbs().maxCoeff() << " of " << H.cwiseAbs().maxCoeff());
  CHECK((h_fd - H).cwiseAbs().maxCoeff() < 1e-6 * H.cwiseAbs().maxCoeff());
  CHECK((H - H.transpose()).cwiseAbs().maxCoeff() < 1e-9 * H.cwiseAbs().maxCoeff());
  // The angles' block is not trivial (twist and bending both reach it).
  CHECK(H.block(21, 0, 6, 21).cwiseAbs().maxCoeff() > 1e-3);
  CHECK(g.segment(21, 6).cwiseAbs().maxCoeff() > 1e-3);
}

TEST_CASE("structure3d: bad input gives one InputError naming it", "[structure3d]") {
  Polyline3 a;
  for (int k = 0; k <= 4; ++k) a.emplace_back(0.05 * k, 0.0, 0.0);
  Structure3dInput good;
  good.wires = {wire("A", a, Vec3::UnitZ()), wire("B", a, Vec3::UnitZ())};
  for (Vec3& p : good.wires[1].rest) p.z() = -0.01;
  good.wires[1].start = good.wires[1].rest;
  good.clamps.push_back({0, 0});
  auto fails = [](const Structure3dInput& in, const std::string& text, const Structure3dOptions& o = {}) {
    CHECK_THROWS_AS(solve_structure3d(in, o), InputError);
    CHECK_THROWS_WITH(solve_structure3d(in, o), Catch::Contains(text));
  };
  Structure3dInput in = good;
  in.wires[1].start[2].y() = std::nan("");
  fails(in, "wire 1 'B': start point 2 is not finite");
  in = good;
  in.ties.push_back({{0, 2}, {1, 9}, Vec3::Zero()});
  fails(in, "tie 0: vertex 9 does not exist on wire 1 'B'");
  in = good;
  in.wires[0].rest[3] = in.wires[0].rest[2];
  fails(in, "wire 0 'A': rest edge 2 has zero length");
  in = good;
  in.ties.push_back({{0, 1}, {1, 1}, Vec3::Zero()});
  fails(in, "tie 0: vertex 1 of wire 0 'A' is held by a clamp or pin");
  in = good;
  in.ties = {{{0, 3}, {1, 3}, Vec3::Zero()}, {{0, 3}, {1, 4}, Vec3::Zero()}};
  fails(in, "tie 1: vertex 3 of wire 0 'A' is already in tie 0");
  in = good;
  in.wires[0].normal = Vec3::UnitX();
  fails(in, "wire 0 'A': the normal lies along the first rest edge");
  in = good;
  in.loads.push_back({{2, 0}, Vec3::Zero()});
  fails(in, "load 0: wire 2 does not exist");
  Structure3dOptions o;
  o.bending_stiffness = 0.0;
  fails(good, "bending_stiffness", o);
  o = {};
  o.shear_modulus = -1.0;
  fails(good, "shear_modulus", o);
}

TEST_CASE("structure3d: moving too far and running out of iterations are told apart", "[structure3d]") {
  // The elastica of P L²/EI = 2 (tip down 0.49 L = 15 cm): with max_motion 1 cm it has moved away;
  // with one Newton iteration it has not converged. The sentence names the motion in mm.
  Structure3dInput in;
  in.wires.push_back(wire("cantilever", cantilever_points(0.3, 10), Vec3::UnitY()));
  in.clamps.push_back({0, 0});
  in.loads.push_back({{0, 10}, Vec3(0, 0, -2.0 * 0.73 / 0.09)});
  Structure3dOptions o = weightless();
  o.max_motion = 0.01;
  const Structure3dResult far = solve_structure3d(in, o);
  CHECK_FALSE(far.converged);
  CHECK(far.cause == Structure3dCause::moved_away);
  CHECK(far.cause_figure > 0.01);
  CHECK(describe(far.cause, far.cause_figure).find(" mm ") != std::string::npos);
  o = weightless();
  o.max_iterations = 1;
  const Structure3dResult capped = solve_structure3d(in, o);
  CHECK_FALSE(capped.converged);
  CHECK(capped.cause == Structure3dCause::iteration_cap);
  CHECK(capped.iterations == 1);
  CHECK(capped.residual > o.tolerance);
}

TEST_CASE("structure3d: progress is reported and cancellation honoured", "[structure3d]") {
  Structure3dInput in;
  in.wires.push_back(wire("cantilever", cantilever_points(0.3, 10), Vec3::UnitY()));
  in.clamps.push_back({0, 0});
  in.loads.push_back({{0, 10}, Vec3(0, 0, -10.0)});
  int calls = 0;
  const Structure3dResult r = solve_structure3d(in, weightless(), [&](std::string_view stage, double f) {
    CHECK(stage == "structure3d");
    CHECK((f >= 0.0 && f <= 1.0));
    return ++calls > 0;
  });
  CHECK(r.converged);
  CHECK(calls == r.iterations);
  CHECK(calls > 1);
  CHECK_THROWS_AS(solve_structure3d(in, weightless(), [](std::string_view, double) { return false; }), Cancelled);
}

TEST_CASE("structure3d: a force in or out of a contact pyramid", "[structure3d]") {
  // The cone of x, y, z and (1, 1, 1): every force with nonnegative coordinates is in it; the
  // nearest point of the cone to (-1, 2, 3) is (0, 2, 3), at distance 1; to (-1, -1, -1) it is the
  // apex, at distance √3.
  const std::array<Vec3, 4> cone{Vec3::UnitX(), Vec3::UnitY(), Vec3::UnitZ(), Vec3(1, 1, 1)};
  const PyramidFit in = pyramid_fit(Vec3(2, 3, 0.5), cone);
  CHECK(in.inside);
  CHECK(in.distance < 1e-12);
  Vec3 sum = Vec3::Zero();
  for (int i = 0; i < 4; ++i) {
    CHECK(in.coefficients[i] >= 0.0);
    sum += in.coefficients[i] * cone[i];
  }
  CHECK((sum - Vec3(2, 3, 0.5)).norm() < 1e-12);
  const PyramidFit out = pyramid_fit(Vec3(-1, 2, 3), cone);
  CHECK_FALSE(out.inside);
  CHECK(out.distance == Approx(1.0).epsilon(1e-12));
  CHECK(pyramid_fit(Vec3(-1, -1, -1), cone).distance == Approx(std::sqrt(3.0)).epsilon(1e-12));
  // A narrow pyramid about -z (a hook's friction cone, half-angle 20°): a force 10° off its axis
  // is in, 30° off is out.
  std::array<Vec3, 4> narrow;
  const double s = std::sin(20.0 * pi / 180), c = std::cos(20.0 * pi / 180);
  narrow = {Vec3(s, 0, -c), Vec3(-s, 0, -c), Vec3(0, s, -c), Vec3(0, -s, -c)};
  CHECK(pyramid_fit(Vec3(std::sin(0.1745), 0, -std::cos(0.1745)), narrow).inside);
  CHECK_FALSE(pyramid_fit(Vec3(std::sin(0.5236), 0, -std::cos(0.5236)), narrow).inside);
}
