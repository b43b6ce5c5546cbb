// Streaming a validated program on an open port with GRBL's send-response protocol: one line
// out, then its answer, every wait bounded and the switches of StreamControl looked at while
// waiting; a stop says which lines are done and where a resume goes on (serial.hpp, Resume).
#include <algorithm>
#include <chrono>
#include <cstddef>
#include <optional>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "grbl_protocol.hpp"
#include "wiresculpt/error.hpp"
#include "wiresculpt/fab/serial.hpp"

namespace wiresculpt::fab {

const char* to_string(StreamStatus status) {
  switch (status) {
    case StreamStatus::completed: return "completed";
    case StreamStatus::dry_run: return "dry_run";
    case StreamStatus::error: return "error";
    case StreamStatus::alarm: return "alarm";
    case StreamStatus::disconnected: return "disconnected";
    case StreamStatus::timeout: return "timeout";
    case StreamStatus::aborted: return "aborted";
    case StreamStatus::protocol_error: return "protocol_error";
  }
  return "unknown";
}

namespace {

using Clock = std::chrono::steady_clock;
using detail::is_dwell;
using detail::is_modal_setup;
using detail::is_motionless;
using detail::is_sync;
using detail::moves_of;

// What unlocks a GRBL in alarm (ALARM:n) or lock (error:9) state, named in every such message.
const std::string kUnlock =
    "unlock it with $X (kill alarm lock), or home it with $H when the machine has homing switches";
using Kind = GrblAnswer::Kind;

int to_ms(double seconds) { return static_cast<int>(std::clamp(seconds, 0.0, 1e6) * 1000.0); }

std::string quoted(const std::vector<std::string>& lines, std::size_t i) {
  return "line " + std::to_string(i + 1) + " ('" + lines[i] + "')";
}

// Splits the port's bytes into lines ("\n"-terminated), each read by parse_answer.
class LineReader {
 public:
  explicit LineReader(SerialPort& port) : port_(port) {}
  enum class Got { line, nothing, lost };
  // Waits at most timeout_ms for one complete line.
  Got next(GrblAnswer& line, int timeout_ms) {
    const auto deadline = Clock::now() + std::chrono::milliseconds(timeout_ms);
    for (bool looked = false;; looked = true) {
      const std::size_t nl = buffer_.find('\n');
      if (nl != std::string::npos) {
        line = parse_answer(buffer_.substr(0, nl));
        buffer_.erase(0, nl + 1);
        return Got::line;
      }
      const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(deadline - Clock::now()).count();
      if (left <= 0 && looked) return Got::nothing;  // the port is read at least once
      char buf[256];
      const int n = port_.read(buf, sizeof buf, static_cast<int>(std::max<long long>(left, 0)));
      if (n < 0) return Got::lost;
      buffer_.append(buf, static_cast<std::size_t>(n));
    }
  }
  // A complete line already received or readable now, without waiting.
  Got pending(GrblAnswer& line) { return next(line, 0); }

 private:
  SerialPort& port_;
  std::string buffer_;
};

// One call of stream_program on an open port: the result being filled, the stops it can end in,
// and the stream's phases (restoring modes before a resume, the lines, the check after the last).
class Streamer {
 public:
  Streamer(SerialPort& port, const std::vector<std::string>& lines, const MachineProfile& profile, StreamState& state,
           const StreamOptions& options, const ProgressFn& progress)
      : port_(port),
        lines_(lines),
        profile_(profile),
        state_(state),
        progress_(progress),
        total_(lines.size()),
        write_ms_(std::max(1, to_ms(options.write_timeout))),
        answer_ms_(std::max(1, to_ms(options.response_timeout))),
        control_(options.control),
        reader_(port) {
    r_.last_acknowledged = static_cast<long>(state.next_line) - 1;
  }

