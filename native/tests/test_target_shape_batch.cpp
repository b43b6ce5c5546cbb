// optimize_target_shapes (a round's wires on two threads) against optimize_target_shape of each
// wire alone: the same results bit for bit, in the jobs' order whatever order the threads take
// them in; errors and cancellation as one call's.
#include <catch2/catch.hpp>
#include <atomic>
#include <chrono>
#include <cmath>
#include <mutex>
#include <numbers>
#include <set>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include "wiresculpt/error.hpp"
#include "wiresculpt/target_shape_batch.hpp"

using namespace wiresculpt;
using Catch::Matchers::Contains;

namespace {
constexpr double pi = std::numbers::pi;

// A closed wavy loop r = r0 + a cos(lobes t) of n points with `kinks` active crossings whose
// bisectors alternate outwards and inwards.
TargetShapeJob loop(const std::string& name, double r0, double a, int lobes, int n, int kinks) {
  TargetShapeJob job;
  job.closed = true;
  for (int k = 0; k < n; ++k) {
    const double t = 2 * pi * k / n;
    const double r = r0 + a * std::cos(lobes * t);
    job.contour.emplace_back(r * std::cos(t), r * std::sin(t));
  }
  for (int k = 0; k < kinks; ++k) {
    const int v = k * n / kinks + 3;
    job.crossings.push_back({v, (k % 2 ? -1.0 : 1.0) * job.contour[v].normalized(), 2 * pi / 3, true});
  }
  job.options.wire_name = name;
  job.options.sweep_ftol = 1e-3;
  job.options.algorithm = TargetShapeAlgorithm::sqp;
  return job;
}

// Short loops first, so that the dearest-first order differs from the jobs' order: one-block
// wires (under 32 points) and windowed ones (the 0.6 m and 1 m loops).
std::vector<TargetShapeJob> round_of_wires() {
  return {loop("Alpha", 0.05, 0.005, 3, 200, 2), loop("Bravo", 0.09, 0.01, 4, 300, 3), loop("Charlie", 0.16, 0.02, 5, 600, 4),
          loop("Delta", 0.06, 0.0, 1, 200, 0), loop("Echo", 0.1, 0.015, 3, 400, 4)};
}

// A 3 m loop solved the slow way (SLSQP, sweeps to 1 nm): about a second.
TargetShapeJob slow_loop() {
  TargetShapeJob slow = loop("Slow", 0.45, 0.05, 5, 3000, 6);
  slow.options.algorithm = TargetShapeAlgorithm::slsqp;
  slow.options.sweep_ftol = 0.0;
  slow.options.sweep_tol = 1e-9;
  return slow;
}

void check_same(const TargetShapeResult& a, const TargetShapeResult& b) {
  REQUIRE(a.points.size() == b.points.size());
  for (std::size_t i = 0; i < a.points.size(); ++i) CHECK(a.points[i] == b.points[i]);
  CHECK(a.energy == b.energy);
  CHECK(a.max_distance == b.max_distance);
  CHECK(a.iterations == b.iterations);
  CHECK(a.crossing_vertices == b.crossing_vertices);
  REQUIRE(a.crossings.size() == b.crossings.size());
  for (std::size_t c = 0; c < a.crossings.size(); ++c) {
    CHECK(a.crossings[c].status == b.crossings[c].status);
    CHECK(a.crossings[c].message == b.crossings[c].message);
  }
  CHECK(a.nlopt_result == b.nlopt_result);
  CHECK(a.feasible == b.feasible);
}
}  // namespace

TEST_CASE("target shapes: each result is its wire's alone, in the jobs' order, on one or two threads", "[target]") {
  const std::vector<TargetShapeJob> jobs = round_of_wires();
  std::vector<TargetShapeResult> alone;
  for (const TargetShapeJob& j : jobs) alone.push_back(optimize_target_shape(j.contour, j.closed, j.crossings, j.options));
  // The jobs differ (else a swapped pair would pass): each wire's own number of points.
  std::set<std::size_t> sizes;
  for (const TargetShapeResult& r : alone) sizes.insert(r.points.size());
  REQUIRE(sizes.size() == jobs.size());
  for (int threads : {1, 2}) {
    for (int rep = 0; rep < 3; ++rep) {
      const std::vector<TargetShapeResult> together = optimize_target_shapes(jobs, threads);
      REQUIRE(together.size() == jobs.size());
      for (std::size_t k = 0; k < jobs.size(); ++k) {
        INFO("threads " << threads << ", wire " << jobs[k].options.wire_name);
        check_same(together[k], alone[k]);
      }
    }
  }
  CHECK(optimize_target_shapes({}, 2).empty());
}

