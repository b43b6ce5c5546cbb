// optimize_target_shapes: the wires of one round, independent problems, on up to two threads.
#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <cstddef>
#include <deque>
#include <exception>
#include <mutex>
#include <optional>
#include <stdexcept>
#include <string_view>
#include <thread>
#include <vector>

#include <unistd.h>

#include "wiresculpt/error.hpp"
#include "wiresculpt/target_shape_batch.hpp"

namespace wiresculpt {
namespace {

// A guess of what a job costs, only to start the dearest first: two threads end a round sooner
// when its long jobs do not come last (on the Chair, its 26-point one-block wire is over a quarter
// of a round's solving: last, it would leave the other thread idle). With n the target's points (as the solver places them:
// detail::initial_point_count), a wire solved as one block costs about n² (a dense subproblem per
// iteration; about 4 µs·n² on the stand-ins), one solved in windows about 12·n of the same units
// (about 50 µs a point). The points are counted as the problem resamples them, crossings once:
// counted twice, short wires with many crossings look windowed, hence cheap, and come last.
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

// How long a thread waits awake, yielding the core to any other thread ready to run, before it
// sleeps: finish() for the other thread's last piece, the other thread for the next job. Woken
// from a sleep, a thread ran again 20-60 µs later (median 40 µs on this project's 2-core virtual
// machine, about 2 % of the globe's stage), while the last piece (a window or a short wire) and
// the next job (the stage's Python preparing a wire) mostly come within a few hundred µs.
constexpr std::chrono::microseconds kAwakeWait{1000};

// Waits awake, yielding the core, until done() or kAwakeWait has passed (the caller then sleeps).
template <class Done>
void wait_awake(Done done) {
  using Clock = std::chrono::steady_clock;
  for (const auto until = Clock::now() + kAwakeWait; !done() && Clock::now() < until;) std::this_thread::yield();
}

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

// The other thread, made once and kept for the process: a thread started for every call cost
// about 14 % more CPU than the same solves on one thread (its start and end in the kernel, a fresh
// stack, malloc arena and caches). It serves one batch at a time;
// a batch that finds it busy (another solve on another thread) runs on its own thread alone. It is
// never destroyed: parked at exit, it is the operating system's to end (joining it from a static
// destructor could wait on a batch whose caller the interpreter froze).
class Helper {
 public:
  using Fn = void (*)(void*) noexcept;

  // The process's helper, made at the first call (again in a forked child, which has no thread);
  // null when no thread can be made.
  static Helper* instance() {
    static std::mutex made;
    static Helper* helper = nullptr;
    static pid_t owner = 0;
    const std::lock_guard<std::mutex> lock(made);
    if (!helper || owner != getpid()) {
      helper = nullptr;  // a forked child's copy: its thread is the parent's (the object is left)
      try {
        helper = new Helper();
        owner = getpid();
      } catch (...) {
        helper = nullptr;
      }
    }
    return helper;
  }

  // Runs work(arg) and then done(arg) on the helper thread, unless it serves another batch (false).
  // After done(arg) returns the helper no longer touches arg.
  bool lend(Fn work, Fn done, void* arg) {
    const std::lock_guard<std::mutex> lock(mutex_);
    if (work_) return false;
    work_ = work, done_ = done, arg_ = arg;
    wake_.notify_one();
    return true;
  }

 private:
  Helper() { std::thread([this] { loop(); }).detach(); }

  void loop() noexcept {
    for (;;) {
      Fn work = nullptr, done = nullptr;
      void* arg = nullptr;
      try {
        std::unique_lock<std::mutex> lock(mutex_);
        wake_.wait(lock, [&] { return work_ != nullptr; });
        work = work_, done = done_, arg = arg_;
      } catch (...) {
        continue;  // no lock to be had (never seen): wait again
      }
      work(arg);
      try {
        const std::lock_guard<std::mutex> lock(mutex_);
        work_ = nullptr;  // free for the next batch before this one hears it ended
      } catch (...) {
        work_ = nullptr;
      }
      done(arg);
    }
  }

  std::mutex mutex_;
  std::condition_variable wake_;
  Fn work_ = nullptr, done_ = nullptr;
  void* arg_ = nullptr;
};

}  // namespace

struct TargetShapeBatch::State {
  using Clock = std::chrono::steady_clock;
  static constexpr std::size_t none = static_cast<std::size_t>(-1);

  explicit State(int t) : threads(t) {}

  // One job's run and bookkeeping. A windowed wire is a run of pieces (detail::TargetShapeRun: its
  // windows; a one-block wire is one piece). A thread keeps its wire while no free wire has clearly
  // more work left by the guess (expected_cost less the time it has had), else hands it over
  // between two windows: three equal wires on two threads then end together instead of in two
  // waves (the globe).
  struct Slot {
    const TargetShapeJob* job = nullptr;
    std::optional<detail::TargetShapeRun> run;
    std::optional<TargetShapeResult> result;  // taken from the run on the thread that ended it
    double left = 0.0;  // guessed seconds of work left
    bool busy = false, done = false;
    std::exception_ptr error;
  };

