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
// when its long jobs do not come last (the Chair's 26-point one-block wire took 12 of the first
// round's 42 ms of solving, and came last). With n the target's points (as the solver places them:
// detail::initial_point_count), a wire solved as one block costs about n² (a dense subproblem per
// iteration; about 4 µs·n² on the stand-ins), one solved in windows about 12·n of the same units
// (about 50 µs a point). (The guess was the contour's length / spacing + the crossings, which
// counted the crossings twice: the Chair's backrest and the Car's 24-point wires looked windowed,
// hence cheap, and came last; issue 17, fourteenth round.)
double expected_cost(const TargetShapeJob& job) {
  const TargetShapeOptions& o = job.options;
  const double n = detail::initial_point_count(job.contour, job.closed, job.crossings, o);
  if (n <= 0.0) return 0.0;  // bad input: optimize_target_shape says what is wrong
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
  // The other thread's jobs only look at `stop`; the calling thread's ask `progress` as well. An
  // exception from `progress` stops both (every job still running ends in Cancelled) and is the
  // one thrown at the end, as optimize_target_shape's callers see it.
  std::exception_ptr progress_error;  // written by the calling thread only
  const ProgressFn none;
  const ProgressFn stopped = [&](std::string_view, double) { return !stop.load(); };
  const ProgressFn asked = [&](std::string_view stage, double fraction) {
    if (stop) return false;
    try {
      if (!progress(stage, fraction)) stop = true;
    } catch (...) {
      progress_error = std::current_exception();
      stop = true;
    }
    return !stop.load();
  };
  auto solve = [&](std::size_t i, const ProgressFn& fn) noexcept {  // the i-th job in `order`
    const std::size_t k = order[i];
    try {
      if (stop) throw Cancelled();
      results[k].emplace(optimize_target_shape(jobs[k].contour, jobs[k].closed, jobs[k].crossings, jobs[k].options, fn));
    } catch (...) {
      errors[k] = std::current_exception();
    }
    ++finished;
  };
  auto work = [&](const ProgressFn& fn) noexcept {
    for (std::size_t i; (i = next++) < n;) solve(i, fn);
  };

  std::mutex mutex;
  std::condition_variable worker_ended;
  std::atomic<bool> ended{false};
  std::optional<std::thread> worker;
  // Whatever happens below, the other thread is stopped and joined before this frame goes (a
  // joinable std::thread destroyed would terminate the process, and Blender with it).
  struct Joiner {
    std::optional<std::thread>& thread;
    std::atomic<bool>& stop;
    ~Joiner() {
      if (thread && thread->joinable()) {
        stop = true;
        thread->join();
      }
    }
  } joiner{worker, stop};
  if (threads == 2 && n >= 2) {
    // The dearest job is the other thread's from the start (the calling thread, which answers
    // `progress` too, takes the next), so who does which does not hang on when the thread starts.
    const std::size_t first = next++;
    try {
      worker.emplace([&, first]() noexcept {
        solve(first, progress ? stopped : none);
        work(progress ? stopped : none);
        try {
          const std::lock_guard<std::mutex> lock(mutex);
          ended = true;
        } catch (...) {  // no lock to be had: the caller's 20 ms wait still sees the flag
          ended = true;
        }
        worker_ended.notify_one();
      });
    } catch (const std::system_error&) {  // no thread to be had: the calling thread does them all
      solve(first, progress ? asked : none);
    }
  }
  work(progress ? asked : none);
  if (worker && progress) {
    // While the other thread ends its last job, `progress` is still asked every 20 ms (Live
    // cancels a solve as soon as the plane moves again).
    std::unique_lock<std::mutex> lock(mutex);
    while (!worker_ended.wait_for(lock, std::chrono::milliseconds(20), [&] { return ended.load(); })) {
      if (stop) continue;
      lock.unlock();
      asked("target_shape", static_cast<double>(finished.load()) / static_cast<double>(n));
      lock.lock();
    }
  }
  if (worker) worker->join();
  if (progress_error) std::rethrow_exception(progress_error);
  for (std::size_t k = 0; k < n; ++k)
    if (errors[k]) std::rethrow_exception(errors[k]);
  std::vector<TargetShapeResult> out;
  out.reserve(n);
  for (std::optional<TargetShapeResult>& r : results) out.push_back(std::move(*r));
  return out;
}

}  // namespace wiresculpt