TEST_CASE("target shapes: a wire run a piece at a time, on any thread and between other wires' pieces, is its wire's alone",
          "[target]") {
  // What optimize_target_shapes relies on to hand a wire from one thread to the other between its
  // windows: a run's pieces depend only on the run. Here every wire of the round advances one
  // piece in turn, each second piece on a thread of its own.
  const std::vector<TargetShapeJob> jobs = round_of_wires();
  std::vector<TargetShapeResult> alone;
  for (const TargetShapeJob& j : jobs) alone.push_back(optimize_target_shape(j.contour, j.closed, j.crossings, j.options));
  std::vector<detail::TargetShapeRun> runs;
  for (const TargetShapeJob& j : jobs) runs.push_back(detail::run_target_shape(j.contour, j.closed, j.crossings, j.options, nullptr));
  std::vector<int> pieces(jobs.size(), 0);
  std::vector<char> more(jobs.size(), 1);
  for (bool any = true; any;) {
    any = false;
    for (std::size_t k = 0; k < jobs.size(); ++k) {
      if (!more[k]) continue;
      bool stepped = false;
      if (pieces[k]++ % 2) {
        std::thread([&] { stepped = runs[k].step(); }).join();
      } else {
        stepped = runs[k].step();
      }
      more[k] = stepped;
      any = any || stepped;
    }
  }
  const int one_block = 4 * TargetShapeOptions{}.window;  // one_block_points -1: 4 windows
  for (std::size_t k = 0; k < jobs.size(); ++k) {
    INFO("wire " << jobs[k].options.wire_name << ", " << pieces[k] << " pieces");
    check_same(runs[k].take(), alone[k]);
    // One piece for a wire solved as one block; a windowed wire pauses after each window.
    if (static_cast<int>(alone[k].points.size()) <= one_block)
      CHECK(pieces[k] == 1);
    else
      CHECK(pieces[k] > alone[k].sweeps);
  }
  CHECK(!runs[0].step());  // an ended run stays ended
}

