// The forces the assembled structure carries (carried_forces.hpp) and the linear tie response
// under them (structure3d_tie_response): against statics worked out by hand, symmetry, the exact
// identity of a force in both planes, and the nonlinear 3D check (solve_structure3d) of the
// rest shapes the forces stage makes.
#include <catch2/catch.hpp>
#include <random>
#include <vector>

#include "structure3d_fixtures.hpp"
#include "wire_fixtures.hpp"
#include "wiresculpt/carried_forces.hpp"
#include "wiresculpt/error.hpp"
#include "wiresculpt/forces_and_rest.hpp"
#include "wiresculpt/network.hpp"
#include "wiresculpt/structure3d.hpp"

using namespace wiresculpt;
using fixtures::straight;
using fixtures::weightless;

TEST_CASE("tie response: a rod between a tie and a pin passes half its middle load", "[carried]") {
  // A cantilever A along x (clamped at its root) and a straight rod B along y from A's tip (tied
  // there) to a pin: a load P at B's middle node reaches the tie and the pin by halves, B's free
  // body alone says so (moments about the pin), whatever the stiffness.
  Structure3dInput in;
  in.wires = {straight("A", Vec3::Zero(), Vec3(0.02, 0, 0), 9), straight("B", Vec3(0.16, 0, 0), Vec3(0, 0.02, 0), 7)};
  in.ties.push_back({{0, 8}, {1, 0}, Vec3::Zero()});
  in.clamps.push_back({0, 0});
  in.pins.push_back({1, 6});
  const Vec3 P(0.0, 0.0, -0.3);
  const std::vector<std::vector<Vec3>> r = structure3d_tie_response(in, {{{{1, 3}, P}}}, weightless());
  REQUIRE(r.size() == 1);
  INFO("tie " << r[0][0].transpose());
  // B may spin about its own axis freely (point supports hold no twist): factor_positive's
  // smallest shift holds that mode, and costs a few 1e-5 of the answer.
  CHECK((r[0][0] - 0.5 * P).norm() < 1e-3 * P.norm());
}

TEST_CASE("tie response: two equal cantilevers tied at their tips share a tip load", "[carried]") {
  // Two equal parallel cantilevers, both clamped, their tips tied: a load P on A's tip bends
  // both alike (symmetry), so B takes half: the tie pulls A's tip back by -P/2.
  Structure3dInput in;
  in.wires = {straight("A", Vec3::Zero(), Vec3(0.02, 0, 0), 11), straight("B", Vec3(0, 0.01, 0), Vec3(0.02, 0, 0), 11)};
  in.ties.push_back({{0, 10}, {1, 10}, Vec3(0.0, -0.01, 0.0)});
  in.clamps = {{0, 0}, {1, 0}};
  for (const Vec3& P : {Vec3(0, 0, -0.2), Vec3(0, 0.1, 0)}) {
    const std::vector<std::vector<Vec3>> r = structure3d_tie_response(in, {{{{0, 10}, P}}}, weightless());
    INFO("load " << P.transpose() << ": tie " << r[0][0].transpose());
    CHECK((r[0][0] + 0.5 * P).norm() < 1e-6 * P.norm());
    // The nonlinear solve under a small share of it agrees.
    Structure3dInput loaded = in;
    loaded.loads = {{{0, 10}, 1e-3 * P}};
    const Structure3dResult nl = solve_structure3d(loaded, weightless());
    REQUIRE(nl.converged);
    CHECK((nl.tie_forces[0] - 1e-3 * r[0][0]).norm() < 1e-3 * 1e-3 * P.norm());
  }
  // A node that is not one: one InputError naming it.
  CHECK_THROWS_AS(structure3d_tie_response(in, {{{{0, 11}, Vec3::UnitZ()}}}, weightless()), InputError);
}

TEST_CASE("carried forces: a force in both wires' planes is carried as it is", "[carried]") {
  // Along the planes' common line d a design force lies in both planes: the rest shapes load
  // each wire with all of it, the tie takes it with nothing deforming, and every other crossing
  // carries nothing more. So R's block column of crossing c maps d_c onto d_c at c alone.
  std::mt19937 rng(61);
  int tested = 0;
  for (int attempt = 0; attempt < 40 && tested < 4; ++attempt) {
    fixtures::HookedNetwork h;
    if (!fixtures::random_hooked_sphere(rng, attempt, 24, h)) continue;
    std::vector<int> cuts;
    try {
      cuts = choose_cuts(h.net, std::vector<int>(h.net.wires.size(), -1));
    } catch (const InputError&) {
      continue;
    }
    CarriedForces cf;
    try {
      cf = carried_forces(h.net, h.hooks, cuts);
    } catch (const SolverError&) {
      continue;  // a wire held at too few crossings turns freely: no stiffness to answer with
    }
    ++tested;
    const int H = static_cast<int>(h.net.crossings.size());
    REQUIRE(cf.R.rows() == 3 * H);
    for (int c = 0; c < H; ++c) {
      const Crossing& x = h.net.crossings[c];
      const Vec3 d = h.net.wires[x.wires[0]].plane.normal.cross(h.net.wires[x.wires[1]].plane.normal).normalized();
      const Eigen::VectorXd carried = cf.R.middleCols<3>(3 * c) * d;
      Eigen::VectorXd expected = Eigen::VectorXd::Zero(3 * H);
      expected.segment<3>(3 * c) = d;
      INFO("attempt " << attempt << ", crossing " << c);
      CHECK((carried - expected).norm() < 1e-6);
    }
    CHECK(cf.weight.norm() == 0.0);  // no density given
  }
  CHECK(tested >= 3);
}

