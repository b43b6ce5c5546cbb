// optimize_target_shapes: the wires of one round, independent problems, on up to two threads.
#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <cstddef>
#include <exception>
#include <mutex>
#include <numeric>
#include <optional>
#include <string_view>
#include <system_error>
#include <thread>
#include <vector>

#include "wiresculpt/error.hpp"
#include "wiresculpt/target_shape.hpp"

namespace wiresculpt {
namespace {

// A guess of what a job costs, only to start the dearest first: two threads end a round sooner
// when its long jobs do not come last (the Chair's 26-point one-block wire took 14 of the first
// round's 33 ms, and came last). With n ≈ the contour's length / spacing points, a wire solved as
// one block costs about n² (a dense subproblem per iteration; about 4 µs·n² on the stand-ins), one
// solved in windows about 12·n of the same units (about 50 µs a point).
double expected_cost(const TargetShapeJob& job) {
  const Polyline2& c = job.contour;
  const TargetShapeOptions& o = job.options;
  double length = 0.0;
  for (std::size_t i = 1; i < c.size(); ++i) length += (c[i] - c[i - 1]).norm();
  if (job.closed && c.size() > 2) length += (c.front() - c.back()).norm();
  const double spacing = o.spacing > 0.0 ? o.spacing : 1.5 * o.min_segment;
  const double n = length / spacing + static_cast<double>(job.crossings.size());
  if (!std::isfinite(n) || n <= 0.0) return 0.0;  // bad input: optimize_target_shape says what is wrong
  const double one_block = o.one_block_points < 0 ? 4.0 * o.window : o.one_block_points;
  return o.window <= 0 || n <= one_block ? n * n : 12.0 * n;
}

}  // namespace

std::vector<TargetShapeResult> optimize_target_shapes(const std::vector<TargetShapeJob>& jobs, int threads,
                                                      const ProgressFn& progress) {
  if (threads < 1 || threads > 2) throw InputError("target shapes: threads must be 1 or 2");
  const std::size_t n = jobs.size();
  std::vector<double> cost(n);
  for (std::size_t k = 0; k < n; ++k) cost[k] = expected_cost(jobs[k]);
  std::vector<std::size_t> order(n);
  std::iota(order.begin(), order.end(), std::size_t{0});
  std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) { return cost[a] > cost[b]; });

  std::vector<std::optional<TargetShapeResult>> results(n);
  std::vector<std::exception_ptr> errors(n);
  std::atomic<std::size_t> next{0}, finished{0};
  std::atomic<bool> stop{false};
  // The other thread's jobs only look at `stop`; the calling thread's ask `progress` as well.
  const ProgressFn stopped = [&](std::string_view, double) { return !stop.load(); };
  const ProgressFn asked = [&](std::string_view stage, double fraction) {
    if (!stop && !progress(stage, fraction)) stop = true;
    return !stop.load();
  };
  auto work = [&](const ProgressFn& fn) {
    for (std::size_t i; (i = next++) < n;) {
      const std::size_t k = order[i];
      try {
        if (stop) throw Cancelled();
        results[k].emplace(optimize_target_shape(jobs[k].contour, jobs[k].closed, jobs[k].crossings, jobs[k].options, fn));
      } catch (...) {
        errors[k] = std::current_exception();
      }
      ++finished;
    }
  };

  std::mutex mutex;
  std::condition_variable worker_ended;
  bool ended = false;
  std::optional<std::thread> worker;
  if (threads == 2 && n >= 2) {
    try {
      worker.emplace([&] {
        work(progress ? stopped : ProgressFn{});
        const std::lock_guard<std::mutex> lock(mutex);
        ended = true;
        worker_ended.notify_one();
      });
    } catch (const std::system_error&) {  // no thread to be had: the calling thread does them all
    }
  }
  std::exception_ptr waiting_error;
  work(progress ? asked : ProgressFn{});
  if (worker) {
    // While the other thread ends its last job, `progress` is still asked (Live cancels a solve as
    // soon as the plane moves again); its own exception stops both and is thrown below.
    std::unique_lock<std::mutex> lock(mutex);
    while (!worker_ended.wait_for(lock, std::chrono::milliseconds(20), [&] { return ended; })) {
      if (!progress || stop || waiting_error) continue;
      lock.unlock();
      try {
        asked("target_shape", static_cast<double>(finished.load()) / static_cast<double>(n));
      } catch (...) {
        waiting_error = std::current_exception();
        stop = true;
      }
      lock.lock();
    }
    lock.unlock();
    worker->join();
  }
  for (std::size_t k = 0; k < n; ++k)
    if (errors[k]) std::rethrow_exception(errors[k]);
  if (waiting_error) std::rethrow_exception(waiting_error);
  std::vector<TargetShapeResult> out;
  out.reserve(n);
  for (std::optional<TargetShapeResult>& r : results) out.push_back(std::move(*r));
  return out;
}

}  // namespace wiresculpt
