// Cancellation of the long native steps: the network, the assembly check, the force LP and the
// load-capacity LPs. A counting progress callback that asks to stop at its k-th call must make
// the step throw Cancelled at that very call (never called again: nothing more than one step of
// work runs after the request), for every k the step reaches; the polls come at least once per
// pair of wires / assembly step / LP; and a full run after all those cancellations gives exactly
// the result of a full run before them (no state is left behind, e.g. in GLPK's environment).
#include <catch2/catch.hpp>
#include <string>
#include <vector>

#include "wire_fixtures.hpp"
#include "wiresculpt/error.hpp"
#include "wiresculpt/forces.hpp"
#include "wiresculpt/layering.hpp"
#include "wiresculpt/load_capacity.hpp"
#include "wiresculpt/network.hpp"

using namespace wiresculpt;

namespace {

// Counts its calls; returns false (cancel) at call `stop_at` (1-based; 0: never).
struct CountingProgress {
  explicit CountingProgress(int stop = 0) : stop_at(stop) {}
  int stop_at;
  int calls = 0;
  std::vector<std::string> stages;
  bool in_range = true;  // every fraction in [0, 1]

  ProgressFn fn() {
    return [this](std::string_view stage, double fraction) {
      ++calls;
      if (stages.empty() || stages.back() != stage) stages.emplace_back(stage);
      in_range = in_range && fraction >= 0.0 && fraction <= 1.0;
      return stop_at == 0 || calls < stop_at;
    };
  }
};

// Runs `run(progress)` once to the end, then cancelled at each of its calls in turn. Returns
// the number of calls of the full run.
template <class Run>
int cancel_at_every_call(Run run) {
  CountingProgress full;
  run(full.fn());
  CHECK(full.in_range);
  for (int k = 1; k <= full.calls; ++k) {
    INFO("cancelled at call " << k << " of " << full.calls);
    CountingProgress c(k);
    CHECK_THROWS_AS(run(c.fn()), Cancelled);
    CHECK(c.calls == k);
  }
  return full.calls;
}

// Four circles of one sphere (radius 0.125 m): the three great circles of the axes and a fourth
// whose plane x + y + z = 0 meets each of them twice away from the others' crossings.
std::vector<WireSpec> four_circles() {
  auto cuts = fixtures::great_circle_cuts();
  cuts.push_back({"W", Vec3(1, 1, 1).normalized(), 0.0});
  return fixtures::sphere_wires(cuts, 0.125, 48);
}

}  // namespace

TEST_CASE("cancel: build_network polls per wire and per pair of wires", "[cancel]") {
  const std::vector<WireSpec> wires = four_circles();
  const Network before = build_network(wires);
  const int calls = cancel_at_every_call([&](const ProgressFn& p) { build_network(wires, {}, p); });
  // 4 wires cleaned, 6 pairs met, 4 wires with crossings inserted, and the end.
  CHECK(calls == 4 + 6 + 4 + 1);
  const Network after = build_network(wires);
  REQUIRE(after.crossings.size() == before.crossings.size());
  CHECK(after.crossings.size() == 12);
  for (std::size_t c = 0; c < after.crossings.size(); ++c) {
    CHECK(after.crossings[c].point == before.crossings[c].point);
    CHECK(after.crossings[c].vertices == before.crossings[c].vertices);
  }
}

TEST_CASE("cancel: check_assembly polls once per assembly step", "[cancel]") {
  const Network net = build_network(four_circles());
  const LayeringResult lay = layering(net);
  REQUIRE(lay.stable);
  REQUIRE(lay.steps.size() == 3);  // the first pair, then one wire at a time
  const AssemblyCheck before = check_assembly(net, lay.hooks, lay.steps);
  CHECK(before.stable);
  CountingProgress stages;
  check_assembly(net, lay.hooks, lay.steps, {}, stages.fn());
  CHECK(stages.stages == std::vector<std::string>{"check_assembly"});
  const int calls = cancel_at_every_call([&](const ProgressFn& p) { check_assembly(net, lay.hooks, lay.steps, {}, p); });
  CHECK(calls == 3 + 1);
  const AssemblyCheck after = check_assembly(net, lay.hooks, lay.steps);
  CHECK(after.stable);
  CHECK(after.lp_solves == before.lp_solves);

  // A failing prefix stops at that step: with every hook null nothing holds the first pair.
  const AssemblyCheck none = check_assembly(net, std::vector<int>(net.crossings.size(), 0), lay.steps);
  CHECK_FALSE(none.stable);
  CHECK(none.failed_step == 0);
  CHECK_THROWS_AS(check_assembly(net, {1, -1}, lay.steps), InputError);
}

TEST_CASE("cancel: the force LP and the load-capacity LPs", "[cancel]") {
  const Network net = build_network(four_circles());
  const LayeringResult lay = layering(net);
  REQUIRE(lay.stable);
  const std::vector<int> cuts = choose_cuts(net);
  ForceOptions lp_only;
  lp_only.algorithm = ForceAlgorithm::lp;
  const ForceResult before = optimize_forces(net, lay.hooks, lay.steps, cuts, lp_only);

  SECTION("optimize_forces (LP): before and after the LP and once per wire") {
    const int calls = cancel_at_every_call(
        [&](const ProgressFn& p) { optimize_forces(net, lay.hooks, lay.steps, cuts, lp_only, p); });
    CHECK(calls == 3 + 4 + 1);  // 0, 0.5 (after the LP), 0.9, one per wire, 1
    const ForceResult after = optimize_forces(net, lay.hooks, lay.steps, cuts, lp_only);
    CHECK(after.coefficients == before.coefficients);
  }
  SECTION("load_capacity: once per direction's LP") {
    const ForceProblem problem(net, lay.hooks, lay.steps, cuts, lp_only);
    const LoadCapacityResult full = load_capacity(net, cuts, problem, before.coefficients);
    CountingProgress stages;
    load_capacity(net, cuts, problem, before.coefficients, {}, stages.fn());
    CHECK(stages.stages == std::vector<std::string>{"load_capacity"});
    // On one thread: once before each direction and at the end. (On two, the calling thread
    // reports before direction 0, before each other direction it takes, and at the end: the
    // count depends on the threads' timing; test_load_capacity.cpp cancels those runs.)
    LoadCapacityOptions serial;
    serial.threads = 1;
    const int calls = cancel_at_every_call(
        [&](const ProgressFn& p) { load_capacity(net, cuts, problem, before.coefficients, serial, p); });
    CHECK(calls == 6 + 1);
    const LoadCapacityResult after = load_capacity(net, cuts, problem, before.coefficients);
    REQUIRE(after.directions.size() == 6);
    for (int d = 0; d < 6; ++d) {
      CHECK(after.directions[d].status == full.directions[d].status);
      CHECK(after.directions[d].multiple == full.directions[d].multiple);
    }
  }
  SECTION("optimize_forces (LP then SLSQP): cancelled at its first and at its last poll") {
    CountingProgress full;
    optimize_forces(net, lay.hooks, lay.steps, cuts, {}, full.fn());
    for (int k : {1, 2, full.calls}) {
      CountingProgress c(k);
      CHECK_THROWS_AS(optimize_forces(net, lay.hooks, lay.steps, cuts, {}, c.fn()), Cancelled);
      CHECK(c.calls == k);
    }
  }
}
