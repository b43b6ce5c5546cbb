// Internal forces (Sec. 4.4, Eq. 6-8): pyramids from the target geometry against contact.hpp's
// idealised ones, the symmetric three-circle sphere, the torque bound, equilibrium at the
// optimum, LP vs SLSQP as independent solvers, and finite-difference gradients.
#include <catch2/catch.hpp>
#include <cmath>
#include <limits>
#include <numbers>
#include <random>
#include <set>
#include <utility>

#include "lp.hpp"  // native/src: the core's LP layer
#include "wire_fixtures.hpp"
#include "wiresculpt/contact.hpp"
#include "wiresculpt/error.hpp"
#include "wiresculpt/forces.hpp"

using namespace wiresculpt;
using Catch::Matchers::Contains;

namespace {

// The three orthogonal great circles (radius 0.125 m, 64-gons with vertices on the axes), every
// crossing hooked so that the configuration has the sphere's symmetry (the 3-fold rotation
// x -> y -> z and the central inversion): hook +1 at the crossings on the positive half-axes,
// -1 on the negative ones. Each kink is the exact symmetric one of hook_geometry (opening
// `contact_angle` about its desired bisector), so it is the target the pyramids are read from.
struct Sphere {
  Network net;
  std::vector<int> hooks;
  std::vector<std::vector<int>> steps{{0, 1}, {2}};
};

// Axis index (0 x, 1 y, 2 z) of a unit vector along a coordinate axis.
int axis_of(const Vec3& v) {
  int a = 0;
  v.cwiseAbs().maxCoeff(&a);
  return a;
}

// Hook patterns of the three great circles. `symmetric`: the sphere's symmetry (above).
// `ellipse`: every crossing hooked so that each wire is pinched (pushed inwards) at its two
// crossings on one axis and spread (pushed outwards) at the two on the other: the wire of normal
// e_a is pinched on e_(a+1). A pinched or spread ring is in equilibrium under radial forces
// alone, and a radial force lies in both planes (it is along d): no out-of-plane part is needed.
enum class Hooks { symmetric, ellipse };

int ellipse_hook(const Network& net, int c) {
  const Crossing& x = net.crossings[c];
  const Vec3 d = crossing_direction(net, c);
  const int along = axis_of(x.point);
  const int pinched_first = (axis_of(net.wires[x.wires[0]].plane.normal) + 1) % 3 == along;
  // The force on wires[0] is along -hook d: inwards (f·p < 0) when hook = sign(d·p).
  const int s = d.dot(x.point) > 0 ? 1 : -1;
  return pinched_first ? s : -s;
}

Sphere hooked_sphere(double contact_angle = 2.0 * std::numbers::pi / 3.0, Hooks pattern = Hooks::symmetric) {
  Sphere s;
  s.net = build_network(fixtures::sphere_wires(fixtures::great_circle_cuts(), 0.125, 64));
  ContactOptions co;
  co.contact_angle = contact_angle;
  for (std::size_t c = 0; c < s.net.crossings.size(); ++c) {
    const Vec3& p = s.net.crossings[c].point;
    s.hooks.push_back(pattern == Hooks::ellipse ? ellipse_hook(s.net, static_cast<int>(c)) : p.sum() > 0 ? 1 : -1);
  }
  Network idealised = s.net;
  for (std::size_t c = 0; c < s.net.crossings.size(); ++c) {
    const HookGeometry g = hook_geometry(s.net, static_cast<int>(c), s.hooks[c], co);
    for (int k = 0; k < 2; ++k) {
      WireSpec& w = idealised.wires[s.net.crossings[c].wires[k]];
      const int n = static_cast<int>(w.points.size());
      const int v = s.net.crossings[c].vertices[k];
      w.points[(v + n - 1) % n] = g.neighbours[k][0];
      w.points[(v + 1) % n] = g.neighbours[k][1];
    }
  }
  s.net = idealised;
  return s;
}

// Cuts mapped onto each other by the rotation x -> y -> z: wire X at (0,1,1)/√2, Y at (1,0,1)/√2,
// Z at (1,1,0)/√2 (each is the middle of a piece between two crossings).
std::vector<int> symmetric_cuts(const Network& net) {
  const Vec3 dirs[3] = {Vec3(0, 1, 1).normalized(), Vec3(1, 0, 1).normalized(), Vec3(1, 1, 0).normalized()};
  std::vector<int> cuts;
  for (int w = 0; w < 3; ++w) {
    const auto& pts = net.wires[w].points;
    int best = 0;
    for (int i = 0; i < static_cast<int>(pts.size()); ++i)
      if (pts[i].normalized().dot(dirs[w]) > pts[best].normalized().dot(dirs[w])) best = i;
    REQUIRE(pts[best].normalized().dot(dirs[w]) > 1 - 1e-12);
    cuts.push_back(best);
  }
  return cuts;
}

// G_stb alone (the LP) with the symmetric cuts.
ForceResult lp_optimum(const Sphere& s, ForceOptions o) {
  o.assembly_weight = 0.0;
  o.algorithm = ForceAlgorithm::lp;
  return optimize_forces(s.net, s.hooks, s.steps, symmetric_cuts(s.net), o);
}

}  // namespace

