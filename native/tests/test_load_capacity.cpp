// Load capacity (beyond the paper): a case whose answer is known by hand. A "gallows" wire A
// (held: its foot is lowest) whose upward V-kink at the origin hooks an inverted-V wire B that
// hangs from it. Under gravity -z, B's weight hangs straight below the contact, the contact
// pyramid contains +z, so only B's bending torque limits the load: the largest torque is at B's
// apex, the weight of one arm (W_B/2) at half the arm's horizontal reach (X/2), so
// λ = t_max / (W_B X / 4). Under +z the force B would need (-z) lies outside the pyramid: λ = 0.
#include <algorithm>
#include <catch2/catch.hpp>
#include <cmath>
#include <numbers>
#include <random>
#include <thread>

#include "wire_fixtures.hpp"

#include "wiresculpt/error.hpp"
#include "wiresculpt/load_capacity.hpp"

using namespace wiresculpt;
using Catch::Matchers::Contains;

namespace {

constexpr double a_ = 0.03, c_ = 0.04, H = 0.3, X = 0.1, Z = 0.08;

// A random hooked sphere (32 vertices) with its cuts and a feasible pre-stress at torque
// fraction 0.5; false when the attempt gives no network or the forces are infeasible.
struct Prestressed {
  fixtures::HookedNetwork h;
  std::vector<int> cuts;
  ForceOptions fo;
  ForceResult pre;
};

bool prestressed_sphere(std::mt19937& rng, int attempt, Prestressed& s) {
  if (!fixtures::random_hooked_sphere(rng, attempt, 32, s.h)) return false;
  s.cuts = choose_cuts(s.h.net);
  s.fo.torque_fraction = 0.5;
  try {
    s.pre = optimize_forces(s.h.net, s.h.hooks, s.h.steps, s.cuts, s.fo);
  } catch (const SolverError&) {
    return false;
  }
  return true;
}

// Runs test(s, problem) on random prestressed spheres drawn from `seed` until `wanted` of them
// gave a network (each within INFO "attempt k"); returns how many did.
template <class Test>
int on_prestressed_spheres(unsigned seed, int wanted, Test test) {
  std::mt19937 rng(seed);
  int tested = 0;
  for (int attempt = 0; attempt < 300 && tested < wanted; ++attempt) {
    Prestressed s;
    if (!prestressed_sphere(rng, attempt, s)) continue;
    ++tested;
    INFO("attempt " << attempt);
    const ForceProblem problem(s.h.net, s.h.hooks, s.h.steps, s.cuts, s.fo);
    test(s, problem);
  }
  return tested;
}

Network gallows() {
  WireSpec A;
  A.name = "gallows";
  A.closed = false;
  A.plane = Plane::make(Vec3::Zero(), Vec3::UnitX());
  A.points = {Vec3(0, -a_, -H), Vec3(0, -a_, -H / 2), Vec3(0, -a_, c_), Vec3(0, 0, 0), Vec3(0, a_, c_)};
  WireSpec B;
  B.name = "lambda";
  B.closed = false;
  B.plane = Plane::make(Vec3::Zero(), Vec3::UnitY());
  for (int k = 0; k <= 8; ++k) {
    const double t = (k - 4) / 4.0;  // -1 .. 1
    B.points.emplace_back(X * t, 0.0, -Z * std::abs(t));
  }
  Network net;
  net.wires = {A, B};
  Crossing x;
  x.wires = {0, 1};
  x.vertices = {3, 4};
  x.point = Vec3::Zero();
  net.crossings = {x};
  return net;
}

}  // namespace