TEST_CASE("target shapes: a run's pauses count neither against its time budget nor in its seconds", "[target]") {
  // A windowed wire (a few ms alone, 33 pieces) with a budget of 0.25 s, paused 20 ms after every window:
  // the pauses add up to more than the budget, and the solve must end as it does alone.
  TargetShapeJob job = loop("Charlie", 0.16, 0.02, 5, 600, 4);
  job.options.max_seconds = 0.25;
  const TargetShapeResult alone = optimize_target_shape(job.contour, job.closed, job.crossings, job.options);
  REQUIRE(alone.nlopt_result != "NLOPT_MAXTIME_REACHED");
  detail::TargetShapeRun run = detail::run_target_shape(job.contour, job.closed, job.crossings, job.options, nullptr);
  CHECK_THROWS_AS(run.take(), std::logic_error);  // not ended yet
  int pieces = 0;
  while (run.step()) {
    ++pieces;
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  const double slept = 0.020 * pieces;
  REQUIRE(slept > job.options.max_seconds);
  const TargetShapeResult r = run.take();
  check_same(r, alone);
  CHECK(r.warnings == alone.warnings);
  CHECK(r.seconds < slept);
  CHECK_THROWS_AS(run.take(), std::logic_error);  // taken already
}

TEST_CASE("target shapes: three equal windowed wires on two threads are handed between them, as each alone",
          "[target]") {
  // The globe's case: three wires of one cost. A thread hands its wire over between two windows for
  // one with more work left, so the three share both threads instead of the third waiting for one
  // of the first two. The results stay each wire's alone; progress is still asked on the calling
  // thread only, and stopping it stops wires paused between their windows too.
  std::vector<TargetShapeJob> jobs;
  for (const char* name : {"North", "East", "West"}) jobs.push_back(loop(name, 0.16, 0.02, 5, 600, 4));
  std::vector<TargetShapeResult> alone;
  for (const TargetShapeJob& j : jobs) alone.push_back(optimize_target_shape(j.contour, j.closed, j.crossings, j.options));
  REQUIRE(alone[0].points.size() > static_cast<std::size_t>(4 * TargetShapeOptions{}.window));  // windowed

  const std::thread::id caller = std::this_thread::get_id();
  std::mutex seen_mutex;
  std::set<std::thread::id> seen;
  const ProgressFn watch = [&](std::string_view, double) {
    const std::lock_guard<std::mutex> lock(seen_mutex);
    seen.insert(std::this_thread::get_id());
    return true;
  };
  detail::TargetShapesStats stats;
  const std::vector<TargetShapeResult> together = detail::optimize_target_shapes(jobs, 2, watch, &stats);
  CHECK(stats.hand_overs > 0);
  CHECK(seen == std::set<std::thread::id>{caller});
  for (std::size_t k = 0; k < jobs.size(); ++k) {
    INFO("wire " << jobs[k].options.wire_name);
    check_same(together[k], alone[k]);
  }

  // Stopped part-way, wires paused between their windows (1 to 7 hand-overs before the stop in
  // five runs): Cancelled, and the paused runs are let go (the sanitizer build checks their frames).
  std::atomic<int> asked{0};
  const ProgressFn stop = [&](std::string_view, double) { return ++asked < 6; };
  detail::TargetShapesStats stopped;
  CHECK_THROWS_AS(detail::optimize_target_shapes(jobs, 2, stop, &stopped), Cancelled);
  CHECK(asked == 6);
}

TEST_CASE("target shapes: progress is asked on the calling thread only, and it cancels every wire", "[target]") {
  const std::vector<TargetShapeJob> jobs = round_of_wires();
  const std::thread::id caller = std::this_thread::get_id();
  // Recorded in the callback, checked after the call (Catch's assertions are not for threads).
  std::mutex seen_mutex;
  std::set<std::thread::id> seen;
  std::vector<double> fractions;
  const ProgressFn count = [&](std::string_view, double f) {
    const std::lock_guard<std::mutex> lock(seen_mutex);
    seen.insert(std::this_thread::get_id());
    fractions.push_back(f);
    return true;
  };
  optimize_target_shapes(jobs, 2, count);
  CHECK(!fractions.empty());
  CHECK(seen == std::set<std::thread::id>{caller});
  for (double f : fractions) {
    CHECK(f >= 0.0);
    CHECK(f <= 1.0);
  }

  // Stopped at the third question: both threads stop, and the call ends in Cancelled.
  std::atomic<int> asked{0};
  const ProgressFn stop = [&](std::string_view, double) { return ++asked < 3; };
  CHECK_THROWS_AS(optimize_target_shapes(jobs, 2, stop), Cancelled);
  CHECK(asked == 3);  // never asked again once it said stop

  // A callback that throws: its own exception, not Cancelled, once both threads stopped.
  std::atomic<int> thrown{0};
  const ProgressFn fails = [&](std::string_view, double) -> bool {
    if (++thrown == 3) throw std::runtime_error("the callback's own error");
    return true;
  };
  CHECK_THROWS_WITH(optimize_target_shapes(jobs, 2, fails), "the callback's own error");
  CHECK(thrown == 3);
}

TEST_CASE("target shapes: progress is still asked while the other thread ends its last wire, and can stop it",
          "[target]") {
  // The dearest job (by its length) is the other thread's from the start: slow_loop, about a
  // second. The calling thread's only job is bad and fails at once, so the calling thread then
  // waits, asking progress every 20 ms with the share of jobs done (1 of 2). Stopping there must stop the long solve: Cancelled, not the bad wire's
  // InputError that would come once the long solve ended.
  const TargetShapeJob slow = slow_loop();
  TargetShapeJob bad = loop("Bad", 0.05, 0.0, 1, 100, 0);
  bad.crossings = {{500, Vec2(1, 0), 2.0, true}};  // past its 100 points
  std::vector<double> fractions;  // asked on the calling thread only
  const ProgressFn stop_when_waiting = [&](std::string_view, double f) {
    fractions.push_back(f);
    return f != 0.5;
  };
  CHECK_THROWS_AS(optimize_target_shapes({slow, bad}, 2, stop_when_waiting), Cancelled);
  REQUIRE(!fractions.empty());
  CHECK(fractions.back() == 0.5);
}

TEST_CASE("target shapes: the first bad wire in the jobs' order is the error, after every thread stopped",
          "[target]") {
  std::vector<TargetShapeJob> jobs = round_of_wires();
  jobs[3].crossings = {{5000, Vec2(1, 0), 2.0, true}};  // past the contour's 200 points
  jobs[4].crossings = {{1, Vec2(0, 0), 2.0, true}};     // a zero bisector
  for (int threads : {1, 2}) {
    INFO("threads " << threads);
    CHECK_THROWS_AS(optimize_target_shapes(jobs, threads), InputError);
    CHECK_THROWS_WITH(optimize_target_shapes(jobs, threads), Contains("Delta") && !Contains("Echo"));
  }
  CHECK_THROWS_WITH(optimize_target_shapes(jobs, 0), Contains("threads must be 1 or 2"));
  CHECK_THROWS_WITH(optimize_target_shapes(jobs, 3), Contains("threads must be 1 or 2"));
}

TEST_CASE("target shapes: a batch fed one job at a time gives each wire's own result, in the order added",
          "[target]") {
  // The other thread starts on the first job while the caller is still adding (here: pausing 2 ms
  // between adds, as the stage's Python prepares the next wire), then finish() works on both.
  const std::vector<TargetShapeJob> jobs = round_of_wires();
  std::vector<TargetShapeResult> alone;
  for (const TargetShapeJob& j : jobs) alone.push_back(optimize_target_shape(j.contour, j.closed, j.crossings, j.options));
  for (int threads : {1, 2}) {
    TargetShapeBatch batch(threads);
    for (const TargetShapeJob& j : jobs) {
      batch.add(j);
      std::this_thread::sleep_for(std::chrono::milliseconds(2));
    }
    const std::vector<TargetShapeResult> results = batch.finish();
    REQUIRE(results.size() == jobs.size());
    for (std::size_t k = 0; k < jobs.size(); ++k) {
      INFO("threads " << threads << ", wire " << jobs[k].options.wire_name);
      check_same(results[k], alone[k]);
    }
    CHECK_THROWS_AS(batch.add(jobs[0]), std::logic_error);
    CHECK_THROWS_AS(batch.finish(), std::logic_error);
  }
  CHECK(TargetShapeBatch(2).finish().empty());
  TargetShapeBatch lone(2);  // one job with two threads: whichever takes it, its own result
  lone.add(jobs[2]);
  const std::vector<TargetShapeResult> one = lone.finish();
  REQUIRE(one.size() == 1);
  check_same(one[0], alone[2]);
  CHECK_THROWS_WITH(TargetShapeBatch(3), Contains("threads must be 1 or 2"));
}

TEST_CASE("target shapes: two batches at once share the other thread and each gets its wires' own results",
          "[target]") {
  // The helper thread serves one batch at a time: the one that finds it busy runs on its own thread.
  const std::vector<TargetShapeJob> jobs = round_of_wires();
  std::vector<TargetShapeResult> alone;
  for (const TargetShapeJob& j : jobs) alone.push_back(optimize_target_shape(j.contour, j.closed, j.crossings, j.options));
  std::vector<TargetShapeResult> first, second;
  std::thread other([&] { second = optimize_target_shapes(jobs, 2); });
  first = optimize_target_shapes(jobs, 2);
  other.join();
  REQUIRE(first.size() == jobs.size());
  REQUIRE(second.size() == jobs.size());
  for (std::size_t k = 0; k < jobs.size(); ++k) {
    INFO("wire " << jobs[k].options.wire_name);
    check_same(first[k], alone[k]);
    check_same(second[k], alone[k]);
  }
}

TEST_CASE("target shapes: a batch dropped before finish stops the other thread's work, which serves the next",
          "[target]") {
  // As when the Python that feeds a batch raises: the long job the other thread took is stopped at
  // its next poll (well before its second of work), and the thread is free for the next batch.
  const TargetShapeJob slow = slow_loop();
  const auto began = std::chrono::steady_clock::now();
  {
    TargetShapeBatch batch(2);
    batch.add(slow);
    std::this_thread::sleep_for(std::chrono::milliseconds(20));  // the other thread is on it
  }
  const double dropped = std::chrono::duration<double>(std::chrono::steady_clock::now() - began).count();
  const TargetShapeResult whole = optimize_target_shape(slow.contour, slow.closed, slow.crossings, slow.options);
  const double solved = std::chrono::duration<double>(std::chrono::steady_clock::now() - began).count() - dropped;
  CHECK(dropped < 0.5 * solved);  // stopped, not waited for (no time asserted, only the proportion)
  const std::vector<TargetShapeJob> jobs = round_of_wires();
  detail::TargetShapesStats stats;
  const std::vector<TargetShapeResult> next = detail::optimize_target_shapes(jobs, 2, {}, &stats);
  REQUIRE(next.size() == jobs.size());
  check_same(next[0], optimize_target_shape(jobs[0].contour, jobs[0].closed, jobs[0].crossings, jobs[0].options));
  CHECK(whole.points.size() > 0);
}

TEST_CASE("target shapes: the dearest-first guess counts a wire's target points as the solver places them",
          "[target]") {
  // Wires near the one-block limit with many crossings: the guess must tell one-block wires (a
  // dense problem, the dearest per point) from windowed ones as the solver does, else a long
  // one-block solve can come last and run alone on one thread (the Chair's 26-point backrest with
  // ten crossings did, when the guess added the crossings to length / spacing). The solver's count
  // is its own problem's points (TargetShapeProblem::initial).
  int near_limit = 0;
  for (bool closed : {true, false}) {
    for (int kinks : {0, 1, 4, 8, 10, 12}) {
      for (double wanted : {3.0, 18.0, 22.0, 25.0, 26.0, 27.0, 30.0, 32.0, 36.0, 120.0}) {
        TargetShapeJob job = loop("Wavy", 0.05, 0.004, 3, 240, kinks);
        job.closed = closed;
        if (!closed && kinks >= 8) {  // crossings at an open wire's ends: no extra knot there
          job.crossings.front().vertex = 0;
          job.crossings.back().vertex = static_cast<int>(job.contour.size()) - 1;
        }
        double length = 0.0;
        for (std::size_t i = 0; i + 1 < job.contour.size(); ++i) length += (job.contour[i + 1] - job.contour[i]).norm();
        job.options.min_segment = length / wanted / 1.5;  // the default spacing: 1.5 min_segment
        const TargetShapeProblem problem(job.contour, job.closed, job.crossings, job.options);
        const int m = static_cast<int>(problem.initial().size());
        INFO((closed ? "closed, " : "open, ") << kinks << " crossings, " << wanted << " points wanted");
        CHECK(detail::initial_point_count(job.contour, job.closed, job.crossings, job.options) == m);
        near_limit += kinks >= 8 && m >= 24 && m <= 28;
      }
    }
  }
  CHECK(near_limit >= 2);  // the case that matters was met: one-block wires just under the limit, many crossings
  // Input the problem refuses is no count (the solve says what is wrong).
  TargetShapeJob bad = loop("Bad", 0.05, 0.0, 1, 100, 0);
  bad.crossings = {{500, Vec2(1, 0), 2.0, true}};
  CHECK(detail::initial_point_count(bad.contour, bad.closed, bad.crossings, bad.options) == -1);
  CHECK(detail::initial_point_count({Vec2(0, 0)}, false, {}, bad.options) == -1);
}

TEST_CASE("target shapes: a job with a plane has its result placed in space and measured", "[target]") {
  std::vector<TargetShapeJob> jobs = round_of_wires();
  jobs.resize(3);
  const Plane tilted = Plane::make(Vec3(0.3, -0.2, 1.5), Vec3(0.2, -0.7, 0.4));
  jobs[0].plane = tilted;
  jobs[2].plane = Plane::make(Vec3(-1.0, 0.0, 0.25), Vec3(0.0, 1.0, 0.0));
  jobs[2].closed = false;  // an open wire: no closing edge
  for (int threads : {1, 2}) {
    const std::vector<TargetShapeResult> rs = optimize_target_shapes(jobs, threads);
    for (std::size_t k : {std::size_t{0}, std::size_t{2}}) {
      INFO("threads " << threads << ", wire " << jobs[k].options.wire_name);
      const TargetShapeResult& r = rs[k];
      const TargetShapeJob& job = jobs[k];
      const TargetShapeResult alone = optimize_target_shape(job.contour, job.closed, job.crossings, job.options);
      check_same(r, alone);
      REQUIRE(r.target.size() == r.points.size());
      for (std::size_t i = 0; i < r.points.size(); ++i) {
        const Vec3 expected = jobs[k].plane->to_3d(r.points[i]);
        CHECK(r.target[i] == expected);
        // In the plane, at the 2D point's distance from the origin.
        CHECK(std::abs(jobs[k].plane->signed_distance(r.target[i])) < 1e-12);
        CHECK(std::abs((r.target[i] - jobs[k].plane->origin).norm() - r.points[i].norm()) < 1e-12);
      }
      // The 2D polyline's length: the frame is orthonormal.
      CHECK(std::abs(r.length - polyline_length(r.points, jobs[k].closed)) < 1e-12);
      CHECK(r.length > 0.1);
    }
    CHECK(rs[1].target.empty());  // no plane: nothing placed
    CHECK(rs[1].length == 0.0);
  }
}