TEST_CASE("forces: target pyramids of symmetric kinks are contact.hpp's pyramids", "[forces]") {
  const Sphere s = hooked_sphere();
  REQUIRE(s.net.crossings.size() == 6);
  ContactOptions co;
  for (int c = 0; c < 6; ++c) {
    const auto ideal = contact_pyramid(s.net, c, s.hooks[c], co);
    const auto actual = target_pyramid(s.net, c, s.hooks[c], co.friction);
    // Same set of vectors (the order of the two arms may differ).
    for (const Vec3& b : actual) {
      double best = 1e9;
      for (const Vec3& q : ideal) best = std::min(best, (b - q).norm());
      CHECK(best < 1e-12);
    }
    // docs/formats.md sign: every vector on wires[0] has a -hook component along d.
    const Vec3 d = crossing_direction(s.net, c);
    for (const Vec3& b : actual) CHECK(b.dot(d) * s.hooks[c] < 0);
  }
  CHECK_THROWS_AS(target_pyramid(s.net, 0, 0, 0.3), InputError);
}

TEST_CASE("forces: the symmetric three-circle sphere has symmetric forces", "[forces]") {
  const Sphere s = hooked_sphere();
  const auto cuts = symmetric_cuts(s.net);
  ForceOptions o;
  o.assembly_weight = 0.0;  // the assembly order is not symmetric; G_stb alone is
  for (ForceAlgorithm alg : {ForceAlgorithm::lp, ForceAlgorithm::slsqp}) {
    o.algorithm = alg;
    const ForceResult r = optimize_forces(s.net, s.hooks, s.steps, cuts, o);
    REQUIRE(r.normal.size() == 6);
    CHECK(r.g_stb > 0);
    CHECK(r.equilibrium_residual < 1e-9);
    // The rotation x -> y -> z maps wires, hooks, kinks, walk directions and these cuts onto
    // each other; its orbits are the crossings on the positive and on the negative half-axes.
    // (A cut breaks the central inversion, so the two orbits may differ.)
    for (int sign : {1, -1}) {
      int first = -1;
      for (int c = 0; c < 6; ++c) {
        if ((s.net.crossings[c].point.sum() > 0 ? 1 : -1) != sign) continue;
        if (first < 0) {
          first = c;
          continue;
        }
        CHECK(r.normal[c] == Approx(r.normal[first]).epsilon(1e-6));
        CHECK(r.forces[c].norm() == Approx(r.forces[first].norm()).epsilon(1e-6));
      }
    }
    CHECK(r.torque_active);
  }
}

TEST_CASE("forces: LP and SLSQP agree, and the assembly term trades little G_stb", "[forces]") {
  const Sphere s = hooked_sphere();
  const auto cuts = choose_cuts(s.net);
  ForceOptions o;
  o.assembly_weight = 0.0;
  o.algorithm = ForceAlgorithm::lp;
  const ForceResult lp = optimize_forces(s.net, s.hooks, s.steps, cuts, o);
  o.algorithm = ForceAlgorithm::slsqp;
  const ForceResult nlp = optimize_forces(s.net, s.hooks, s.steps, cuts, o);
  CHECK(nlp.g_stb == Approx(lp.g_stb).epsilon(1e-6));
  // With G_asm: the combined solver and SLSQP from zero reach the same G (a convex QP).
  o.assembly_weight = 0.05;
  o.algorithm = ForceAlgorithm::lp_then_slsqp;
  const ForceResult both = optimize_forces(s.net, s.hooks, s.steps, cuts, o);
  o.algorithm = ForceAlgorithm::slsqp;
  const ForceResult alone = optimize_forces(s.net, s.hooks, s.steps, cuts, o);
  CHECK(both.method == "lp+slsqp");
  CHECK(both.g_stb + both.g_asm == Approx(alone.g_stb + alone.g_asm).epsilon(1e-6));
  // The combined optimum is at least as good as the LP's point under the combined objective.
  const ForceProblem p(s.net, s.hooks, s.steps, cuts, o);
  CHECK(both.g_stb + both.g_asm >= lp.g_stb - p.weight() * lp.assembly_residual - 1e-9);
  CHECK(both.g_asm == Approx(-p.weight() * both.assembly_residual));
  CHECK(both.assembly_residual <= lp.assembly_residual + 1e-9);
  CHECK(both.g_stb <= lp.g_stb + 1e-9);
  CHECK(both.equilibrium_residual < 1e-9);
  CHECK(alone.equilibrium_residual < 1e-9);
}

