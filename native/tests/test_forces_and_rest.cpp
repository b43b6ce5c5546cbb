// forces_and_rest: the composition of cuts, forces, rest shapes and load capacity equals the
// stages called one by one, and its summaries (closure gap, over-bends, loaded crossings) are
// those of the per-wire results.
#include <algorithm>
#include <cmath>
#include <limits>
#include <catch2/catch.hpp>
#include <random>

#include "wire_fixtures.hpp"
#include "wiresculpt/error.hpp"
#include "wiresculpt/forces_and_rest.hpp"

using namespace wiresculpt;

TEST_CASE("forces_and_rest: the same as the stages one by one", "[forces][rest]") {
  std::mt19937 rng(41);
  int tested = 0;
  for (int attempt = 0; attempt < 200 && tested < 4; ++attempt) {
    fixtures::HookedNetwork h;
    if (!fixtures::random_hooked_sphere(rng, attempt, 24, h)) continue;
    ForcesAndRestOptions o;
    o.forces.algorithm = ForceAlgorithm::lp;
    o.forces.torque_bound = attempt % 2 ? TorqueBound::in_plane : TorqueBound::full_3d;
    o.load.torque_bound = TorqueBound::full_3d;  // overridden by the forces' bound
    o.rest.max_bend = 0.05;                      // some rest bends exceed it
    o.load_capacity = tested % 2 == 0;
    std::vector<int> requested(h.net.wires.size(), -1);
    ForcesAndRestResult r;
    try {
      r = forces_and_rest(h.net, h.hooks, h.steps, requested, o);
    } catch (const SolverError&) {
      continue;
    }
    ++tested;
    INFO("attempt " << attempt);
    const std::vector<int> cuts = choose_cuts(h.net, requested);
    CHECK(r.cuts == cuts);
    const ForceResult f = optimize_forces(h.net, h.hooks, h.steps, cuts, o.forces);
    REQUIRE(r.forces.forces.size() == f.forces.size());
    for (std::size_t c = 0; c < f.forces.size(); ++c) CHECK((r.forces.forces[c] - f.forces[c]).norm() <= 1e-12);
    REQUIRE(r.rests.size() == h.net.wires.size());
    double gap = 0.0;
    int over = 0;
    for (std::size_t w = 0; w < h.net.wires.size(); ++w) {
      const int wi = static_cast<int>(w);
      const RestShapeResult one = rest_shape(h.net.wires[w], cuts[w], wire_loads(h.net, h.hooks, f.forces, wi), o.rest);
      REQUIRE(r.rests[w].rest.size() == one.rest.size());
      for (std::size_t i = 0; i < one.rest.size(); ++i) CHECK((r.rests[w].rest[i] - one.rest[i]).norm() <= 1e-12);
      if (h.net.wires[w].closed) gap = std::max(gap, one.closure_gap);
      over += static_cast<int>(one.over_bend.size());
    }
    CHECK(r.max_closure_gap == Approx(gap).margin(1e-15));
    CHECK(r.over_bend == over);
    CHECK(r.hooked_crossings == static_cast<int>(std::count_if(h.hooks.begin(), h.hooks.end(), [](int k) { return k != 0; })));
    CHECK(r.rest_seconds >= 0.0);
    CHECK(r.load_capacity.has_value() == o.load_capacity);
    if (r.load_capacity) {
      LoadCapacityOptions lo = o.load;
      lo.torque_bound = o.forces.torque_bound;
      const ForceProblem problem(h.net, h.hooks, h.steps, cuts, o.forces);
      const LoadCapacityResult lc = load_capacity(h.net, cuts, problem, f.coefficients, lo);
      REQUIRE(r.load_capacity->directions.size() == lc.directions.size());
      for (std::size_t d = 0; d < lc.directions.size(); ++d)
        CHECK(r.load_capacity->directions[d].multiple == Approx(lc.directions[d].multiple).epsilon(1e-9));
    }
  }
  CHECK(tested >= 2);
}

TEST_CASE("forces_and_rest: bad input is an input error naming the crossing", "[forces][rest]") {
  Network net = build_network(fixtures::sphere_wires(fixtures::great_circle_cuts(), 0.1, 32));
  std::vector<int> hooks(net.crossings.size(), 1);
  hooks[2] = 3;
  CHECK_THROWS_AS(forces_and_rest(net, hooks, {}, {}), InputError);
  CHECK_THROWS_WITH(forces_and_rest(net, hooks, {}, {}), Catch::Matchers::Contains("crossing 2"));
}