  StreamResult run() {
    if (!report()) return abort_machine(static_cast<long>(state_.next_line));
    if (auto stopped = restore_modes()) return *stopped;
    while (state_.next_line < total_) {
      const std::size_t i = state_.next_line;
      const long li = static_cast<long>(i);
      if (wants_abort()) return abort_machine(li);
      if (control_ && control_->pause.load())
        if (auto stopped = hold(li)) return *stopped;
      if (auto stopped = send(i)) return *stopped;
      if (auto stopped = await_ok(i)) return *stopped;
      ++state_.next_line;
      if (is_sync(lines_[i]) || (state_.confirmed == i && is_motionless(lines_[i]))) state_.confirmed = i + 1;
      ++r_.acknowledged;
      r_.last_acknowledged = li;
      if (!report()) return abort_machine(state_.next_line < total_ ? static_cast<long>(state_.next_line) : -1);
    }
    return finish();
  }

 private:
  using Outcome = std::optional<StreamResult>;
  static constexpr int kSliceMs = 20;  // how often control switches are looked at while waiting

  double fraction() const {
    return total_ ? static_cast<double>(state_.next_line) / static_cast<double>(total_) : 1.0;
  }
  bool wants_abort() const { return control_ && control_->abort.load(); }
  bool report() { return !progress_ || progress_("stream", fraction()); }

  StreamResult stop(StreamStatus status, long line, std::string message) {
    r_.status = status;
    r_.failed_line = line;
    r_.message = std::move(message);
    return r_;
  }

  // Where a resume goes on after a stop: "; N lines are done; resume from line N+1".
  std::string resume_at() const {
    return "; " + std::to_string(state_.next_line) + " lines are done; resume from line " +
           std::to_string(state_.next_line + 1);
  }

  // A stop after which the controller's queued moves may be lost (a dropped link or a timeout,
  // then the reset of reopening the port; an alarm; our own soft reset; a restart; a feed hold
  // left in place). GRBL answers "ok" when it queues a line, so the lines acknowledged since the
  // last sync line (state.confirmed) are in doubt: the message names that step, and
  // state.next_line goes back to its first line, so that a resume makes the whole step again.
  StreamResult interrupted(StreamStatus status, long line, const std::string& cause) {
    if (state_.next_line <= state_.confirmed) return stop(status, line, cause + resume_at());
    const std::size_t a = state_.confirmed, acked = state_.next_line - 1;
    std::size_t b = a;
    while (b + 1 < total_ && !is_sync(lines_[b])) ++b;  // the step's end: its sync line (or the last line)
    bool steps = false;
    std::size_t step = 1;
    for (std::size_t j = 0; j < total_; ++j)
      if (is_dwell(lines_[j])) {
        steps = true;
        if (j < a) ++step;
      }
    const std::string span = std::to_string(a + 1) + "-" + std::to_string(b + 1);
    const std::string what = (steps ? "step " + std::to_string(step) + " (lines " : "the moves of lines (") + span +
                             ": " + moves_of(lines_, profile_, a, b) + ")";
    const std::string done = a ? "lines 1-" + std::to_string(a) + " are done" : "no line is known done";
    state_.next_line = a;
    return stop(status, line,
                cause + "; " + what + " may be half made: GRBL answers 'ok' when it queues a line, and " +
                    (acked > a ? "lines " + std::to_string(a + 1) + "-" + std::to_string(acked + 1) + " were"
                               : "line " + std::to_string(a + 1) + " was") +
                    " acknowledged but not " + quoted(lines_, b) +
                    ", which is answered only when the moves have run; a reset of the controller drops queued "
                    "moves; check the wire: the resume restarts " + (steps ? "the step" : "these lines") +
                    " from line " + std::to_string(a + 1) + " (" + done + "); if the wire shows " +
                    (steps ? "the step" : "them") + " made in full, continue from line " + std::to_string(b + 2) +
                    " instead (next_line " + std::to_string(b + 1) + ")");
  }

  StreamResult abort_machine(long line) {
    port_.write(std::string("!") + '\x18', write_ms_);  // feed hold, then soft reset
    return interrupted(StreamStatus::aborted, line,
                       "aborted by request before " +
                           (line >= 0 ? quoted(lines_, static_cast<std::size_t>(line)) : std::string("the end")) +
                           " was acknowledged; the machine was stopped with a feed hold and a soft reset");
  }