TEST_CASE("forces: the torque bound is active and G_stb drops with the torque fraction", "[forces]") {
  // in_plane: the largest plane-normal torque reaches t_max. 3D (default): the largest 3D torque
  // reaches the polytope's boundary, between (1 - gap) t_max and t_max.
  const Sphere s = hooked_sphere();
  const auto cuts = choose_cuts(s.net);
  for (const TorqueBound bound : {TorqueBound::in_plane, TorqueBound::full_3d}) {
  double previous = 1e300;
  for (double fraction : {1.0, 0.6, 0.3}) {
    ForceOptions o;
    o.torque_fraction = fraction;
    o.torque_bound = bound;
    const ForceResult r = optimize_forces(s.net, s.hooks, s.steps, cuts, o);
    CHECK(r.t_max == Approx(1.77 * fraction));
    CHECK(r.torque_active);
    CHECK(r.torque_bound == bound);
    double worst = 0, worst_3d = 0;
    for (const WireTorque& w : r.wires) {
      worst = std::max(worst, w.max_torque);
      worst_3d = std::max(worst_3d, w.max_torque_3d);
    }
    CHECK(worst <= r.t_max * (1 + 1e-7));
    if (bound == TorqueBound::in_plane) {
      CHECK(worst >= r.t_max * (1 - 1e-6));
    } else {
      CHECK(worst_3d <= r.t_max * (1 + 1e-7));
      CHECK(worst_3d >= r.t_max * (1 - torque_polytope(bound).gap) * (1 - 1e-9));
    }
    CHECK(r.g_stb < previous);
    previous = r.g_stb;
    CHECK(r.equilibrium_residual < 1e-9);
    // a >= 0 and every normal force >= 0.
    CHECK(r.coefficients.minCoeff() >= 0.0);
    for (double nk : r.normal) CHECK(nk >= -1e-9);
  }
  }
}

TEST_CASE("forces: null crossings carry no force, and M a = 0 at the optimum", "[forces]") {
  Sphere s = hooked_sphere();
  s.hooks[1] = 0;
  const auto cuts = choose_cuts(s.net);
  const ForceResult r = optimize_forces(s.net, s.hooks, s.steps, cuts);
  CHECK(r.forces[1].norm() == 0.0);
  CHECK(r.normal[1] == 0.0);
  CHECK(r.coefficients.size() == 20);
  // Independent equilibrium check: per wire, sum of forces and of moments about the origin.
  for (int w = 0; w < 3; ++w) {
    Vec3 f = Vec3::Zero(), m = Vec3::Zero();
    double scale = 0;
    for (const WireLoad& l : wire_loads(s.net, s.hooks, r.forces, w)) {
      f += l.force;
      m += s.net.wires[w].points[l.vertex].cross(l.force);
      scale += l.force.norm();
    }
    CHECK(f.norm() <= 1e-9 * scale);
    CHECK(m.norm() <= 1e-9 * scale * 0.125);
  }
}

TEST_CASE("forces: the objective's gradient matches finite differences", "[forces]") {
  const Sphere s = hooked_sphere();
  const auto cuts = choose_cuts(s.net);
  ForceOptions o;
  o.assembly_weight = 0.3;
  const ForceProblem p(s.net, s.hooks, s.steps, cuts, o);
  REQUIRE(p.weight() > 0);
  REQUIRE(p.assembly_matrix().norm() > 0);
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(0.0, 5.0);
  for (int trial = 0; trial < 3; ++trial) {
    Eigen::VectorXd a(p.columns());
    for (int j = 0; j < p.columns(); ++j) a(j) = u(rng);
    Eigen::VectorXd g;
    p.objective(a, &g);
    for (int j = 0; j < p.columns(); ++j) {
      const double h = 1e-5;
      Eigen::VectorXd ap = a, am = a;
      ap(j) += h;
      am(j) -= h;
      const double fd = (p.objective(ap) - p.objective(am)) / (2 * h);
      CHECK(g(j) == Approx(fd).epsilon(1e-7).margin(1e-9));
    }
  }
  // Torque rows are Eq. 11's plane-normal component: check one row against a direct sum.
  Eigen::VectorXd a = Eigen::VectorXd::Zero(p.columns());
  for (int j = 0; j < p.columns(); ++j) a(j) = 1.0 + 0.1 * j;
  const auto f = p.forces(a);
  const Eigen::VectorXd t = p.torque_rows() * a;
  for (int row : {0, 5, 40, 100}) {
    const auto [w, v] = p.torque_vertex()[row];
    // walk from the cut: vertices after v are those later in the walk
    const int n = static_cast<int>(s.net.wires[w].points.size());
    const int cut = cuts[w];
    const int pos_v = (v - cut + n) % n;
    Vec3 sum = Vec3::Zero();
    for (const WireLoad& l : wire_loads(s.net, s.hooks, f, w))
      if ((l.vertex - cut + n) % n > pos_v) sum += (s.net.wires[w].points[v] - s.net.wires[w].points[l.vertex]).cross(l.force);
    CHECK(t(row) == Approx(sum.dot(s.net.wires[w].plane.normal)).margin(1e-12));
  }
}

