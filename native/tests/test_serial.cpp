// GRBL streaming against an emulator inside the test: a pseudo-terminal pair whose master end is
// answered by a thread that behaves like GRBL (normal, error at line k, alarm, slow, disconnect).
// Every wait is bounded; each case runs well under a second.
#include <catch2/catch.hpp>
#include <pty.h>
#include <poll.h>
#include <termios.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdlib>
#include <fstream>
#include <limits>
#include <mutex>
#include <thread>

#include "wiresculpt/error.hpp"
#include "wiresculpt/fab/bend_program.hpp"
#include "wiresculpt/fab/gcode.hpp"
#include "wiresculpt/fab/serial.hpp"

using namespace wiresculpt;
using namespace wiresculpt::fab;
using Catch::Matchers::Contains;

namespace {

class GrblEmulator {
 public:
  // drop_at: line k is received, never answered, and the cable is pulled (the master end closed).
  // banner_on_hold / alarm_on_hold / ok_on_hold: on a feed hold ('!') the controller restarts (its
  // banner), raises ALARM:3, or sends an 'ok' no line was waiting for. banner_after: line k is
  // answered "ok" and the controller restarts at once (the banner in the same write).
  enum class Mode { normal, error_at, alarm_at, slow, disconnect_after, garbage_at, double_ok_at, double_ok_always,
                    binary_error_at, drop_at, banner_on_hold, alarm_on_hold, ok_on_hold, banner_after };

  explicit GrblEmulator(Mode mode, std::size_t k = 0, int delay_ms = 0) : mode_(mode), k_(k), delay_ms_(delay_ms) {
    termios raw{};
    ::cfmakeraw(&raw);
    char name[256] = {};
    REQUIRE(::openpty(&master_, &slave_, name, &raw, nullptr) == 0);
    path_ = name;
    send("\r\nGrbl 1.1h ['$' for help]\r\n");  // what GRBL prints when the port opens
    thread_ = std::thread([this] { run(); });
  }
  ~GrblEmulator() {
    stop_ = true;
    if (thread_.joinable()) thread_.join();
    if (master_ >= 0) ::close(master_);
    if (slave_ >= 0) ::close(slave_);
  }
  const std::string& path() const { return path_; }
  std::vector<std::string> received() { std::lock_guard<std::mutex> g(mu_); return received_; }
  std::vector<std::string> acknowledged() { std::lock_guard<std::mutex> g(mu_); return acknowledged_; }
  std::string realtime() { std::lock_guard<std::mutex> g(mu_); return realtime_; }

 private:
  void send(const std::string& s) {
    if (master_ >= 0 && ::write(master_, s.data(), s.size()) < 0) { /* the test sees the missing answer */ }
  }

  void answer(const std::string& line) {
    std::size_t index;
    {
      std::lock_guard<std::mutex> g(mu_);
      index = received_.size();
      received_.push_back(line);
    }
    if (mode_ == Mode::drop_at && index == k_) {
      ::close(master_);  // the cable is pulled while this line waits for its answer
      master_ = -1;
      stop_ = true;
      return;
    }
    if (locked_) return send("error:9\r\n");  // GRBL refuses everything while in alarm
    if (mode_ == Mode::error_at && index == k_) return send("error:20\r\n");
    if (mode_ == Mode::alarm_at && index == k_) {
      locked_ = true;
      return send("ALARM:1\r\n");
    }
    if (mode_ == Mode::garbage_at && index == k_)  // line noise: near-misses of "ok", binary junk
      return send("okay\r\nerror\r\n\x01\xff\xfeok?\r\nOK \r\nerror:\r\n");
    if (mode_ == Mode::binary_error_at && index == k_)  // invalid UTF-8 in the answer
      return send("error:\xff\xfe" "9\r\n");
    if (mode_ == Mode::slow) std::this_thread::sleep_for(std::chrono::milliseconds(delay_ms_));
    {
      std::lock_guard<std::mutex> g(mu_);
      acknowledged_.push_back(line);
    }
    // An informational line first: the streamer must skip it. A doubled "ok" comes in one write,
    // as a device that echoes its answer twice sends it.
    const bool twice = (mode_ == Mode::double_ok_at && index == k_) || mode_ == Mode::double_ok_always;
    if (mode_ == Mode::banner_after && index == k_) return send("[MSG:busy]\r\nok\r\n\r\nGrbl 1.1h ['$' for help]\r\n");
    send(twice ? "[MSG:busy]\r\nok\r\nok\r\n" : "[MSG:busy]\r\nok\r\n");
    if (mode_ == Mode::disconnect_after && index + 1 == k_) {
      std::this_thread::sleep_for(std::chrono::milliseconds(100));  // the ok reaches the streamer
      ::close(master_);  // the cable is pulled: the slave end hangs up
      master_ = -1;
      stop_ = true;
    }
  }

