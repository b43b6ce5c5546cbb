// optimize_target_shapes: the wires of one round, independent problems, on up to two threads.
#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <cstddef>
#include <exception>
#include <mutex>
#include <optional>
#include <string_view>
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

// expected_cost's units in seconds, about (4 µs a unit on the stand-ins; see above).
constexpr double kSecondsPerCost = 4e-6;
// A thread hands its wire over for a free one only when that one has this much more work left by
// the guess: each hand-over moves a wire's working set to the other core, so a wire keeps its
// thread for a few windows at least.
constexpr double kHandOverSeconds = 2e-4;

// Guards the jobs' bookkeeping between two pieces (a few comparisons over the jobs): never throws,
// unlike std::mutex, inside the threads' noexcept loops.
class SpinLock {
 public:
  void lock() noexcept {
    while (flag_.test_and_set(std::memory_order_acquire)) std::this_thread::yield();
  }
  void unlock() noexcept { flag_.clear(std::memory_order_release); }

 private:
  std::atomic_flag flag_;
};

}  // namespace

std::vector<TargetShapeResult> optimize_target_shapes(const std::vector<TargetShapeJob>& jobs, int threads,
                                                      const ProgressFn& progress) {
  return detail::optimize_target_shapes(jobs, threads, progress, nullptr);
}

std::vector<TargetShapeResult> detail::optimize_target_shapes(const std::vector<TargetShapeJob>& jobs, int threads,
                                                              const ProgressFn& progress, TargetShapesStats* stats) {
  if (threads < 1 || threads > 2) throw InputError("target shapes: threads must be 1 or 2");
  const std::size_t n = jobs.size();
  using Clock = std::chrono::steady_clock;

  // The calling thread asks `progress`; the other thread's pieces only look at `stop`. An
  // exception from `progress` stops both (every job still running ends in Cancelled) and is the
  // one thrown at the end, as optimize_target_shape's callers see it. A wire's pieces may run on
  // either thread, so its progress function asks by the thread it finds itself on.
  std::atomic<bool> stop{false};
  std::exception_ptr progress_error;  // written by the calling thread only
  const std::thread::id caller = std::this_thread::get_id();
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
  const ProgressFn by_thread = [&](std::string_view stage, double fraction) {
    if (std::this_thread::get_id() == caller) return asked(stage, fraction);
    return !stop.load();
  };
  const ProgressFn none;
  const ProgressFn& fn = progress ? by_thread : none;

  // Each job is a run of pieces (detail::TargetShapeRun: a windowed wire's windows, one piece for
  // a one-block wire). A thread keeps its wire while no free wire has clearly more work left by
  // the guess (expected_cost less the time it has had), else hands it over between two windows:
  // three equal wires on two threads then end together instead of in two waves (the globe).
  struct Slot {
    std::optional<detail::TargetShapeRun> run;
    double left = 0.0;  // guessed seconds of work left
    bool busy = false, done = false;
    std::exception_ptr error;
  };
  std::vector<Slot> slots(n);
  for (std::size_t k = 0; k < n; ++k) slots[k].left = kSecondsPerCost * expected_cost(jobs[k]);
  SpinLock book;  // guards slots' left, busy and done
  std::atomic<std::size_t> finished{0};
  int hand_overs = 0;  // guarded by book
  // The free wire with the most work left (the first of equals), or n.
  auto dearest_free = [&]() {
    std::size_t best = n;
    for (std::size_t k = 0; k < n; ++k)
      if (!slots[k].busy && !slots[k].done && (best == n || slots[k].left > slots[best].left)) best = k;
    return best;
  };
  auto work = [&](std::size_t mine) noexcept {  // mine: the job it starts with (busy already), or n
    for (;;) {
      {
        const std::lock_guard<SpinLock> lock(book);
        const std::size_t other = dearest_free();
        if (mine != n && other != n && slots[other].left > slots[mine].left + kHandOverSeconds) {
          slots[mine].busy = false;
          mine = n;
          ++hand_overs;
        }
        if (mine == n) {
          if (other == n) return;
          mine = other;
          slots[mine].busy = true;
        }
      }
      Slot& slot = slots[mine];
      const auto began = Clock::now();
      bool more = false;
      try {
        if (stop) throw Cancelled();
        if (!slot.run) {
          const TargetShapeJob& job = jobs[mine];
          slot.run.emplace(detail::run_target_shape(job.contour, job.closed, job.crossings, job.options, fn));
        }
        more = slot.run->step();
      } catch (...) {
        slot.error = std::current_exception();
      }
      const double spent = std::chrono::duration<double>(Clock::now() - began).count();
      const std::lock_guard<SpinLock> lock(book);
      slot.left -= spent;
      if (!more) {
        slot.done = true;
        slot.busy = false;
        ++finished;
        mine = n;
      }
    }
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
    // `progress` too, takes the next), so who starts which does not hang on when the thread starts
    // (40-100 µs on this project's 2-core virtual machine).
    const std::size_t first = dearest_free();
    slots[first].busy = true;
    try {
      worker.emplace([&, first]() noexcept {
        work(first);
        try {
          const std::lock_guard<std::mutex> lock(mutex);
          ended = true;
        } catch (...) {  // no lock to be had: the caller's 20 ms wait still sees the flag
          ended = true;
        }
        worker_ended.notify_one();
      });
    } catch (...) {  // no thread to be had: the calling thread does them all
      slots[first].busy = false;
    }
  }
  work(n);
  if (worker && progress) {
    // While the other thread ends its last piece, `progress` is still asked every 20 ms (Live
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
  if (stats) stats->hand_overs = hand_overs;
  if (progress_error) std::rethrow_exception(progress_error);
  std::vector<TargetShapeResult> out;
  out.reserve(n);
  for (Slot& slot : slots) {
    if (slot.error) std::rethrow_exception(slot.error);
    out.push_back(slot.run->take());  // rethrows what the run threw
  }
  return out;
}

}  // namespace wiresculpt