TEST_CASE("forces: bad input names the crossing or wire", "[forces]") {
  const Sphere s = hooked_sphere();
  const auto cuts = choose_cuts(s.net);
  std::vector<int> hooks = s.hooks;
  hooks[2] = 3;
  CHECK_THROWS_WITH(optimize_forces(s.net, hooks, s.steps, cuts), Contains("crossing 2"));
  CHECK_THROWS_AS(optimize_forces(s.net, s.hooks, s.steps, {1, 2}), InputError);
  ForceOptions o;
  o.torque_fraction = 0.0;
  CHECK_THROWS_WITH(optimize_forces(s.net, s.hooks, s.steps, cuts, o), Contains("torque_fraction"));
  CHECK_THROWS_WITH(optimize_forces(s.net, s.hooks, {{0, 1}, {1}}, cuts), Contains("twice"));
}

TEST_CASE("forces: progress can cancel", "[forces]") {
  const Sphere s = hooked_sphere();
  const auto cuts = choose_cuts(s.net);
  CHECK_THROWS_AS(optimize_forces(s.net, s.hooks, s.steps, cuts, {}, [](std::string_view, double) { return false; }),
                  Cancelled);
}

TEST_CASE("forces: the working set reaches the optimum of the full constraint set", "[forces]") {
  // Random sphere cuts with random hooks: SLSQP over every torque row (the reference) and over
  // the growing working set must agree on G, and the working-set result must satisfy every row.
  // With a tiny first margin the set starts from the LP's active rows alone and has to grow.
  // Both bounds; the 3D reference holds all 180 rows of every vertex, so its wires are coarser.
  for (const TorqueBound bound : {TorqueBound::in_plane, TorqueBound::full_3d})
  for (const double margin : {0.5, 1e-3}) {
    const bool in_plane = bound == TorqueBound::in_plane;
    std::mt19937 rng(11);
    int tested = 0, grew = 0;
    const int wanted = in_plane ? 12 : 5;
    for (int attempt = 0; attempt < 400 && tested < wanted; ++attempt) {
      fixtures::HookedNetwork h;
      if (!fixtures::random_hooked_sphere(rng, attempt, in_plane ? 48 : 20, h)) continue;
      const Network& net = h.net;
      const std::vector<int>& hooks = h.hooks;
      const auto& steps = h.steps;
      const int P = static_cast<int>(net.wires.size()), C = static_cast<int>(net.crossings.size());
      ForceOptions o;
      o.torque_bound = bound;
      o.torque_fraction = attempt % 2 ? 1.0 : 0.3;
      o.working_set_margin = o.working_set_margin_3d = margin;
      ForceResult full, ws;
      try {
        o.working_set = false;
        full = optimize_forces(net, hooks, steps, choose_cuts(net), o);
        o.working_set = true;
        ws = optimize_forces(net, hooks, steps, choose_cuts(net), o);
      } catch (const SolverError&) {
        continue;  // random hooks may leave a force no torque bounds
      }
      if (full.method != "lp+slsqp") continue;
      ++tested;
      INFO(torque_bound_name(bound) << ", margin " << margin << ", attempt " << attempt << ", " << P << " wires, " << C
                                    << " crossings");
      CHECK(ws.method == "lp+slsqp");
      const double G_full = full.g_stb + full.g_asm, G_ws = ws.g_stb + ws.g_asm;
      CHECK(G_ws == Approx(G_full).epsilon(1e-7));
      // every row of the full problem holds at the working-set optimum
      const ForceProblem p(net, hooks, steps, ws.cuts, o);
      CHECK(p.torque_gauges(ws.coefficients).maxCoeff() <= 1 + 1e-7);
      CHECK((p.torque_rows() * ws.coefficients).cwiseAbs().maxCoeff() <= p.t_max() * (1 + 1e-7));
      CHECK(ws.coefficients.minCoeff() >= 0.0);
      CHECK(ws.equilibrium_residual < 1e-9);
      CHECK(ws.working_set_rows < full.working_set_rows);
      if (ws.working_set_rounds > 1) ++grew;
    }
    INFO(torque_bound_name(bound) << ", margin " << margin);
    CHECK(tested >= wanted - 2);
    if (margin < 0.01) CHECK(grew > 0);
  }
}