  void on_hold() {
    if (mode_ == Mode::banner_on_hold) send("\r\nGrbl 1.1h ['$' for help]\r\n");  // reset: modes and queue lost
    if (mode_ == Mode::alarm_on_hold) {
      locked_ = true;
      send("ALARM:3\r\n");
    }
    if (mode_ == Mode::ok_on_hold) send("ok\r\n");
  }

  void run() {
    std::string buffer;
    while (!stop_) {
      pollfd p{master_, POLLIN, 0};
      if (::poll(&p, 1, 10) <= 0 || !(p.revents & POLLIN)) continue;
      char buf[256];
      const ssize_t n = ::read(master_, buf, sizeof buf);
      if (n <= 0) continue;
      for (ssize_t i = 0; i < n && !stop_; ++i) {
        const char c = buf[i];
        if (c == '!' || c == '~' || c == '?' || c == '\x18') {
          {
            std::lock_guard<std::mutex> g(mu_);
            realtime_ += c;
          }
          if (c == '!') on_hold();
        } else if (c == '\n') {
          if (!buffer.empty() && buffer.back() == '\r') buffer.pop_back();
          answer(buffer);
          buffer.clear();
        } else {
          buffer += c;
        }
      }
    }
  }

  Mode mode_;
  std::size_t k_;
  int delay_ms_;
  int master_ = -1, slave_ = -1;
  std::string path_;
  std::thread thread_;
  std::atomic<bool> stop_{false};
  bool locked_ = false;
  std::mutex mu_;
  std::vector<std::string> received_, acknowledged_;
  std::string realtime_;
};

std::vector<std::string> program_lines() {
  const double a = 0.04;
  const BendProgram p = make_bend_program(Polyline2{{0, 0}, {a, 0}, {a, a}, {0, a}, {0, 0}}, MachineProfile{});
  return stream_lines(gcode_program(p, MachineProfile{}, GcodeInfo{"test", "steel", true}));
}

StreamOptions quick() {
  StreamOptions o;
  o.settle = 0.05;
  o.response_timeout = 1.0;
  o.write_timeout = 0.5;
  return o;
}

double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

}  // namespace

TEST_CASE("serial: a full program is streamed, each line acknowledged once", "[fab][serial]") {
  const auto lines = program_lines();
  REQUIRE(lines.size() > 10);
  GrblEmulator grbl(GrblEmulator::Mode::normal);
  StreamState state;
  std::vector<double> fractions;
  const auto r = stream_program(grbl.path(), lines, MachineProfile{}, state, quick(),
                                [&](std::string_view, double f) { fractions.push_back(f); return true; });
  CHECK(r.status == StreamStatus::completed);
  CHECK(r.sent == lines.size());
  CHECK(r.acknowledged == lines.size());
  CHECK(r.last_acknowledged == static_cast<long>(lines.size()) - 1);
  CHECK(state.next_line == lines.size());
  CHECK(grbl.received() == lines);
  CHECK(grbl.acknowledged() == lines);
  REQUIRE(fractions.size() == lines.size() + 1);
  CHECK(fractions.front() == 0.0);
  CHECK(fractions.back() == 1.0);
}

TEST_CASE("serial: error:N at line k stops at k", "[fab][serial]") {
  const auto lines = program_lines();
  const std::size_t k = 4;
  GrblEmulator grbl(GrblEmulator::Mode::error_at, k);
  StreamState state;
  const auto r = stream_program(grbl.path(), lines, MachineProfile{}, state, quick());
  CHECK(r.status == StreamStatus::error);
  CHECK(r.code == 20);
  CHECK(r.failed_line == static_cast<long>(k));
  CHECK(r.last_acknowledged == static_cast<long>(k) - 1);
  CHECK(state.next_line == k);
  CHECK(grbl.received().size() == k + 1);  // nothing was sent after the rejected line
  CHECK_THAT(r.message, Contains("line 5") && Contains("error:20"));
}