TEST_CASE("carried forces: the forces stage's carried forces are the nonlinear 3D check's", "[carried]") {
  // The forces stage with carried_3d, then its rest shapes assembled and solved in 3D by Newton
  // (pre-stress alone, one node clamped): the ties carry what the linear map predicted, within
  // 2 % of the largest force, and where the rows held every such force lies in its pyramid.
  std::mt19937 rng(67);
  int tested = 0, held = 0;
  for (int attempt = 0; attempt < 60 && tested < 4; ++attempt) {
    fixtures::HookedNetwork h;
    if (!fixtures::random_hooked_sphere(rng, attempt, 32, h)) continue;
    ForcesAndRestOptions o;
    o.forces.carried_3d = true;
    o.forces.carried_margin = 0.0, o.forces.carried_share = 0.0;  // the pyramids themselves
    ForcesAndRestResult r;
    try {
      r = forces_and_rest(h.net, h.hooks, h.steps, std::vector<int>(h.net.wires.size(), -1), o);
    } catch (const Error&) {
      continue;
    }
    if (r.forces.carried_forces.empty() || r.forces.g_stb <= 0) continue;
    Structure3dInput in;
    std::vector<std::vector<int>> position(h.net.wires.size());
    for (std::size_t w = 0; w < h.net.wires.size(); ++w) {
      const WireSpec& s = h.net.wires[w];
      const std::vector<int> walk = wire_walk(static_cast<int>(s.points.size()), s.closed, r.cuts[w], s.name);
      Structure3dWire wire;
      wire.name = s.name, wire.normal = s.plane.normal;
      for (int t : walk) wire.start.push_back(s.points[static_cast<std::size_t>(t)]);
      for (const Vec2& p : r.rests[w].rest) wire.rest.push_back(s.plane.origin + p.x() * s.plane.u + p.y() * s.plane.v);
      position[w].assign(s.points.size(), -1);
      for (int k = static_cast<int>(walk.size()) - 1; k >= 0; --k) position[w][static_cast<std::size_t>(walk[k])] = k;
      if (s.closed) in.ties.push_back({{static_cast<int>(w), 0}, {static_cast<int>(w), static_cast<int>(walk.size()) - 1}, Vec3::Zero()});
      in.wires.push_back(wire);
    }
    const std::size_t closures = in.ties.size();
    std::vector<int> hooked;
    for (std::size_t c = 0; c < h.net.crossings.size(); ++c) {
      if (h.hooks[c] == 0) continue;
      const Crossing& x = h.net.crossings[c];
      const NodeRef a{x.wires[0], position[x.wires[0]][x.vertices[0]]}, b{x.wires[1], position[x.wires[1]][x.vertices[1]]};
      in.ties.push_back({a, b, in.wires[a.wire].start[a.vertex] - in.wires[b.wire].start[b.vertex]});
      hooked.push_back(static_cast<int>(c));
    }
    in.clamps.push_back({0, 1});
    const Structure3dResult nl = solve_structure3d(in, weightless());
    if (!nl.converged) continue;
    ++tested;
    double largest = 0.0;
    for (int c : hooked) largest = std::max(largest, r.forces.forces[c].norm());
    for (std::size_t k = 0; k < hooked.size(); ++k) {
      const int c = hooked[k];
      INFO("attempt " << attempt << ", crossing " << c << ": carried " << r.forces.carried_forces[c].transpose()
                      << ", 3D check " << nl.tie_forces[closures + k].transpose());
      CHECK((r.forces.carried_forces[c] - nl.tie_forces[closures + k]).norm() < 0.02 * largest);
      if (r.forces.carried_3d) {
        const ForceProblem p(h.net, h.hooks, h.steps, r.cuts);
        CHECK(pyramid_fit(nl.tie_forces[closures + k], p.pyramid(c)).distance < 0.02 * largest);
      }
    }
    held += r.forces.carried_3d ? 1 : 0;
  }
  CHECK(tested >= 3);
  CHECK(held >= 1);
}