TEST_CASE("forces: the 3D polytope lies inside the ball and touches it at +-n", "[forces][torque]") {
  // Support of {t : e_k·t <= t_max} in direction d, by an LP over the rows alone (independent of
  // how they were built): never more than t_max (inside the ball), t_max along ±n (pure in-plane
  // bending reaches the limit), and at least (1 - gap) t_max (gap <= 3%).
  const double t_max = 1.77;
  auto support = [&](const TorquePolytope& poly, const Vec3& d) {
    detail::LinearProgram lp;
    lp.maximise = true;
    lp.obj = {d.x(), d.y(), d.z()};
    lp.col_lo.assign(3, -std::numeric_limits<double>::infinity());
    lp.col_hi.assign(3, std::numeric_limits<double>::infinity());
    for (std::size_t k = 0; k < poly.rows.size(); ++k) {
      for (int i = 0; i < 3; ++i) {
        lp.tri_row.push_back(static_cast<int>(k));
        lp.tri_col.push_back(i);
        lp.tri_val.push_back(poly.rows[k](i));
      }
      lp.row_lo.push_back(-std::numeric_limits<double>::infinity());
      lp.row_hi.push_back(t_max);
    }
    const detail::LpSolution sol = detail::solve_lp(lp);
    REQUIRE(sol.status == detail::LpSolution::optimal);
    return sol.objective;
  };
  const TorquePolytope& poly = torque_polytope(TorqueBound::full_3d);
  CHECK(poly.rows.size() == 180);
  CHECK(poly.gap <= 0.03);
  CHECK(poly.gap >= 0.02);
  CHECK(support(poly, Vec3(1, 0, 0)) == Approx(t_max).epsilon(1e-12));
  CHECK(support(poly, Vec3(-1, 0, 0)) == Approx(t_max).epsilon(1e-12));
  std::mt19937 rng(5);
  std::normal_distribution<double> normal;
  double lowest = 1.0, highest = 0.0;
  for (int i = 0; i < 2000; ++i) {
    const Vec3 d = Vec3(normal(rng), normal(rng), normal(rng)).normalized();
    const double h = support(poly, d) / t_max;
    lowest = std::min(lowest, h);
    highest = std::max(highest, h);
  }
  CHECK(highest <= 1 + 1e-12);
  CHECK(lowest >= 1 - poly.gap - 1e-12);
  CHECK(lowest < 1 - 0.5 * poly.gap);  // the gap is real: some direction falls short of the ball
  // The lazy loop (rows added as solutions violate them) reaches the same support from a box
  // much larger than the ball, with a torque that is an affine map of the columns.
  Eigen::Matrix3d A;
  A << 0.5, 0.2, 0.0, -0.1, 1.0, 0.3, 0.0, 0.4, 2.0;
  const Vec3 c0(0.1, -0.2, 0.05);
  detail::TorqueBlocks blocks{A, c0};
  for (int i = 0; i < 50; ++i) {
    const Vec3 d = Vec3(normal(rng), normal(rng), normal(rng)).normalized();
    detail::LinearProgram lp;
    const Vec3 obj = A.transpose() * d;  // maximise d·t(x)
    lp.obj = {obj.x(), obj.y(), obj.z()};
    lp.col_lo.assign(3, -100.0);
    lp.col_hi.assign(3, 100.0);
    std::set<std::pair<int, int>> added;
    int rounds = 0;
    const detail::LpSolution sol = detail::solve_lp_with_torque_rows(lp, blocks, poly, t_max, added, &rounds);
    REQUIRE(sol.status == detail::LpSolution::optimal);
    CHECK(sol.objective + d.dot(c0) == Approx(support(poly, d)).epsilon(1e-9));
    CHECK(rounds >= 2);
    CHECK(added.size() < 60);  // a few of the 180 rows
  }
  // Finer polytopes close the gap; every facet's neighbours share a vertex with it.
  CHECK(geodesic_polytope(4).gap < poly.gap);
  CHECK(geodesic_polytope(4).rows.size() == 320);
  // The slab of in_plane: only ±n, not inside the ball.
  const TorquePolytope& slab = torque_polytope(TorqueBound::in_plane);
  CHECK(slab.rows.size() == 2);
  CHECK(torque_gauge(slab, Vec3(0.5, 10.0, 10.0), 1.0) == Approx(0.5));
  CHECK(torque_gauge(poly, Vec3(0.5, 10.0, 10.0), 1.0) > 14.0);
  CHECK_THROWS_WITH(parse_torque_bound("2d", "settings: torque_bound"), Contains("settings: torque_bound"));
  CHECK(parse_torque_bound("in_plane", "k") == TorqueBound::in_plane);
  CHECK(parse_torque_bound(torque_bound_name(TorqueBound::full_3d), "k") == TorqueBound::full_3d);
}

TEST_CASE("forces: the 3D bound holds every 3D torque, which in_plane leaves above t_max", "[forces][torque]") {
  // The symmetric three-circle sphere: with in_plane the forces leave the planes and the 3D
  // torque exceeds t_max (docs/method-forces.md §9.4); with the 3D bound every 3D torque, summed
  // directly, is at most t_max, the optimum differs and G_stb can only be lower (the polytope
  // lies inside the slab).
  const Sphere s = hooked_sphere();
  const auto cuts = symmetric_cuts(s.net);
  ForceOptions o;
  o.torque_bound = TorqueBound::in_plane;
  const ForceResult flat = optimize_forces(s.net, s.hooks, s.steps, cuts, o);
  o.torque_bound = TorqueBound::full_3d;
  const ForceResult full = optimize_forces(s.net, s.hooks, s.steps, cuts, o);
  double flat_3d = 0.0, full_3d = 0.0, full_in = 0.0;
  for (int w = 0; w < 3; ++w) {
    flat_3d = std::max(flat_3d, fixtures::max_torque_3d(s.net.wires[w], cuts[w], wire_loads(s.net, s.hooks, flat.forces, w)));
    full_3d = std::max(full_3d, fixtures::max_torque_3d(s.net.wires[w], cuts[w], wire_loads(s.net, s.hooks, full.forces, w)));
    full_in = std::max(full_in, full.wires[w].max_torque);
  }
  CHECK(flat_3d > 1.05 * flat.t_max);
  CHECK(full_3d <= full.t_max * (1 + 1e-7));
  CHECK(full_3d >= full.t_max * (1 - torque_polytope(TorqueBound::full_3d).gap));
  CHECK(full_in <= full.t_max * (1 + 1e-7));
  CHECK(full.torque_active);
  CHECK(full.g_stb <= flat.g_stb);
  CHECK(full.g_stb < 0.99 * flat.g_stb);
  CHECK(full.warnings.empty());
  CHECK_FALSE(flat.warnings.empty());
  CHECK(full.equilibrium_residual < 1e-9);
}

