#pragma once
// Streaming a program to a GRBL-based bender over a serial port (serial_backend()), with GRBL's
// send-response protocol: one line is sent, then nothing more until GRBL answers that line with
// "ok" (accepted) or "error:N" (rejected, not executed). "ALARM:N" at any time stops the stream.
// Every read and write has a timeout, so nothing here can hang; the full protocol, the resume
// semantics and the realtime characters are described in docs/machine-protocol.md.
//
// Resume: the caller keeps a StreamState between calls. GRBL answers "ok" when it has queued a
// line, not when the line has run; only a sync line (G4 P0 at the end of each bend step, M2) is
// answered after every queued move has run. state.next_line is where the next call starts: after
// each "ok" the line after it; state.confirmed is the line after the last step known complete.
// A stop that can lose queued moves (disconnected, timeout, aborted, alarm, a controller restart,
// a stop in a feed hold) with lines acknowledged past state.confirmed names that step in its
// message (step k, lines a-b, its feed and bend) and sets next_line back to state.confirmed: the
// resume makes the whole step again, after the user has checked the wire. After error:N or a
// protocol error (the queued moves run on) next_line stays at the first unacknowledged line.
#include <atomic>
#include <cstddef>
#include <memory>
#include <string>
#include <vector>

#include "wiresculpt/fab/machine.hpp"
#include "wiresculpt/progress.hpp"

namespace wiresculpt::fab {

struct PortInfo {
  std::string name;         ///< e.g. "/dev/ttyUSB0"
  std::string description;  ///< from the system, e.g. "USB2.0-Serial"
};

/// The serial back end this build has: "libserialport" (Linux), "posix" (termios alone: macOS),
/// "win32" (Windows' own API) or "none" (opening a port throws; WIRESCULPT_SERIAL_BACKEND).
const char* serial_backend();

/// Serial ports the system reports: libserialport's list; the posix back end's /dev/cu.* (macOS)
/// or /dev/ttyUSB*, /dev/ttyACM*; Windows' SERIALCOMM. Pseudo-terminals are not listed.
std::vector<PortInfo> list_ports();

/// An open serial link with timeouts. Opens through the build's back end (serial_backend()); the
/// libserialport one opens a device libserialport does not know (a pseudo-terminal such as a
/// socat or emulator port) as a plain POSIX tty with the same settings, as the posix one opens
/// every port.
class SerialPort {
 public:
  /// Throws InputError naming the port when it cannot be opened or configured.
  SerialPort(const std::string& name, const SerialSettings& settings);
  ~SerialPort();
  SerialPort(const SerialPort&) = delete;
  SerialPort& operator=(const SerialPort&) = delete;

  const std::string& name() const;
  /// Writes all bytes within timeout_ms. Returns false when the link is lost or the time passed.
  bool write(const std::string& bytes, int timeout_ms);
  /// Reads what is available, waiting at most timeout_ms for the first byte.
  /// Returns the number of bytes (0 = nothing in time), or -1 when the link is lost.
  int read(char* buffer, int size, int timeout_ms);
  /// Discards pending input, reading for at most timeout_ms.
  void drain_input(int timeout_ms);

  struct Impl;  // opaque: the back end's handle (libserialport, POSIX descriptor, Windows HANDLE)