  // An answer with no line of ours outstanding (before a line is sent, or while paused). `held`:
  // the machine is in a feed hold, so its queued moves have not run.
  Outcome unexpected(const GrblAnswer& answer, long li, const std::string& when, bool held) {
    if (answer.kind == Kind::banner)
      return interrupted(StreamStatus::disconnected, li,
                         "the controller restarted " + when + " (its banner '" + answer.text +
                             "' arrived): it is back in its default modes and dropped its queued moves; the resume "
                             "restores the program's modes first");
    if (answer.kind == Kind::alarm) {
      r_.code = answer.code;
      return interrupted(StreamStatus::alarm, li,
                         "GRBL raised " + answer.text + " " + when + "; the machine is locked: " + kUnlock);
    }
    if (answer.kind == Kind::ok || answer.kind == Kind::error) {
      const std::string cause = "protocol error: the controller sent an unexpected '" + answer.text +
                                "' (more answers than lines sent) " + when + "; " +
                                std::to_string(state_.next_line) +
                                " lines are acknowledged; check the device and the port settings";
      if (held) return interrupted(StreamStatus::protocol_error, li, cause + " (the machine is in a feed hold)");
      return stop(StreamStatus::protocol_error, li, cause + ", then resume from line " + std::to_string(li + 1));
    }
    return std::nullopt;  // [MSG:...], <status>, blank: informational
  }

  // Resuming mid-program: GRBL comes back from any reset (reopening the port, our own abort, an
  // alarm cleared with a reset) in its default modes (G21 G90 G94), so the program's mode lines
  // before the resume point are sent again first; relative feeds run as absolute moves otherwise.
  // They change no position, so sending them twice is harmless; next_line does not move.
  Outcome restore_modes() {
    for (std::size_t j = 0; j < state_.next_line && j < total_; ++j)
      if (is_modal_setup(lines_[j]))
        if (auto stopped = restore_mode(j)) return stopped;
    return std::nullopt;
  }

  Outcome restore_mode(std::size_t j) {
    const long lj = static_cast<long>(state_.next_line);
    const std::string resume = "; resume from line " + std::to_string(state_.next_line + 1) + " again";
    if (!port_.write(lines_[j] + "\n", write_ms_))
      return stop(StreamStatus::disconnected, lj, "the link to " + port_.name() + " dropped while restoring the "
                  "machine's modes (" + quoted(lines_, j) + ") before resuming" + resume);
    const auto deadline = Clock::now() + std::chrono::milliseconds(answer_ms_);
    for (bool ok = false; !ok;) {
      if (wants_abort()) return abort_machine(lj);
      const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(deadline - Clock::now()).count();
      if (left <= 0)
        return stop(StreamStatus::timeout, lj, "no answer to " + quoted(lines_, j) +
                    " while restoring the machine's modes before resuming" + resume);
      GrblAnswer answer;
      const auto got = reader_.next(answer, static_cast<int>(std::min<long long>(left, kSliceMs)));
      if (got == LineReader::Got::lost)
        return stop(StreamStatus::disconnected, lj, "the link to " + port_.name() +
                    " dropped while restoring the machine's modes before resuming" + resume);
      if (got == LineReader::Got::nothing) continue;
      if (answer.kind == Kind::ok) ok = true;
      else if (answer.kind == Kind::error || answer.kind == Kind::alarm)
        return stop(answer.kind == Kind::error ? StreamStatus::error : StreamStatus::alarm, lj,
                    "GRBL answered " + answer.text + " to " + quoted(lines_, j) +
                    " while its modes were restored before resuming (" + kUnlock + ")" + resume);
      else if (answer.kind == Kind::banner)
        return stop(StreamStatus::disconnected, lj, "the controller restarted (its banner '" + answer.text +
                    "' arrived) while its modes were restored before resuming" + resume);
    }
    return std::nullopt;
  }