TEST_CASE("forces: on random networks every 3D torque stays within t_max", "[forces][torque]") {
  std::mt19937 rng(23);
  int tested = 0;
  for (int attempt = 0; attempt < 300 && tested < 15; ++attempt) {
    fixtures::HookedNetwork h;
    if (!fixtures::random_hooked_sphere(rng, attempt, 40, h)) continue;
    ForceOptions o;
    o.torque_fraction = attempt % 2 ? 1.0 : 0.4;
    o.algorithm = attempt % 3 == 0 ? ForceAlgorithm::lp : ForceAlgorithm::lp_then_slsqp;
    const auto cuts = choose_cuts(h.net);
    ForceResult r;
    try {
      r = optimize_forces(h.net, h.hooks, h.steps, cuts, o);
    } catch (const SolverError&) {
      continue;
    }
    ++tested;
    INFO("attempt " << attempt);
    double worst = 0.0;
    for (int w = 0; w < static_cast<int>(h.net.wires.size()); ++w) {
      const double t = fixtures::max_torque_3d(h.net.wires[w], cuts[w], wire_loads(h.net, h.hooks, r.forces, w));
      CHECK(t <= r.t_max * (1 + 1e-7));
      CHECK(r.wires[w].max_torque_3d == Approx(t).epsilon(1e-9).margin(1e-12));
      worst = std::max(worst, t);
    }
    if (worst > 0) CHECK(r.torque_active);
    CHECK(r.equilibrium_residual < 1e-9);
    CHECK(r.coefficients.minCoeff() >= 0.0);
  }
  CHECK(tested >= 10);
}

TEST_CASE("forces: warm-started cutting planes reach the rebuilt LP optima on random networks", "[forces][torque][warm]") {
  // The force LP and the least-out-of-plane LP after it, each a cutting-plane loop over the 3D
  // polytope's rows (the second starts from the first's basis): re-solving the problem GLPK holds
  // from its last basis must give the optimum that rebuilding every round gives (relative 1e-7),
  // with every 3D torque within t_max.
  std::mt19937 rng(41);
  int tested = 0;
  for (int attempt = 0; attempt < 300 && tested < 10; ++attempt) {
    fixtures::HookedNetwork h;
    if (!fixtures::random_hooked_sphere(rng, attempt, 32, h)) continue;
    ForceOptions o;
    o.torque_fraction = attempt % 2 ? 1.0 : 0.4;
    o.algorithm = ForceAlgorithm::lp;
    o.least_out_of_plane = attempt % 3 != 0;
    const auto cuts = choose_cuts(h.net);
    ForceResult warm, cold;
    ForceOptions rebuilt = o;
    rebuilt.lp_warm_start = false;
    try {
      cold = optimize_forces(h.net, h.hooks, h.steps, cuts, rebuilt);
    } catch (const SolverError&) {
      CHECK_THROWS_AS(optimize_forces(h.net, h.hooks, h.steps, cuts, o), SolverError);
      continue;
    }
    warm = optimize_forces(h.net, h.hooks, h.steps, cuts, o);
    ++tested;
    INFO("attempt " << attempt);
    if (o.least_out_of_plane) {
      // The second LP's optimum is its objective, the least Σ_c Σ_w |f_c · n_w| (summed here from
      // the forces), with G_stb kept within tie_tolerance of the first LP's optimum (which of the
      // G_stb values in that band it returns is not unique).
      auto out_of_plane = [&](const ForceResult& f) {
        double sum = 0.0, scale = 0.0;
        for (std::size_t c = 0; c < h.net.crossings.size(); ++c) {
          for (int w : h.net.crossings[c].wires) sum += std::abs(f.forces[c].dot(h.net.wires[w].plane.normal));
          scale += f.forces[c].norm();
        }
        return std::pair{sum, scale};
      };
      const auto [warm_sum, scale] = out_of_plane(warm);
      CHECK(warm_sum == Approx(out_of_plane(cold).first).epsilon(1e-7).margin(1e-9 * scale));
      ForceOptions first = o;
      first.least_out_of_plane = false;
      const double best = optimize_forces(h.net, h.hooks, h.steps, cuts, first).g_stb;
      CHECK(warm.g_stb >= (1 - o.tie_tolerance) * best * (1 - 1e-9));
    } else {
      CHECK(warm.g_stb == Approx(cold.g_stb).epsilon(1e-7).margin(1e-12));
    }
    for (int w = 0; w < static_cast<int>(h.net.wires.size()); ++w)
      CHECK(fixtures::max_torque_3d(h.net.wires[w], cuts[w], wire_loads(h.net, h.hooks, warm.forces, w)) <=
            warm.t_max * (1 + 1e-7));
    CHECK(warm.equilibrium_residual < 1e-9);
  }
  CHECK(tested >= 8);
}