TEST_CASE("serial: ALARM stops the stream", "[fab][serial]") {
  const auto lines = program_lines();
  GrblEmulator grbl(GrblEmulator::Mode::alarm_at, 2);
  StreamState state;
  const auto r = stream_program(grbl.path(), lines, MachineProfile{}, state, quick());
  CHECK(r.status == StreamStatus::alarm);
  CHECK(r.code == 1);
  CHECK(r.failed_line == 2);
  CHECK(state.next_line == 2);
  CHECK(grbl.received().size() == 3);
  CHECK_THAT(r.message, Contains("ALARM:1") && Contains("line 3"));
  CHECK_THAT(r.message, Contains("$X") && Contains("$H"));  // what unlocks the machine
  // resuming while GRBL is still locked: every line gets error:9, and the message says how to unlock
  const auto again = stream_program(grbl.path(), lines, MachineProfile{}, state, quick());
  CHECK(again.status == StreamStatus::error);
  CHECK_THAT(again.message, Contains("error:9") && Contains("$X") && Contains("$H"));
  CHECK(state.next_line == 2);  // nothing more was acknowledged
}

TEST_CASE("serial: slow answers are waited for, missing answers time out", "[fab][serial]") {
  const auto lines = program_lines();
  SECTION("slow but within the timeout") {
    GrblEmulator grbl(GrblEmulator::Mode::slow, 0, 15);
    StreamState state;
    const auto r = stream_program(grbl.path(), std::vector<std::string>(lines.begin(), lines.begin() + 6),
                                  MachineProfile{}, state, quick());
    CHECK(r.status == StreamStatus::completed);
    CHECK(state.next_line == 6);
  }
  SECTION("slower than the timeout") {
    GrblEmulator grbl(GrblEmulator::Mode::slow, 0, 400);
    StreamState state;
    StreamOptions o = quick();
    o.response_timeout = 0.1;
    const auto t0 = std::chrono::steady_clock::now();
    const auto r = stream_program(grbl.path(), lines, MachineProfile{}, state, o);
    CHECK(seconds_since(t0) < 1.0);
    CHECK(r.status == StreamStatus::timeout);
    CHECK(r.failed_line == 0);
    CHECK(state.next_line == 0);
    CHECK_THAT(r.message, Contains("line 1"));
  }
}

TEST_CASE("serial: a device answering garbage acknowledges nothing and the stream stops there", "[fab][serial]") {
  const auto lines = program_lines();
  const std::size_t k = 3;
  GrblEmulator grbl(GrblEmulator::Mode::garbage_at, k);
  StreamState state;
  StreamOptions o = quick();
  o.response_timeout = 0.3;
  const auto r = stream_program(grbl.path(), lines, MachineProfile{}, state, o);
  CHECK(r.status != StreamStatus::completed);
  CHECK(r.failed_line == k);
  CHECK(state.next_line == k);  // lines 0..k-1 acknowledged, line k not
  CHECK(grbl.acknowledged().size() == k);
  CHECK_FALSE(r.message.empty());
}