  const int threads;
  const std::thread::id caller = std::this_thread::get_id();
  // Stable addresses as jobs are added (a run refers to its job; a thread holds its slot by
  // pointer outside the lock while add() appends).
  std::deque<TargetShapeJob> jobs;
  std::deque<Slot> slots;
  SpinLock book;  // guards slots (their number, left, busy, done), closed, reserved, started, hand_overs
  bool closed = false;      // finish() began: the caller works too and no job comes
  std::size_t reserved = none;  // the job the other thread starts with (finish() before it started)
  bool started = false;     // the other thread took its first job
  int hand_overs = 0;
  std::atomic<unsigned> posted{0};  // bumped at each add and at the close: wakes an idle thread
  std::atomic<bool> stop{false};
  std::atomic<std::size_t> finished{0};

  // The calling thread asks finish()'s `progress`; the other thread's pieces only look at `stop`.
  // An exception from `progress` stops both (every job still running ends in Cancelled) and is
  // the one thrown at the end, as optimize_target_shape's callers see it. A wire's pieces may run
  // on either thread, so the function every run polls asks by the thread it finds itself on.
  const ProgressFn* progress = nullptr;  // finish()'s, read on the calling thread only
  std::exception_ptr progress_error;     // written by the calling thread only
  bool asked(std::string_view stage, double fraction) {
    if (stop) return false;
    try {
      if (!(*progress)(stage, fraction)) stop = true;
    } catch (...) {
      progress_error = std::current_exception();
      stop = true;
    }
    return !stop.load();
  }
  const ProgressFn by_thread = [this](std::string_view stage, double fraction) {
    if (std::this_thread::get_id() == caller && progress && *progress) return asked(stage, fraction);
    return !stop.load();
  };

  bool lent = false;          // the helper thread works on this batch until `ended`
  std::mutex mutex;
  std::condition_variable worker_ended;
  std::atomic<bool> ended{false};

  // The free job with the most work left (the first of equals), or none. Under `book`.
  std::size_t dearest_free() const {
    std::size_t best = none;
    for (std::size_t k = 0; k < slots.size(); ++k)
      if (!slots[k].busy && !slots[k].done && (best == none || slots[k].left > slots[best].left)) best = k;
    return best;
  }

  // A thread's loop: pieces of the jobs until none is left (for the other thread, once the batch
  // is closed; until then it waits for the next add).
  void work() noexcept {
    const bool other_thread = std::this_thread::get_id() != caller;
    std::size_t mine = none;
    Slot* slot = nullptr;
    for (;;) {
      const unsigned seen = posted.load();
      {
        const std::lock_guard<SpinLock> lock(book);
        if (other_thread && !started && reserved != none) {
          mine = reserved;
          started = true;
        }
        const std::size_t other = dearest_free();
        if (closed && mine != none && other != none && slots[other].left > slots[mine].left + kHandOverSeconds) {
          slots[mine].busy = false;
          mine = none;
          ++hand_overs;
        }
        if (mine == none) {
          if (other == none) {
            if (closed) return;
          } else {
            mine = other;
            slots[mine].busy = true;
            if (other_thread) started = true;
          }
        }
        slot = mine == none ? nullptr : &slots[mine];
      }
      if (!slot) {  // nothing free yet: wait for the next add (or the close), awake for a while
        wait_awake([&] { return posted.load() != seen; });
        posted.wait(seen);
        continue;
      }
      const auto began = Clock::now();
      bool more = false;
      try {
        if (stop) throw Cancelled();
        if (!slot->run) {
          const TargetShapeJob& job = *slot->job;
          slot->run.emplace(detail::run_target_shape(job.contour, job.closed, job.crossings, job.options, by_thread));
        }
        more = slot->run->step();
        if (!more) {  // the result, placed in its plane here: one thread's work less after the batch
          slot->result.emplace(slot->run->take());
          if (slot->job->plane) detail::place_target(*slot->result, *slot->job->plane, slot->job->closed);
        }
      } catch (...) {
        slot->error = std::current_exception();
      }
      const double spent = std::chrono::duration<double>(Clock::now() - began).count();
      const std::lock_guard<SpinLock> lock(book);
      slot->left -= spent;
      if (!more) {
        slot->done = true;
        slot->busy = false;
        ++finished;
        mine = none;
      }
    }
  }

  void post() {
    posted.fetch_add(1);
    posted.notify_all();
  }

  // Lends the helper thread to this batch (with threads = 2), unless it serves another solve: then
  // asked again at the next add() and at finish().
  void borrow_helper() {
    if (threads != 2 || lent) return;
    Helper* helper = Helper::instance();
    lent = helper && helper->lend(&State::helper_work, &State::helper_done, this);
  }