TEST_CASE("forces: out-of-plane shares are per wire, in that wire's own plane", "[forces][share]") {
  // Two wires in perpendicular planes (normals z and x) crossing at the origin on their common
  // line d = z × x = y. Only the planes and the crossing matter for the shares.
  Network net;
  WireSpec a, b;
  a.name = "A";
  a.plane = Plane::make(Vec3::Zero(), Vec3::UnitZ());
  a.points = {Vec3(-0.1, 0, 0), Vec3(0, 0, 0), Vec3(0.1, 0, 0)};
  b.name = "B";
  b.plane = Plane::make(Vec3::Zero(), Vec3::UnitX());
  b.points = {Vec3(0, 0, -0.1), Vec3(0, 0, 0), Vec3(0, 0, 0.1)};
  net.wires = {a, b};
  Crossing x;
  x.wires = {0, 1};
  x.vertices = {1, 1};
  net.crossings = {x};
  const std::vector<int> hook{1};
  auto shares = [&](const Vec3& f) { return out_of_plane_shares(net, hook, {f}); };
  // Along the common line: in both planes.
  OutOfPlaneShares s = shares(Vec3(0, -3.0, 0));
  CHECK(s.share[0][0] == 0.0);
  CHECK(s.share[0][1] == 0.0);
  // Along A's normal: wholly out of A's plane, wholly in B's.
  s = shares(Vec3(0, 0, 2.0));
  CHECK(s.share[0][0] == Approx(1.0));
  CHECK(s.share[0][1] == 0.0);
  // Along B's normal: the other way round.
  s = shares(Vec3(-2.0, 0, 0));
  CHECK(s.share[0][0] == 0.0);
  CHECK(s.share[0][1] == Approx(1.0));
  CHECK(s.mean == Approx(0.5));
  CHECK(s.max == Approx(1.0));
  // Half way between d and A's normal: sin 45° out of A's plane, none out of B's.
  s = shares(Vec3(0, 1.0, 1.0));
  CHECK(s.share[0][0] == Approx(std::sqrt(0.5)));
  CHECK(s.share[0][1] == Approx(0.0).margin(1e-15));
  // B's plane turned: normal (cos 60°, 0, sin 60°). A force along A's normal z is sin 60° out of
  // B's plane (and still wholly out of A's).
  net.wires[1].plane = Plane::make(Vec3::Zero(), Vec3(std::cos(std::numbers::pi / 3), 0, std::sin(std::numbers::pi / 3)));
  s = shares(Vec3(0, 0, 5.0));
  CHECK(s.share[0][0] == Approx(1.0));
  CHECK(s.share[0][1] == Approx(std::sin(std::numbers::pi / 3)));
  // Null crossings and zero forces are left out.
  CHECK(out_of_plane_shares(net, {0}, {Vec3(0, 0, 5.0)}).max == 0.0);
  CHECK(shares(Vec3::Zero()).mean == 0.0);
  CHECK_THROWS_AS(out_of_plane_shares(net, {1, 1}, {Vec3::Zero()}), InputError);
}

TEST_CASE("forces: the paper's normalisation divides by the structure's largest force", "[forces][share]") {
  Network net;
  WireSpec a, b, c;
  a.plane = Plane::make(Vec3::Zero(), Vec3::UnitZ());
  b.plane = Plane::make(Vec3::Zero(), Vec3::UnitX());
  c.plane = Plane::make(Vec3::Zero(), Vec3::UnitY());
  net.wires = {a, b, c};
  Crossing x01, x02;
  x01.wires = {0, 1};
  x02.wires = {0, 2};
  net.crossings = {x01, x02};
  // Crossing 0: 4 N along d = y (in both planes); crossing 1: 1 N along z (A's normal, in C's
  // plane). Shares per force: {0, 0} and {1, 0}; over the largest force 4 N: {0, 0}, {1/4, 0}.
  const OutOfPlaneShares s = out_of_plane_shares(net, {1, -1}, {Vec3(0, 4.0, 0), Vec3(0, 0, 1.0)});
  CHECK(s.mean == Approx(0.25));
  CHECK(s.max == Approx(1.0));
  CHECK(s.mean_to_max_force == Approx(0.25 / 4));
  CHECK(s.max_to_max_force == Approx(0.25));
}