TEST_CASE("serial: after a disconnect mid-step, a resume restores the modes, then makes the step again from its "
          "first line", "[fab][serial]") {
  const auto lines = program_lines();
  const std::size_t k = 5;  // step 1 is lines 3-6 (0-based): its feed and bend acknowledged, line 5 not
  REQUIRE(lines[3].rfind("G1 X", 0) == 0);
  REQUIRE(lines[6] == "G4 P0");
  StreamState state;
  std::vector<std::string> received, acknowledged;
  {
    GrblEmulator grbl(GrblEmulator::Mode::disconnect_after, k);
    const auto t0 = std::chrono::steady_clock::now();
    const auto r = stream_program(grbl.path(), lines, MachineProfile{}, state, quick());
    CHECK(seconds_since(t0) < 1.5);
    CHECK(r.status == StreamStatus::disconnected);
    CHECK(r.last_acknowledged == static_cast<long>(k) - 1);
    CHECK(r.failed_line == static_cast<long>(k));
    CHECK(state.next_line == 3);  // the step's first line: its queued moves may be lost
    CHECK(state.confirmed == 3);  // the mode lines moved nothing: done
    CHECK_THAT(r.message, Contains("step 1 (lines 4-7") && Contains("restarts the step from line 4"));
    received = grbl.received();
    acknowledged = grbl.acknowledged();
  }
  CHECK(acknowledged.size() == k);
  // The program's mode lines (units, relative distances, feed mode) come first in the program;
  // the restarted machine is back in its defaults and must get them again before line k.
  std::vector<std::string> modes;
  for (std::size_t j = 0; j < k; ++j)
    if (lines[j] == "G21" || lines[j] == "G91" || lines[j] == "G94") modes.push_back(lines[j]);
  REQUIRE(modes == std::vector<std::string>{"G21", "G91", "G94"});
  {
    GrblEmulator grbl(GrblEmulator::Mode::normal);  // the machine again, on a new device name
    const auto r = stream_program(grbl.path(), lines, MachineProfile{}, state, quick());
    CHECK(r.status == StreamStatus::completed);
    CHECK(r.sent == lines.size() - 3);
    auto more_received = grbl.received(), more_acknowledged = grbl.acknowledged();
    REQUIRE(more_received.size() >= modes.size());
    CHECK(std::vector<std::string>(more_received.begin(), more_received.begin() + 3) == modes);
    more_received.erase(more_received.begin(), more_received.begin() + 3);
    more_acknowledged.erase(more_acknowledged.begin(), more_acknowledged.begin() + 3);
    received.insert(received.end(), more_received.begin(), more_received.end());
    acknowledged.insert(acknowledged.end(), more_acknowledged.begin(), more_acknowledged.end());
  }
  CHECK(state.next_line == lines.size());
  // Over the two links: lines 1-5, then step 1 from its first line again (line 4 on), none skipped.
  std::vector<std::string> expected(lines.begin(), lines.begin() + static_cast<long>(k));
  expected.insert(expected.end(), lines.begin() + 3, lines.end());
  CHECK(acknowledged == expected);
  CHECK(received == expected);  // line 6 never reached the first device
}

TEST_CASE("serial: pause, resume and abort", "[fab][serial]") {
  const auto lines = program_lines();
  SECTION("pause holds the stream, resume continues it") {
    GrblEmulator grbl(GrblEmulator::Mode::normal);
    StreamControl control;
    StreamState state;
    StreamOptions o = quick();
    o.control = &control;
    std::thread releaser;
    std::size_t received_while_paused = 0;
    const auto r = stream_program(grbl.path(), lines, MachineProfile{}, state, o, [&](std::string_view, double) {
      if (state.next_line == 3 && !releaser.joinable()) {
        control.pause = true;
        releaser = std::thread([&] {
          std::this_thread::sleep_for(std::chrono::milliseconds(150));
          received_while_paused = grbl.received().size();
          control.pause = false;
        });
      }
      return true;
    });
    releaser.join();
    CHECK(r.status == StreamStatus::completed);
    CHECK(received_while_paused == 3);
    CHECK(grbl.realtime() == "!~");
    CHECK(grbl.acknowledged() == lines);
  }
  SECTION("the progress callback aborts") {
    GrblEmulator grbl(GrblEmulator::Mode::normal);
    StreamState state;
    const auto r = stream_program(grbl.path(), lines, MachineProfile{}, state, quick(),
                                  [&](std::string_view, double f) { return f < 0.5; });
    CHECK(r.status == StreamStatus::aborted);
    // The soft reset drops the queued moves: the resume starts at the first line after the last
    // step known complete (its G4 P0 acknowledged).
    CHECK(grbl.acknowledged().size() >= lines.size() / 2);
    CHECK(state.next_line == state.confirmed);
    CHECK(state.next_line <= grbl.acknowledged().size());
    REQUIRE(state.next_line > 0);
    CHECK(lines[state.next_line - 1] == "G4 P0");
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
    CHECK(grbl.realtime() == "!\x18");
  }
}

TEST_CASE("serial: dry run, bad programs and bad ports", "[fab][serial]") {
  const auto lines = program_lines();
  StreamState state;
  StreamOptions o = quick();
  o.dry_run = true;
  const auto r = stream_program("/dev/does-not-exist", lines, MachineProfile{}, state, o);
  CHECK(r.status == StreamStatus::dry_run);
  CHECK(state.next_line == 0);
  auto bad = lines;
  bad[6] = "G1 Q3";
  CHECK_THROWS_WITH(stream_program("/dev/does-not-exist", bad, MachineProfile{}, state, o), Contains("line 7"));
  o.dry_run = false;
  CHECK_THROWS_WITH(stream_program("/dev/does-not-exist", lines, MachineProfile{}, state, o),
                    Contains("/dev/does-not-exist"));
  state.next_line = lines.size() + 1;
  CHECK_THROWS_WITH(stream_program("/dev/does-not-exist", lines, MachineProfile{}, state, o), Contains("past"));
  CHECK_NOTHROW(list_ports());
}