TEST_CASE("load: a wire hanging from a held wire, torque- and pyramid-limited (by hand)", "[load]") {
  const Network net = gallows();
  const std::vector<int> hooks{1};  // d = x × y = +z; A opens +z, B opens -z
  const std::vector<std::vector<int>> steps{{0, 1}};
  const auto cuts = choose_cuts(net);
  ForceOptions fo;
  fo.torque_fraction = 0.5;
  const ForceResult pre = optimize_forces(net, hooks, steps, cuts, fo);
  // One contact cannot pre-stress anything: the pyramid is pointed.
  CHECK(pre.coefficients.norm() < 1e-12);
  const ForceProblem problem(net, hooks, steps, cuts, fo);
  LoadCapacityOptions lo;
  lo.density = 8500.0;
  const LoadCapacityResult r = load_capacity(net, cuts, problem, pre.coefficients, lo);
  const double per_metre = std::numbers::pi * 0.25 * 0.003 * 0.003 * 8500.0 * 9.81;
  const double arm = std::hypot(X, Z);
  const double length = (H / 2 + H / 2 + c_) + 2 * std::hypot(a_, c_) + 2 * arm;
  CHECK(r.length == Approx(length).epsilon(1e-12));
  CHECK(r.weight == Approx(length * per_metre).epsilon(1e-12));
  REQUIRE(r.directions.size() == 6);
  const LoadDirection& down = r.directions[5];
  CHECK(down.name == "-z");
  CHECK(down.base == std::vector<int>{0});
  CHECK(down.status == "optimal");
  const double W_B = 2 * arm * per_metre;
  CHECK(down.multiple == Approx(1.77 * 0.5 / (W_B * X / 4)).epsilon(1e-7));
  const LoadDirection& up = r.directions[4];
  CHECK(up.name == "+z");
  CHECK(up.base == std::vector<int>{0});  // A's arms reach higher than B's apex
  CHECK(up.multiple == 0.0);
  for (const LoadDirection& d : r.directions) CHECK(d.multiple >= 0.0);
  // Halving the torque limit halves the -z capacity.
  fo.torque_fraction = 0.25;
  const ForceProblem half(net, hooks, steps, cuts, fo);
  const LoadCapacityResult r2 = load_capacity(net, cuts, half, pre.coefficients, lo);
  CHECK(r2.directions[5].multiple == Approx(0.5 * down.multiple).epsilon(1e-7));
}

TEST_CASE("load: bad options and sizes are input errors", "[load]") {
  const Network net = gallows();
  const auto cuts = choose_cuts(net);
  const ForceProblem problem(net, {1}, {{0, 1}}, cuts);
  LoadCapacityOptions lo;
  lo.density = -1;
  CHECK_THROWS_WITH(load_capacity(net, cuts, problem, Eigen::VectorXd::Zero(4), lo), Contains("density"));
  CHECK_THROWS_AS(load_capacity(net, cuts, problem, Eigen::VectorXd::Zero(3)), InputError);
}

TEST_CASE("load: densities far outside any wire's are refused before GLPK (it aborted on 1e-300 and 1e200)",
          "[load][robustness]") {
  const Network net = gallows();
  const auto cuts = choose_cuts(net);
  const ForceProblem problem(net, {1}, {{0, 1}}, cuts);
  const ForceResult pre = optimize_forces(net, {1}, {{0, 1}}, cuts);
  for (double density : {1e-300, 1e200, 0.5, 1.1e5}) {
    LoadCapacityOptions lo;
    lo.density = density;
    CHECK_THROWS_WITH(load_capacity(net, cuts, problem, pre.coefficients, lo),
                      "density must be a number of kg/m^3 from 1 to 100000 (steel 7850)");
  }
  for (double density : {1.0, 1e5}) {  // the ends of the range still solve
    LoadCapacityOptions lo;
    lo.density = density;
    const LoadCapacityResult r = load_capacity(net, cuts, problem, pre.coefficients, lo);
    for (const LoadDirection& d : r.directions) CHECK(d.status != "failed");
  }
}