  // The helper thread's part: its loop, then the word that it ended (given under the lock, so
  // that the batch, free to go once it hears it, is not touched after).
  static void helper_work(void* state) noexcept { static_cast<State*>(state)->work(); }
  static void helper_done(void* state) noexcept {
    State& s = *static_cast<State*>(state);
    try {
      const std::lock_guard<std::mutex> lock(s.mutex);
      s.ended = true;
      s.worker_ended.notify_one();
    } catch (...) {  // no lock to be had: the waits below poll the flag every 20 ms
      s.ended = true;
    }
  }

  // Waits until the helper thread, if it works on this batch, is done with it (closing the batch
  // first, so that it stops waiting for jobs): awake for kAwakeWait, then asleep. With
  // `ask_progress`, finish()'s `progress` is still asked every 20 ms meanwhile, with the share of
  // jobs done (Live cancels a solve as soon as the plane moves again).
  void join(bool ask_progress = false) noexcept {
    if (!lent) return;
    {
      const std::lock_guard<SpinLock> lock(book);
      closed = true;
    }
    post();
    wait_awake([&] { return ended.load(); });
    try {
      std::unique_lock<std::mutex> lock(mutex);
      while (!worker_ended.wait_for(lock, std::chrono::milliseconds(20), [&] { return ended.load(); })) {
        if (!ask_progress || stop) continue;
        lock.unlock();
        const double jobs_done = static_cast<double>(finished.load());  // of none: all
        asked("target_shape", slots.empty() ? 1.0 : jobs_done / static_cast<double>(slots.size()));
        lock.lock();
      }
    } catch (...) {
      while (!ended) std::this_thread::sleep_for(std::chrono::milliseconds(1));
    }
    lent = false;
  }
};

TargetShapeBatch::TargetShapeBatch(int threads) {
  if (threads < 1 || threads > 2) throw InputError("target shapes: threads must be 1 or 2");
  state_ = std::make_unique<State>(threads);
  // The helper is woken now, so that it is awake (waiting for the first add, kAwakeWait) by the
  // time the first job is read: woken at that add it started 20-40 µs later.
  state_->borrow_helper();
}

TargetShapeBatch::~TargetShapeBatch() {
  if (!state_) return;
  state_->stop = true;
  state_->join();
}

void TargetShapeBatch::add(TargetShapeJob job) {
  State& s = *state_;
  if (s.closed) throw std::logic_error("TargetShapeBatch::add after finish");
  s.jobs.push_back(std::move(job));  // only this thread touches jobs
  State::Slot slot;
  slot.job = &s.jobs.back();
  slot.left = kSecondsPerCost * expected_cost(s.jobs.back());
  {
    const std::lock_guard<SpinLock> lock(s.book);
    s.slots.push_back(std::move(slot));
  }
  s.borrow_helper();
  s.post();
}

std::vector<TargetShapeResult> TargetShapeBatch::finish(const ProgressFn& progress, detail::TargetShapesStats* stats) {
  State& s = *state_;
  if (s.closed) throw std::logic_error("TargetShapeBatch::finish called twice");
  s.progress = &progress;
  if (s.slots.size() >= 2) s.borrow_helper();
  {
    const std::lock_guard<SpinLock> lock(s.book);
    s.closed = true;
    // The dearest job is the other thread's when it has not started yet (the calling thread, which
    // answers `progress` too, takes the next), so who starts which does not hang on when the
    // thread starts (40-100 µs on this project's 2-core virtual machine). A lone job is the
    // calling thread's (it asks `progress` as it goes), unless the helper took it already.
    if (s.lent && !s.started && s.slots.size() >= 2) {
      s.reserved = s.dearest_free();
      if (s.reserved != State::none) s.slots[s.reserved].busy = true;
    }
  }
  s.post();
  s.work();
  s.join(static_cast<bool>(progress));  // the other thread's last piece, `progress` asked meanwhile
  s.progress = nullptr;
  if (stats) stats->hand_overs = s.hand_overs;
  if (s.progress_error) std::rethrow_exception(s.progress_error);
  std::vector<TargetShapeResult> out;
  out.reserve(s.slots.size());
  for (State::Slot& slot : s.slots) {
    if (slot.error) std::rethrow_exception(slot.error);  // what the run threw, too
    out.push_back(std::move(*slot.result));
  }
  return out;
}

std::vector<TargetShapeResult> optimize_target_shapes(const std::vector<TargetShapeJob>& jobs, int threads,
                                                      const ProgressFn& progress) {
  return detail::optimize_target_shapes(jobs, threads, progress, nullptr);
}

std::vector<TargetShapeResult> detail::optimize_target_shapes(const std::vector<TargetShapeJob>& jobs, int threads,
                                                              const ProgressFn& progress, TargetShapesStats* stats) {
  // Fewer than two jobs: the other thread would only wait, the calling thread solves it alone.
  TargetShapeBatch batch(jobs.size() < 2 && threads == 2 ? 1 : threads);
  for (const TargetShapeJob& job : jobs) batch.add(job);
  return batch.finish(progress, stats);
}

}  // namespace wiresculpt