TEST_CASE("serial: 'ok ok' to one line is a protocol error before the next line: the resume sends that line",
          "[fab][serial][robustness]") {
  // Before strict accounting, the second "ok" acknowledged line k+1 the moment it was sent: a
  // resume after any later stop would have skipped it (a bend never made).
  const auto lines = program_lines();
  const std::size_t k = 3;
  StreamState state;
  {
    GrblEmulator grbl(GrblEmulator::Mode::double_ok_at, k);
    const auto r = stream_program(grbl.path(), lines, MachineProfile{}, state, quick());
    CHECK(r.status == StreamStatus::protocol_error);
    CHECK(std::string(to_string(r.status)) == "protocol_error");
    CHECK(r.failed_line == static_cast<long>(k) + 1);
    CHECK(r.last_acknowledged == static_cast<long>(k));
    CHECK(state.next_line == k + 1);
    CHECK(grbl.received().size() == k + 1);  // line k+1 was never sent
    CHECK_THAT(r.message, Contains("unexpected 'ok'") && Contains("resume from line " + std::to_string(k + 2)));
  }
  GrblEmulator again(GrblEmulator::Mode::normal);
  const auto r = stream_program(again.path(), lines, MachineProfile{}, state, quick());
  CHECK(r.status == StreamStatus::completed);
  const auto got = again.received();
  REQUIRE(got.size() >= lines.size() - (k + 1));
  // After the restored mode lines, exactly the lines from k+1 on, each once.
  CHECK(std::vector<std::string>(got.end() - static_cast<long>(lines.size() - (k + 1)), got.end()) ==
        std::vector<std::string>(lines.begin() + static_cast<long>(k + 1), lines.end()));
}

TEST_CASE("serial: a device that always doubles its 'ok' never gets 'all lines acknowledged'",
          "[fab][serial][robustness]") {
  const auto lines = program_lines();
  GrblEmulator grbl(GrblEmulator::Mode::double_ok_always);
  StreamState state;
  const auto r = stream_program(grbl.path(), lines, MachineProfile{}, state, quick());
  CHECK(r.status == StreamStatus::protocol_error);
  CHECK(r.failed_line == 1);
  CHECK(state.next_line == 1);
  CHECK(grbl.received().size() == 1);
}

TEST_CASE("serial: an error: line with invalid UTF-8 is a status with a printable message", "[fab][serial][robustness]") {
  const auto lines = program_lines();
  GrblEmulator grbl(GrblEmulator::Mode::binary_error_at, 2);
  StreamState state;
  const auto r = stream_program(grbl.path(), lines, MachineProfile{}, state, quick());
  CHECK(r.status == StreamStatus::error);
  CHECK(r.failed_line == 2);
  CHECK_THAT(r.message, Contains("error:\\xff\\xfe9"));
  for (char c : r.message) CHECK(static_cast<unsigned char>(c) < 0x80);
}

TEST_CASE("serial: a port held by a stream refuses a second one, naming the holder", "[fab][serial][robustness]") {
  const auto lines = program_lines();
  GrblEmulator grbl(GrblEmulator::Mode::normal);
  StreamState state;
  {
    SerialPort holder(grbl.path(), MachineProfile{}.serial);
    CHECK_THROWS_WITH(stream_program(grbl.path(), lines, MachineProfile{}, state, quick()),
                      Contains("is in use by process " + std::to_string(::getpid())) &&
                          Contains("stop that stream first"));
    CHECK(grbl.received().empty());  // nothing of the second stream reached the device
    CHECK(state.next_line == 0);
  }
  const auto r = stream_program(grbl.path(), lines, MachineProfile{}, state, quick());  // released
  CHECK(r.status == StreamStatus::completed);
  CHECK(grbl.received() == lines);
}