TEST_CASE("load: on random networks every 3D torque at the limit load stays within t_max", "[load][torque]") {
  // At each direction's limit load (the LP's contact coefficients and λ times the weight), every
  // vertex of every wire not held has |t_v| <= t_max, summed directly with each edge's weight at
  // its midpoint. The in_plane bound only limits n·t_v, so its capacities are never below the
  // 3D ones (the pre-stress does not enter: δ is free).
  const double per_metre = std::numbers::pi * 0.25 * 0.003 * 0.003 * 7850.0 * 9.81;
  int lower = 0;
  const int tested = on_prestressed_spheres(31, 10, [&](const Prestressed& s, const ForceProblem& problem) {
    const fixtures::HookedNetwork& h = s.h;
    const std::vector<int>& cuts = s.cuts;
    const ForceResult& pre = s.pre;
    LoadCapacityOptions lo;
    lo.density = 7850.0;
    const LoadCapacityResult r = load_capacity(h.net, cuts, problem, pre.coefficients, lo);
    lo.torque_bound = TorqueBound::in_plane;
    const LoadCapacityResult flat = load_capacity(h.net, cuts, problem, pre.coefficients, lo);
    for (std::size_t d = 0; d < r.directions.size(); ++d) {
      const LoadDirection& ld = r.directions[d];
      INFO("gravity " << ld.name << " " << ld.status);
      CHECK(ld.multiple <= flat.directions[d].multiple * (1 + 1e-9) + 1e-12);
      if (ld.multiple < flat.directions[d].multiple * (1 - 1e-6)) ++lower;
      if (ld.status != "optimal") continue;
      REQUIRE(ld.coefficients.size() == problem.columns());
      CHECK(ld.coefficients.minCoeff() >= -1e-12);
      const std::vector<Vec3> forces = problem.forces(ld.coefficients);
      for (int w = 0; w < static_cast<int>(h.net.wires.size()); ++w) {
        if (std::find(ld.base.begin(), ld.base.end(), w) != ld.base.end()) continue;
        const double t = fixtures::max_torque_3d(h.net.wires[w], cuts[w], wire_loads(h.net, h.hooks, forces, w),
                                                 ld.multiple * per_metre * ld.gravity);
        CHECK(t <= problem.t_max() * (1 + 1e-7));
      }
    }
  });
  CHECK(tested >= 8);
  CHECK(lower > 0);
}

TEST_CASE("load: warm-started cutting planes give the rebuilt capacities on random networks", "[load][torque][warm]") {
  // Each direction's LP is a cutting-plane loop over the 3D polytope's rows: re-solving the
  // problem GLPK holds from its last basis must give the capacity that rebuilding every round
  // gives (relative 1e-7), direction by direction.
  int finite = 0;
  const int tested = on_prestressed_spheres(37, 8, [&](const Prestressed& s, const ForceProblem& problem) {
    const fixtures::HookedNetwork& h = s.h;
    const std::vector<int>& cuts = s.cuts;
    const ForceResult& pre = s.pre;
    LoadCapacityOptions lo;
    const LoadCapacityResult warm = load_capacity(h.net, cuts, problem, pre.coefficients, lo);
    lo.lp_warm_start = false;
    const LoadCapacityResult cold = load_capacity(h.net, cuts, problem, pre.coefficients, lo);
    REQUIRE(warm.directions.size() == 6);
    for (std::size_t d = 0; d < 6; ++d) {
      INFO("gravity " << cold.directions[d].name);
      CHECK(warm.directions[d].status == cold.directions[d].status);
      CHECK(warm.directions[d].multiple == Approx(cold.directions[d].multiple).epsilon(1e-7).margin(1e-12));
      if (std::isfinite(cold.directions[d].multiple) && cold.directions[d].multiple > 0) ++finite;
    }
  });
  CHECK(tested >= 6);
  CHECK(finite >= 12);  // capacities that are neither 0 nor unbounded
}

TEST_CASE("load: one row per vertex and round gives the capacities of the loop that adds neighbour rows too",
          "[load][torque][cuts]") {
  // The load capacity adds one polytope row per vertex outside it and round (CutRows::
  // most_violated); the forces' loop adds the violated neighbour rows too. Both must reach each
  // direction's optimal λ (relative 1e-7) with the same status, the capped re-solve included;
  // the one-row loop carries fewer rows, so its rounds are at least as many.
  int finite = 0, more_rounds = 0;
  const int tested = on_prestressed_spheres(41, 8, [&](const Prestressed& s, const ForceProblem& problem) {
    LoadCapacityOptions lo;
    const LoadCapacityResult one = load_capacity(s.h.net, s.cuts, problem, s.pre.coefficients, lo);
    lo.lp_neighbour_rows = true;
    const LoadCapacityResult both = load_capacity(s.h.net, s.cuts, problem, s.pre.coefficients, lo);
    REQUIRE(one.directions.size() == 6);
    for (std::size_t d = 0; d < 6; ++d) {
      INFO("gravity " << both.directions[d].name);
      CHECK(one.directions[d].status == both.directions[d].status);
      CHECK(one.directions[d].multiple == Approx(both.directions[d].multiple).epsilon(1e-7).margin(1e-12));
      CHECK(one.directions[d].lp_rounds >= both.directions[d].lp_rounds);
      if (one.directions[d].lp_rounds > both.directions[d].lp_rounds) ++more_rounds;
      if (std::isfinite(both.directions[d].multiple) && both.directions[d].multiple > 0) ++finite;
    }
  });
  CHECK(tested >= 6);
  CHECK(finite >= 12);
  CHECK(more_rounds > 0);  // the rules did take different paths
}