 private:
  std::unique_ptr<Impl> impl_;
};

/// What the caller keeps between stream calls (see Resume above).
struct StreamState {
  std::size_t next_line = 0;  ///< the line a stream (or a resume) starts at (0-based); see Resume above
  std::size_t confirmed = 0;  ///< the line after the last step known complete: after the last
                              ///< acknowledged sync line (G4, M2, M30; GRBL answers it only when every
                              ///< queued move has run), or after motionless lines acknowledged with
                              ///< nothing queued (mode lines, $ settings); at most next_line
};

/// Pause / resume / abort from another thread while a stream runs.
struct StreamControl {
  std::atomic<bool> pause{false};  ///< true: after the current line's answer, send '!' (feed hold)
                                   ///< and send nothing more; back to false: send '~' and go on
  std::atomic<bool> abort{false};  ///< true: send '!' then Ctrl-X (soft reset) and stop
};

struct StreamOptions {
  double response_timeout = 30.0;  ///< s to wait for a line's answer, (0, 3600]; default 30 s (a
                                   ///< full planner buffer answers only when a move ends)
  double write_timeout = 2.0;      ///< s to hand a line to the port, (0, 600]; default 2 s
  double settle = 2.0;             ///< s to wait after opening (GRBL restarts when the port opens)
                                   ///< before discarding its banner, [0, 60]; default 2 s
  bool dry_run = false;            ///< only validate the program; no port is opened
  StreamControl* control = nullptr;  ///< optional pause/abort switches (not owned)
};

enum class StreamStatus {
  completed,     ///< every line acknowledged
  dry_run,       ///< validated only
  error,         ///< GRBL answered error:N to failed_line (not executed)
  alarm,         ///< GRBL raised ALARM:N while failed_line was in flight
  disconnected,  ///< the link dropped (or GRBL restarted: its banner arrived) with failed_line in flight (or next)
  timeout,       ///< no answer to failed_line within response_timeout
  aborted,       ///< StreamControl::abort or the progress callback returned false
  protocol_error ///< an answer no line was waiting for ("ok" or "error:N" with nothing outstanding:
                 ///< before a line is sent or while paused): stopped before failed_line was sent;
                 ///< next_line is not advanced by it
};

const char* to_string(StreamStatus status);

/// Throws InputError naming the option outside its range (above; NaN and inf refused).
void validate(const StreamOptions& options);

/// One line the controller sent, as the streamer reads it.
struct GrblAnswer {
  enum class Kind {
    ok,      ///< exactly "ok": acknowledges the one outstanding line
    error,   ///< "error:N": the outstanding line was rejected
    alarm,   ///< "ALARM:N" (or "ALARM"): the machine is locked
    banner,  ///< "Grbl ...": the controller restarted
    info,    ///< anything else ([MSG:...], <status>, blank, noise): ignored
  } kind = Kind::info;
  int code = 0;      ///< N of error:N / ALARM:N (0 when absent or unreadable)
  std::string text;  ///< the line as printable ASCII: "\r" dropped, other bytes outside 0x20-0x7e
                     ///< (invalid UTF-8 included) as \xNN, so a message can always quote it
};

/// Classifies one raw line from the device (without its "\n"); never throws.
GrblAnswer parse_answer(const std::string& raw);

struct StreamResult {
  StreamStatus status = StreamStatus::completed;
  std::size_t sent = 0;            ///< lines sent during this call
  std::size_t acknowledged = 0;    ///< lines acknowledged during this call
  long last_acknowledged = -1;     ///< index of the last acknowledged line overall (-1: none)
  long failed_line = -1;           ///< index of the line the stream stopped at (-1: none)
  int code = 0;                    ///< N of error:N or ALARM:N
  std::string message;             ///< a sentence naming the line (1-based "line N") and what to do
};

/// Throws InputError naming the first bad line (1-based) and why: empty, longer than 79
/// characters, non-printable or realtime characters ('!', '~', '?'), comments (strip them with
/// stream_lines()), or a word letter that is neither a G-code command word (G M F S P N T) nor
/// one of the profile's axis letters. Lines starting with '$' (GRBL settings) are allowed.
void validate_program(const std::vector<std::string>& lines, const MachineProfile& profile);

/// Streams lines[state.next_line ...] on an open port. Validates the whole program first.
/// `progress` gets ("stream", acknowledged fraction) after each answer and while paused; it
/// returning false aborts like StreamControl::abort. Never throws for machine or link trouble:
/// that is the returned status; throws InputError for an invalid program or state.
StreamResult stream_program(SerialPort& port, const std::vector<std::string>& lines, const MachineProfile& profile,
                            StreamState& state, const StreamOptions& options = {}, const ProgressFn& progress = {});

/// Opens `port_name` with the profile's serial settings (unless dry_run), waits options.settle,
/// discards the controller's banner, then streams as above.
StreamResult stream_program(const std::string& port_name, const std::vector<std::string>& lines,
                            const MachineProfile& profile, StreamState& state, const StreamOptions& options = {},
                            const ProgressFn& progress = {});

}  // namespace wiresculpt::fab