namespace {
// The smallest of the six load multiples of `net` at torque fraction `f`, solved on its own:
// the forces at f, then the load capacity LP (nothing of the load factor's choice is used).
double weakest_multiple(const fixtures::HookedNetwork& h, const std::vector<int>& cuts, ForcesAndRestOptions o, double f) {
  o.forces.torque_fraction = f;
  const ForceResult forces = optimize_forces(h.net, h.hooks, h.steps, cuts, o.forces);
  LoadCapacityOptions lo = o.load;
  lo.torque_bound = o.forces.torque_bound;
  const ForceProblem problem(h.net, h.hooks, h.steps, cuts, o.forces);
  const LoadCapacityResult lc = load_capacity(h.net, cuts, problem, forces.coefficients, lo);
  double m = std::numeric_limits<double>::infinity();
  for (const LoadDirection& d : lc.directions) m = std::min(m, d.multiple);
  return m;
}
// Calls body(h, requested, cuts, o, at_one) on the first three random hooked spheres (seed `seed`)
// whose weakest load multiple at the plastic limit, at_one, is finite and at least 1e-3, with
// LP forces and the load capacity on; returns how many it called it on.
template <class Body>
int on_loaded_spheres(unsigned seed, Body body) {
  std::mt19937 rng(seed);
  int tested = 0;
  for (int attempt = 0; attempt < 200 && tested < 3; ++attempt) {
    fixtures::HookedNetwork h;
    if (!fixtures::random_hooked_sphere(rng, attempt, 24, h)) continue;
    ForcesAndRestOptions o;
    o.forces.algorithm = ForceAlgorithm::lp;
    o.load_capacity = true;
    std::vector<int> requested(h.net.wires.size(), -1);
    const std::vector<int> cuts = choose_cuts(h.net, requested);
    double at_one = 0.0;
    try {
      at_one = weakest_multiple(h, cuts, o, 1.0);
    } catch (const SolverError&) {
      continue;
    }
    if (!std::isfinite(at_one) || at_one < 1e-3) continue;
    ++tested;
    INFO("attempt " << attempt << ", weakest multiple at the plastic limit " << at_one);
    body(h, requested, cuts, o, at_one);
  }
  return tested;
}
}  // namespace

TEST_CASE("forces_and_rest: the load factor picks the least torque fraction that holds it", "[forces][load]") {
  const int tested = on_loaded_spheres(43, [](const fixtures::HookedNetwork& h, const std::vector<int>& requested,
                                              const std::vector<int>& cuts, ForcesAndRestOptions o, double at_one) {

    // Reachable: 40% of what the plastic limit holds.
    o.load_factor = 0.4 * at_one;
    const ForcesAndRestResult r = forces_and_rest(h.net, h.hooks, h.steps, requested, o);
    REQUIRE(r.load_factor.has_value());
    CHECK_FALSE(r.load_factor->limited);
    CHECK(r.torque_fraction < 1.0);
    // Met within 1%, by the design's own load capacity and by an independent solve at its fraction.
    CHECK(r.load_factor->reached == Approx(o.load_factor).epsilon(0.01));
    const double held = weakest_multiple(h, cuts, o, r.torque_fraction);
    CHECK(held >= 0.99 * o.load_factor);
    CHECK(held <= 1.01 * o.load_factor);
    // The least: 3% less pre-stress no longer holds it (a search from below, not the formula).
    CHECK(weakest_multiple(h, cuts, o, 0.97 * r.torque_fraction) < o.load_factor);
    CHECK(r.forces.t_max == Approx(o.forces.max_torque * r.torque_fraction).epsilon(1e-12));

    // Unreachable: twice what the plastic limit holds: the limit is used, the factor reached is
    // below the one asked and is what the plastic limit holds.
    o.load_factor = 2.0 * at_one;
    const ForcesAndRestResult u = forces_and_rest(h.net, h.hooks, h.steps, requested, o);
    REQUIRE(u.load_factor.has_value());
    CHECK(u.load_factor->limited);
    CHECK(u.torque_fraction == 1.0);
    CHECK(u.load_factor->reached < u.load_factor->asked);
    CHECK(u.load_factor->reached == Approx(at_one).epsilon(1e-6));

    // Monotone: a larger factor never asks for less pre-stress.
    double previous = 0.0;
    for (double share : {0.1, 0.25, 0.5, 0.75, 1.0, 1.5}) {
      o.load_factor = share * at_one;
      const double f = forces_and_rest(h.net, h.hooks, h.steps, requested, o).torque_fraction;
      CHECK(f >= previous);
      previous = f;
    }

    // The load factor needs the load capacity (a density).
    o.load_capacity = false;
    CHECK_THROWS_WITH(forces_and_rest(h.net, h.hooks, h.steps, requested, o), Catch::Matchers::Contains("load factor"));
  });
  CHECK(tested >= 2);
}