TEST_CASE("load: two threads give the serial capacities direction by direction, progress only from the caller",
          "[load][threads]") {
  // The six directions' LPs are independent: solved on the calling thread and a second one they
  // must be exactly the serial ones (GLPK keeps a state per thread, docs/robustness.md), in the
  // order +x, -x, +y, -y, +z, -z; the progress callback is only ever called from the calling thread.
  const int tested = on_prestressed_spheres(43, 6, [&](const Prestressed& s, const ForceProblem& problem) {
    const fixtures::HookedNetwork& h = s.h;
    const std::vector<int>& cuts = s.cuts;
    const ForceResult& pre = s.pre;
    LoadCapacityOptions lo;
    lo.threads = 1;
    const LoadCapacityResult serial = load_capacity(h.net, cuts, problem, pre.coefficients, lo);
    lo.threads = 2;
    const std::thread::id caller = std::this_thread::get_id();
    int calls = 0, elsewhere = 0;
    const ProgressFn progress = [&](std::string_view stage, double) {
      ++calls;
      if (std::this_thread::get_id() != caller || stage != "load_capacity") ++elsewhere;
      return true;
    };
    const LoadCapacityResult two = load_capacity(h.net, cuts, problem, pre.coefficients, lo, progress);
    CHECK(calls >= 2);  // at least before direction 0 and at the end
    CHECK(elsewhere == 0);
    REQUIRE(two.directions.size() == 6);
    const char* names[6] = {"+x", "-x", "+y", "-y", "+z", "-z"};
    for (std::size_t d = 0; d < 6; ++d) {
      const LoadDirection &a = serial.directions[d], &b = two.directions[d];
      INFO("gravity " << a.name);
      CHECK(b.name == names[d]);
      CHECK(b.name == a.name);
      CHECK(b.status == a.status);
      CHECK(b.multiple == a.multiple);  // exactly
      CHECK(b.base == a.base);
      CHECK(b.lp_rounds == a.lp_rounds);
      CHECK(b.lp_iterations == a.lp_iterations);
      CHECK(b.coefficients.size() == a.coefficients.size());
      if (b.coefficients.size() == a.coefficients.size()) CHECK(b.coefficients == a.coefficients);
    }
    CHECK(two.length == serial.length);
    CHECK(two.weight == serial.weight);
  });
  CHECK(tested >= 5);
}

TEST_CASE("load: cancelling with two threads throws Cancelled on the calling thread, and threads 0 or 3 is an input error",
          "[load][threads]") {
  const Network net = gallows();
  const std::vector<int> hooks{1};
  const std::vector<std::vector<int>> steps{{0, 1}};
  const auto cuts = choose_cuts(net);
  const ForceProblem problem(net, hooks, steps, cuts);
  const Eigen::VectorXd a0 = Eigen::VectorXd::Zero(problem.columns());
  // The first call (before direction 0, before the second thread starts) and the second (before
  // another direction the calling thread takes, or the closing one when the second thread took
  // the rest) both come whatever the threads' timing.
  for (int stop_at : {1, 2}) {
    int calls = 0;
    const ProgressFn progress = [&](std::string_view, double) { return ++calls < stop_at; };
    LoadCapacityOptions lo;
    lo.threads = 2;
    CHECK_THROWS_AS(load_capacity(net, cuts, problem, a0, lo, progress), Cancelled);
    CHECK(calls == stop_at);  // nothing called it after it asked to stop
  }
  for (int threads : {0, 3}) {
    LoadCapacityOptions lo;
    lo.threads = threads;
    CHECK_THROWS_WITH(load_capacity(net, cuts, problem, a0, lo), "load capacity: threads must be 1 or 2");
  }
}