TEST_CASE("serial: timeouts and settle outside their ranges are refused on entry", "[fab][serial][robustness]") {
  const auto lines = program_lines();
  StreamState state;
  const double inf = std::numeric_limits<double>::infinity();
  StreamOptions o = quick();
  o.settle = inf;  // unchecked, a wait with no end
  CHECK_THROWS_WITH(stream_program("/dev/null-port", lines, MachineProfile{}, state, o),
                    "settle must be from 0 to 60 seconds, got inf");
  o = quick();
  o.response_timeout = std::numeric_limits<double>::quiet_NaN();
  CHECK_THROWS_WITH(stream_program("/dev/null-port", lines, MachineProfile{}, state, o),
                    "response_timeout must be more than 0 and at most 3600 seconds, got nan");
  o = quick();
  o.write_timeout = 0.0;
  CHECK_THROWS_WITH(stream_program("/dev/null-port", lines, MachineProfile{}, state, o),
                    "write_timeout must be more than 0 and at most 600 seconds, got 0");
}

TEST_CASE("serial: parse_answer classifies GRBL's lines: device bytes become printable text", "[fab][serial]") {
  using K = GrblAnswer::Kind;
  CHECK(parse_answer("ok").kind == K::ok);
  CHECK(parse_answer("ok\r").kind == K::ok);
  for (const char* not_ok : {"OK", "okay", "ok ", " ok", "ok?", ""}) CHECK(parse_answer(not_ok).kind == K::info);
  const GrblAnswer e = parse_answer("error:20\r");
  CHECK((e.kind == K::error && e.code == 20 && e.text == "error:20"));
  const GrblAnswer bad = parse_answer("error:\xff\xfe" "9");
  CHECK((bad.kind == K::error && bad.code == 0 && bad.text == "error:\\xff\\xfe9"));
  CHECK(parse_answer("error:99999999999999").code == 0);
  const GrblAnswer alarm = parse_answer("ALARM:1");
  CHECK((alarm.kind == K::alarm && alarm.code == 1));
  CHECK(parse_answer("Grbl 1.1h ['$' for help]").kind == K::banner);
  CHECK(parse_answer("[MSG:busy]").kind == K::info);
  CHECK(parse_answer(std::string("a\0b\x7f", 4)).text == "a\\x00b\\x7f");
}

namespace {

std::vector<std::size_t> sync_lines(const std::vector<std::string>& lines) {
  std::vector<std::size_t> out;
  for (std::size_t j = 0; j < lines.size(); ++j)
    if (lines[j] == "G4 P0") out.push_back(j);
  return out;
}

}  // namespace

TEST_CASE("serial: a link dropped while a step's G4 P0 waits names the step in doubt: the resume sends the whole "
          "step again", "[fab][serial][robustness]") {
  // GRBL answers "ok" when a line is queued: step 2's feed and bend lines were all acknowledged at
  // once, and only its G4 P0 waits for the moves. Reopening the port resets the controller in the
  // middle of them, so the step may be half made: the resume must start at the step's first line.
  const auto lines = program_lines();
  const auto syncs = sync_lines(lines);
  REQUIRE(syncs.size() >= 3);
  const std::size_t first = syncs[0] + 1, end = syncs[1];  // step 2: lines first..end (0-based)
  REQUIRE(end - first >= 3);                               // a feed and a bend before its G4 P0
  StreamState state;
  {
    GrblEmulator grbl(GrblEmulator::Mode::drop_at, end);
    const auto r = stream_program(grbl.path(), lines, MachineProfile{}, state, quick());
    CHECK(r.status == StreamStatus::disconnected);
    CHECK(r.failed_line == static_cast<long>(end));
    CHECK(r.last_acknowledged == static_cast<long>(end) - 1);  // the step's moves were queued ...
    CHECK(state.confirmed == first);                           // ... but only step 1 is known made
    CHECK(state.next_line == first);                           // the resume restarts step 2
    CHECK(grbl.received() == std::vector<std::string>(lines.begin(), lines.begin() + static_cast<long>(end) + 1));
    CHECK_THAT(r.message, Contains("step 2") &&
                              Contains("lines " + std::to_string(first + 1) + "-" + std::to_string(end + 1)) &&
                              Contains("feed 40.000 mm") && Contains("bend 90.000 deg") &&
                              Contains("check the wire") && Contains("from line " + std::to_string(first + 1)));
    CHECK_THAT(r.message, !Contains("from line " + std::to_string(end + 1)));
  }
  GrblEmulator again(GrblEmulator::Mode::normal);  // the machine again, on a new device name
  const auto r = stream_program(again.path(), lines, MachineProfile{}, state, quick());
  CHECK(r.status == StreamStatus::completed);
  CHECK(r.sent == lines.size() - first);
  CHECK(state.confirmed == lines.size());
  // The restored mode lines, then every line of step 2 again (its feed, bend and G4 P0), then the rest.
  std::vector<std::string> expected{"G21", "G91", "G94"};
  expected.insert(expected.end(), lines.begin() + static_cast<long>(first), lines.end());
  CHECK(again.received() == expected);
}