TEST_CASE("forces: with pinch-or-spread hooks the optimum carries at least the in-plane forces", "[forces][share]") {
  // Ellipse hooks: each ring can carry alternating radial forces +-F at its four crossings,
  // which lie in both planes (along d). Walked from a cut half way between two crossings, the
  // in-plane moment of such a ring peaks at F·R (at a crossing: F times the distance R from the
  // previous crossing's radial line of action), so radial forces F = t_max / R are feasible up to
  // the kinked neighbours, which lie a little off the circle. The optimum must carry at least
  // that; it need not be radial (docs/method-forces.md: Eq. 6-7 do not prefer in-plane forces),
  // so where it is not, the in-plane torque is exceeded in 3D and a warning says so.
  const Sphere s = hooked_sphere(2.0 * std::numbers::pi / 3.0, Hooks::ellipse);
  const ForceOptions o;
  const ForceResult r = lp_optimum(s, o);
  const double R = 0.125;
  double sum = 0.0;
  for (double nk : r.normal) sum += nk;
  CHECK(sum >= 0.95 * 6 * o.max_torque / R);
  bool above = false;
  for (const WireTorque& w : r.wires) {
    CHECK(w.max_torque <= r.t_max * (1 + 1e-7));
    above = above || w.max_torque_3d > r.t_max * (1 + 1e-6);
  }
  CHECK(above == !r.warnings.empty());
  if (above) CHECK_THAT(r.warnings.front(), Contains("twist together reach"));
}

TEST_CASE("forces: reported shares and 3D torques agree with a direct computation", "[forces][share]") {
  const Sphere s = hooked_sphere();
  const auto cuts = symmetric_cuts(s.net);
  const ForceResult r = lp_optimum(s, {});
  // Shares recomputed here from the forces and the plane normals.
  double worst = 0.0;
  for (int c = 0; c < 6; ++c)
    for (int k = 0; k < 2; ++k) {
      const double share = std::abs(r.forces[c].dot(s.net.wires[s.net.crossings[c].wires[k]].plane.normal)) /
                           r.forces[c].norm();
      CHECK(r.out_of_plane[c][k] == Approx(share).margin(1e-12));
      worst = std::max(worst, share);
    }
  CHECK(r.max_out_of_plane == Approx(worst));
  // The 3D torque, summed directly: walk each wire from its cut; at every position v the torque
  // of the loads after it, |Σ (x_v - x_k) × f_k|.
  for (int w = 0; w < 3; ++w) {
    const auto& pts = s.net.wires[w].points;
    const int n = static_cast<int>(pts.size());
    const auto loads = wire_loads(s.net, s.hooks, r.forces, w);
    double largest = 0.0;
    for (int pv = 0; pv < n; ++pv) {
      const int v = (cuts[w] + pv) % n;
      Vec3 t = Vec3::Zero();
      for (const WireLoad& l : loads)
        if ((l.vertex - cuts[w] + n) % n > pv) t += (pts[v] - pts[l.vertex]).cross(l.force);
      largest = std::max(largest, t.norm());
    }
    CHECK(r.wires[w].max_torque_3d == Approx(largest).epsilon(1e-9));
    CHECK(r.wires[w].max_torque_3d >= r.wires[w].max_torque * (1 - 1e-12));
  }
}

TEST_CASE("forces: least out of plane keeps G_stb within its tolerance and lowers the out-of-plane parts", "[forces][share]") {
  std::mt19937 rng(47);
  int tested = 0;
  for (int attempt = 0; attempt < 200 && tested < 4; ++attempt) {
    fixtures::HookedNetwork h;
    if (!fixtures::random_hooked_sphere(rng, attempt, 24, h)) continue;
    const std::vector<int> cuts = choose_cuts(h.net, std::vector<int>(h.net.wires.size(), -1));
    ForceOptions o;
    o.algorithm = ForceAlgorithm::lp;
    ForceResult plain;
    try {
      plain = optimize_forces(h.net, h.hooks, h.steps, cuts, o);
    } catch (const SolverError&) {
      continue;
    }
    ++tested;
    INFO("attempt " << attempt);
    o.algorithm = ForceAlgorithm::lp_then_slsqp;  // the second LP's result is final
    o.least_out_of_plane = true;
    const ForceResult least = optimize_forces(h.net, h.hooks, h.steps, cuts, o);
    CHECK(least.method == "lp+least_out_of_plane");
    // Σ_k Σ_w |f_k · n_w|, summed here from the forces and the plane normals.
    auto out_of_plane = [&](const ForceResult& r) {
      double sum = 0.0;
      for (std::size_t c = 0; c < h.net.crossings.size(); ++c)
        for (int w : h.net.crossings[c].wires) sum += std::abs(r.forces[c].dot(h.net.wires[w].plane.normal));
      return sum;
    };
    CHECK(least.g_stb >= (1 - o.tie_tolerance) * plain.g_stb * (1 - 1e-9));
    CHECK(out_of_plane(least) <= out_of_plane(plain) + 1e-9 * plain.g_stb);
    CHECK(least.equilibrium_residual < 1e-9);
    for (const WireTorque& w : least.wires) CHECK(w.max_torque_3d <= least.t_max * (1 + 1e-7));
    // A zero tolerance keeps the optimum itself.
    o.tie_tolerance = 0.0;
    const ForceResult tight = optimize_forces(h.net, h.hooks, h.steps, cuts, o);
    CHECK(tight.g_stb == Approx(plain.g_stb).epsilon(1e-7));
    CHECK(out_of_plane(tight) <= out_of_plane(plain) + 1e-9 * plain.g_stb);
  }
  CHECK(tested >= 2);
}