  // A pause asked for before line li: a feed hold, then nothing sent until the pause ends.
  Outcome hold(long li) {
    if (!port_.write("!", write_ms_))
      return interrupted(StreamStatus::disconnected, li, "the link to " + port_.name() + " dropped while pausing");
    // Nothing is outstanding while paused: every answer is news (a restart, an alarm, a stray ok).
    while (control_->pause.load()) {
      if (wants_abort() || !report()) return abort_machine(li);
      GrblAnswer answer;
      const auto got = reader_.next(answer, kSliceMs * 5);
      if (got == LineReader::Got::lost)
        return interrupted(StreamStatus::disconnected, li, "the link to " + port_.name() + " dropped while paused");
      if (got == LineReader::Got::line)
        if (auto stopped = unexpected(answer, li, "while the stream was paused (feed hold)", true)) return stopped;
    }
    if (!port_.write("~", write_ms_))
      return interrupted(StreamStatus::disconnected, li, "the link to " + port_.name() + " dropped on resuming");
    return std::nullopt;
  }

  Outcome send(std::size_t i) {
    const long li = static_cast<long>(i);
    // Strict accounting: with nothing outstanding, any answer already here is not for a line of
    // ours. An "ok" would otherwise be taken as the next line's acknowledgement (a device that
    // doubles its "ok" would skip a bend on resume), so it stops the stream; next_line stays.
    for (GrblAnswer early; reader_.pending(early) == LineReader::Got::line;)
      if (auto stopped = unexpected(early, li, "before " + quoted(lines_, i) + " was sent", false)) return stopped;
    if (!port_.write(lines_[i] + "\n", write_ms_))
      return interrupted(StreamStatus::disconnected, li,
                         "the link to " + port_.name() + " dropped (or stopped accepting data) before " +
                             quoted(lines_, i) + " was sent");
    ++r_.sent;
    return std::nullopt;
  }

  // Waits for the answer to line i, which was just sent: nothing when it is "ok".
  Outcome await_ok(std::size_t i) {
    const long li = static_cast<long>(i);
    const auto deadline = Clock::now() + std::chrono::milliseconds(answer_ms_);
    while (true) {
      if (wants_abort()) return abort_machine(li);
      const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(deadline - Clock::now()).count();
      if (left <= 0)
        return interrupted(StreamStatus::timeout, li,
                           "no answer to " + quoted(lines_, i) + " within " + std::to_string(answer_ms_) +
                               " ms; it is not acknowledged, so a resume sends it again after you check the machine");
      GrblAnswer answer;
      const auto got = reader_.next(answer, static_cast<int>(std::min<long long>(left, kSliceMs)));
      if (got == LineReader::Got::nothing) continue;
      if (got == LineReader::Got::lost)
        return interrupted(StreamStatus::disconnected, li,
                           "the link to " + port_.name() + " dropped while " + quoted(lines_, i) +
                               " was waiting for its answer");
      if (answer.kind == Kind::ok) return std::nullopt;
      if (answer.kind == Kind::error) {
        r_.code = answer.code;
        if (r_.code == 9)  // "G-code locked out during alarm or jog state"
          return stop(StreamStatus::error, li,
                      "GRBL is locked (an alarm, or a jog in progress) and refused " + quoted(lines_, i) + " with " +
                          answer.text + " (the line was not executed): " + kUnlock + ", then resume from line " +
                          std::to_string(i + 1));
        return stop(StreamStatus::error, li,
                    "GRBL rejected " + quoted(lines_, i) + " with " + answer.text +
                        " (the line was not executed); fix it and resume from line " + std::to_string(i + 1));
      }
      if (answer.kind == Kind::alarm) {
        r_.code = answer.code;
        return interrupted(StreamStatus::alarm, li,
                           "GRBL raised " + answer.text + " while " + quoted(lines_, i) +
                               " was in flight; the machine is locked: " + kUnlock);
      }
      if (answer.kind == Kind::banner)
        return interrupted(StreamStatus::disconnected, li,
                           "the controller restarted while " + quoted(lines_, i) + " was in flight (its banner '" +
                               answer.text + "' arrived): it is back in its default modes and dropped its queued "
                               "moves; the resume restores the program's modes first");
      // Anything else ([MSG:...], <status>, blank) is informational.
    }
  }