TEST_CASE("serial: a controller restart, an ALARM or a stray 'ok' while paused stops the stream",
          "[fab][serial][robustness]") {
  // Paused after step 1's feed (line 4) was acknowledged, in the middle of the step.
  const auto lines = program_lines();
  const std::size_t at = 4;
  REQUIRE(lines[3].rfind("G1 X", 0) == 0);
  REQUIRE(lines[6] == "G4 P0");
  auto paused_run = [&](GrblEmulator::Mode mode, StreamState& state, std::size_t& received) {
    GrblEmulator grbl(mode);
    StreamControl control;
    StreamOptions o = quick();
    o.control = &control;
    std::thread releaser;
    const auto r = stream_program(grbl.path(), lines, MachineProfile{}, state, o, [&](std::string_view, double) {
      if (state.next_line == at && !releaser.joinable()) {
        control.pause = true;
        // A streamer that ignored the answers while paused would wait for this forever: release it
        // later so that the test ends (and fails) instead of hanging.
        releaser = std::thread([&] {
          std::this_thread::sleep_for(std::chrono::milliseconds(300));
          control.pause = false;
        });
      }
      return true;
    });
    releaser.join();
    received = grbl.received().size();
    return r;
  };
  StreamState state;
  std::size_t received = 0;
  SECTION("a banner: the controller restarted (modes and queued moves lost)") {
    const auto r = paused_run(GrblEmulator::Mode::banner_on_hold, state, received);
    CHECK(r.status == StreamStatus::disconnected);
    CHECK(received == at);  // the next line was never sent as if nothing happened
    CHECK(r.failed_line == static_cast<long>(at));
    CHECK_THAT(r.message, Contains("restarted") && Contains("step 1") && Contains("check the wire"));
    CHECK(state.next_line == 3);  // step 1 was in doubt: the resume restarts it
    CHECK(state.confirmed == 3);
  }
  SECTION("an ALARM") {
    const auto r = paused_run(GrblEmulator::Mode::alarm_on_hold, state, received);
    CHECK(r.status == StreamStatus::alarm);
    CHECK(r.code == 3);
    CHECK(received == at);
    CHECK_THAT(r.message, Contains("ALARM:3") && Contains("$X") && Contains("step 1"));
    CHECK(state.next_line == 3);  // an alarm loses the queued moves: step 1 is restarted
  }
  SECTION("an 'ok' no line was waiting for") {
    const auto r = paused_run(GrblEmulator::Mode::ok_on_hold, state, received);
    CHECK(r.status == StreamStatus::protocol_error);
    CHECK(received == at);
    CHECK_THAT(r.message, Contains("unexpected 'ok'") && Contains("step 1"));
    // The stream stopped in a feed hold: the step's queued moves have not run, and the resume
    // (reopening the port resets the controller) restarts the step.
    CHECK(state.next_line == 3);
  }
}

TEST_CASE("serial: a lock file that is a symbolic link is not followed", "[fab][serial][robustness]") {
  // Another user's link at the lock path would otherwise make the stream truncate and write the
  // file it points to.
  GrblEmulator grbl(GrblEmulator::Mode::normal);
  char dir_template[] = "/tmp/wiresculpt-lock-XXXXXX";
  REQUIRE(::mkdtemp(dir_template) != nullptr);
  const std::string dir = dir_template;
  const char* before = std::getenv("WIRESCULPT_LOCK_DIR");
  const std::string saved = before ? before : "";
  ::setenv("WIRESCULPT_LOCK_DIR", dir.c_str(), 1);
  char resolved[4096];
  REQUIRE(::realpath(grbl.path().c_str(), resolved) != nullptr);
  std::string device = resolved;
  if (device.rfind("/dev/", 0) == 0) device.erase(0, 5);
  std::replace(device.begin(), device.end(), '/', '_');
  const std::string target = dir + "/victim", link = dir + "/LCK.." + device;
  { std::ofstream(target) << "keep\n"; }
  REQUIRE(::symlink(target.c_str(), link.c_str()) == 0);
  CHECK_THROWS_WITH(SerialPort(grbl.path(), MachineProfile{}.serial), Contains("lock file " + link));
  std::string content;
  {
    std::ifstream in(target);
    std::getline(in, content);
  }
  CHECK(content == "keep");
  if (before) ::setenv("WIRESCULPT_LOCK_DIR", saved.c_str(), 1);
  else ::unsetenv("WIRESCULPT_LOCK_DIR");
  ::unlink(link.c_str());
  ::unlink(target.c_str());
  ::rmdir(dir.c_str());
}