TEST_CASE("forces_and_rest: load_capacity_within skips the load capacity only beyond it", "[forces][load]") {
  std::mt19937 rng(47);
  int tested = 0;
  fixtures::HookedNetwork last;  // a network the options below are refused on
  for (int attempt = 0; attempt < 200 && tested < 2; ++attempt) {
    fixtures::HookedNetwork h;
    if (!fixtures::random_hooked_sphere(rng, attempt, 24, h)) continue;
    ForcesAndRestOptions o;
    o.forces.algorithm = ForceAlgorithm::lp;
    o.load_capacity = true;
    std::vector<int> requested(h.net.wires.size(), -1);
    ForcesAndRestResult all;
    try {
      all = forces_and_rest(h.net, h.hooks, h.steps, requested, o);
    } catch (const SolverError&) {
      continue;
    }
    REQUIRE(all.load_capacity.has_value());
    double largest = 0.0;  // the largest rest angle, read from the rest shapes
    for (const RestShapeResult& rest : all.rests)
      for (double a : rest.rest_angles) largest = std::max(largest, std::abs(a));
    if (largest <= 0.0) continue;
    ++tested;
    last = h;
    // Every rest angle within the limit: the same load capacity.
    o.load_capacity_within = largest;
    const ForcesAndRestResult within = forces_and_rest(h.net, h.hooks, h.steps, requested, o);
    REQUIRE(within.load_capacity.has_value());
    REQUIRE(within.load_capacity->directions.size() == all.load_capacity->directions.size());
    for (std::size_t d = 0; d < all.load_capacity->directions.size(); ++d)
      CHECK(within.load_capacity->directions[d].multiple == all.load_capacity->directions[d].multiple);
    // One beyond it: none, and the forces and rest shapes unchanged.
    o.load_capacity_within = 0.999 * largest;
    const ForcesAndRestResult beyond = forces_and_rest(h.net, h.hooks, h.steps, requested, o);
    CHECK_FALSE(beyond.load_capacity.has_value());
    CHECK(beyond.forces.coefficients == all.forces.coefficients);
    REQUIRE(beyond.rests.size() == all.rests.size());
    for (std::size_t w = 0; w < all.rests.size(); ++w) CHECK(beyond.rests[w].rest_angles == all.rests[w].rest_angles);
  }
  REQUIRE(tested == 2);
  const std::vector<int> requested(last.net.wires.size(), -1);
  ForcesAndRestOptions bad;
  bad.load_capacity = true;
  for (double v : {-1.0, std::numeric_limits<double>::quiet_NaN()}) {
    bad.load_capacity_within = v;
    CHECK_THROWS_WITH(forces_and_rest(last.net, last.hooks, last.steps, requested, bad),
                      Catch::Matchers::Contains("load_capacity_within"));
  }
}

TEST_CASE("forces_and_rest: the load capacity after the forces is f times the one at the plastic limit",
          "[forces][load]") {
  // With a load factor, forces_and_rest scales the plastic limit's load capacity by the torque
  // fraction f it chose instead of solving the six LPs again; here they are solved again, at f
  // with the forces' pre-stress, as load_capacity does for a design without a load factor.
  const int tested = on_loaded_spheres(53, [](const fixtures::HookedNetwork& h, const std::vector<int>& requested,
                                              const std::vector<int>&, ForcesAndRestOptions o, double at_one) {
    o.load_factor = 0.4 * at_one;  // f about 0.4
    const ForcesAndRestResult r = forces_and_rest(h.net, h.hooks, h.steps, requested, o);
    REQUIRE(r.load_capacity.has_value());
    REQUIRE(r.torque_fraction < 0.9);
    ForceOptions at_f = o.forces;
    at_f.torque_fraction = r.torque_fraction;
    LoadCapacityOptions lo = o.load;
    lo.torque_bound = o.forces.torque_bound;
    const ForceProblem problem(h.net, h.hooks, h.steps, r.cuts, at_f);
    const LoadCapacityResult solved = load_capacity(h.net, r.cuts, problem, r.forces.coefficients, lo);
    REQUIRE(solved.directions.size() == r.load_capacity->directions.size());
    for (std::size_t d = 0; d < solved.directions.size(); ++d) {
      const LoadDirection& a = r.load_capacity->directions[d];
      const LoadDirection& b = solved.directions[d];
      INFO("direction " << b.name);
      CHECK(a.status == b.status);
      CHECK(a.base == b.base);
      if (std::isfinite(b.multiple))
        CHECK(a.multiple == Approx(b.multiple).epsilon(1e-6).margin(1e-9));
      else
        CHECK(std::isinf(a.multiple));
    }
    CHECK(r.load_capacity->weight == solved.weight);
  });
  CHECK(tested == 3);
}