  // An "ok" beyond the last line's means some acknowledgement was not for the line it was taken
  // for: the count is not to be trusted (the answer to the last line is already here when a
  // device doubles it).
  StreamResult finish() {
    for (GrblAnswer late; reader_.pending(late) == LineReader::Got::line;)
      if (late.kind == Kind::ok) {
        r_.status = StreamStatus::protocol_error;
        r_.failed_line = static_cast<long>(total_) - 1;
        r_.message = "protocol error: the controller sent an unexpected 'ok' after the last line (more answers than "
                     "lines sent), so its acknowledgements cannot be trusted; check the device and the port settings";
        return r_;
      }
    r_.status = StreamStatus::completed;
    r_.message = "all " + std::to_string(total_) + " lines acknowledged";
    return r_;
  }

  SerialPort& port_;
  const std::vector<std::string>& lines_;
  const MachineProfile& profile_;
  StreamState& state_;
  const ProgressFn& progress_;
  const std::size_t total_;
  const int write_ms_;
  const int answer_ms_;
  StreamControl* control_;
  LineReader reader_;
  StreamResult r_;
};

}  // namespace

void validate(const StreamOptions& o) {
  auto fmt = [](double v) {
    std::ostringstream s;
    s << v;
    return s.str();
  };
  if (!(o.response_timeout > 0.0 && o.response_timeout <= 3600.0))
    throw InputError("response_timeout must be more than 0 and at most 3600 seconds, got " + fmt(o.response_timeout));
  if (!(o.write_timeout > 0.0 && o.write_timeout <= 600.0))
    throw InputError("write_timeout must be more than 0 and at most 600 seconds, got " + fmt(o.write_timeout));
  if (!(o.settle >= 0.0 && o.settle <= 60.0))
    throw InputError("settle must be from 0 to 60 seconds, got " + fmt(o.settle));
}

namespace {

// What both ways of streaming check before anything is sent: the options, the profile, the
// program's lines and where the state would resume.
void validate_stream(const std::vector<std::string>& lines, const MachineProfile& profile, const StreamState& state,
                     const StreamOptions& options) {
  validate(options);
  validate(profile);
  validate_program(lines, profile);
  if (state.next_line > lines.size())
    throw InputError("the stream state's next line (" + std::to_string(state.next_line) +
                     ") is past the program's " + std::to_string(lines.size()) + " lines");
}

}  // namespace

StreamResult stream_program(SerialPort& port, const std::vector<std::string>& lines, const MachineProfile& profile,
                            StreamState& state, const StreamOptions& options, const ProgressFn& progress) {
  validate_stream(lines, profile, state, options);
  state.confirmed = std::min(state.confirmed, state.next_line);
  return Streamer(port, lines, profile, state, options, progress).run();
}

StreamResult stream_program(const std::string& port_name, const std::vector<std::string>& lines,
                            const MachineProfile& profile, StreamState& state, const StreamOptions& options,
                            const ProgressFn& progress) {
  validate_stream(lines, profile, state, options);
  if (options.dry_run) {
    StreamResult r;
    r.status = StreamStatus::dry_run;
    r.last_acknowledged = static_cast<long>(state.next_line) - 1;
    r.message = "dry run: " + std::to_string(lines.size()) + " lines are valid for " + profile.name +
                "; nothing was sent";
    return r;
  }
  SerialPort port(port_name, profile.serial);
  // GRBL restarts when the port opens (DTR); let it boot, then drop its banner.
  const auto settle_end = Clock::now() + std::chrono::milliseconds(to_ms(options.settle));
  while (Clock::now() < settle_end) {
    if (options.control && options.control->abort.load()) break;
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  port.drain_input(200);
  return stream_program(port, lines, profile, state, options, progress);
}

}  // namespace wiresculpt::fab