TEST_CASE("serial: a controller restart seen before the next line is sent stops the stream", "[fab][serial][robustness]") {
  // The restarted GRBL is back in G90 with an empty queue: sending the next relative line as if
  // nothing happened would run it as an absolute move.
  const auto lines = program_lines();
  const std::size_t k = 4;  // step 1's bend line is answered, then the banner arrives
  GrblEmulator grbl(GrblEmulator::Mode::banner_after, k);
  StreamState state;
  const auto r = stream_program(grbl.path(), lines, MachineProfile{}, state, quick());
  CHECK(r.status == StreamStatus::disconnected);
  CHECK(r.failed_line == static_cast<long>(k) + 1);
  CHECK(grbl.received().size() == k + 1);  // line k+1 was never sent
  CHECK_THAT(r.message, Contains("restarted") && Contains("step 1") && Contains("from line 4"));
  CHECK(state.next_line == 3);  // step 1's queued feed and bend are lost: the resume makes it again
}

TEST_CASE("serial: the Windows stage's five streams give its outcomes on this build's back end", "[fab][serial]") {
  // blender_tests/windows/test_windows.py's cases and expected outcomes (globe_design.SERIAL_PROGRAM),
  // here on the back end of this binary: libserialport's pty path, or the posix one (macOS's).
  const std::vector<std::string> program{"G21", "G91", "G1 X1 F100", "G4 P0", "G1 Y-2 F100", "G4 P0", "M2"};
  const MachineProfile profile;
  {
    GrblEmulator grbl(GrblEmulator::Mode::normal);
    StreamState state;
    const auto r = stream_program(grbl.path(), program, profile, state, quick());
    CHECK(r.status == StreamStatus::completed);
    CHECK((r.sent == 7 && r.acknowledged == 7 && r.failed_line == -1));
    CHECK((state.next_line == 7 && state.confirmed == 7));
    CHECK(grbl.received() == program);
  }
  {
    GrblEmulator grbl(GrblEmulator::Mode::error_at, 2);  // error:20 to the 3rd line
    StreamState state;
    const auto r = stream_program(grbl.path(), program, profile, state, quick());
    CHECK(r.status == StreamStatus::error);
    CHECK((r.code == 20 && r.failed_line == 2 && r.acknowledged == 2));
    CHECK(state.next_line == 2);
    CHECK(grbl.received() == std::vector<std::string>{"G21", "G91", "G1 X1 F100"});
  }
  {
    GrblEmulator grbl(GrblEmulator::Mode::drop_at, 2);  // the cable goes with the 3rd line in flight
    StreamState state;
    const auto r = stream_program(grbl.path(), program, profile, state, quick());
    CHECK(r.status == StreamStatus::disconnected);
    CHECK((r.failed_line == 2 && r.acknowledged == 2));
    CHECK((state.next_line == 2 && state.confirmed == 2));
    CHECK(grbl.received() == std::vector<std::string>{"G21", "G91", "G1 X1 F100"});
  }
  {
    GrblEmulator grbl(GrblEmulator::Mode::normal);
    SerialPort holder(grbl.path(), profile.serial);
    StreamState state;
    CHECK_THROWS_WITH(stream_program(grbl.path(), program, profile, state, quick()),
                      Contains("serial port '" + grbl.path() + "' is in use by "));
    CHECK(grbl.received().empty());
  }
  StreamState state;
  CHECK_THROWS_WITH(stream_program("/dev/ttyUSB-wiresculpt-absent", program, profile, state, quick()),
                    Contains("could not open serial port '/dev/ttyUSB-wiresculpt-absent': no such port"));
}
