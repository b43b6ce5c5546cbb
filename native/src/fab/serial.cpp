#include "wiresculpt/fab/serial.hpp"

#ifndef WIRESCULPT_NO_SERIAL_PORT  // the port itself (else serial_none.cpp); the protocol always
#include <fcntl.h>
#include <libserialport.h>
#include <poll.h>
#include <sys/file.h>
#include <sys/ioctl.h>
#include <sys/stat.h>
#include <termios.h>
#include <unistd.h>
#endif

#include <cstdlib>
#include <fstream>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <optional>
#include <sstream>
#include <string>
#include <thread>

#include "wiresculpt/error.hpp"

namespace wiresculpt::fab {

#ifndef WIRESCULPT_NO_SERIAL_PORT
// ---------------------------------------------------------------------------------------------
// Listing
// ---------------------------------------------------------------------------------------------

std::vector<PortInfo> list_ports() {
  std::vector<PortInfo> out;
  sp_port** ports = nullptr;
  if (sp_list_ports(&ports) != SP_OK) return out;  // no serial subsystem: no ports
  for (int i = 0; ports[i]; ++i) {
    PortInfo info;
    if (const char* n = sp_get_port_name(ports[i])) info.name = n;
    if (const char* d = sp_get_port_description(ports[i])) info.description = d;
    out.push_back(info);
  }
  sp_free_port_list(ports);
  return out;
}

// ---------------------------------------------------------------------------------------------
// The port: libserialport, or a plain POSIX tty for devices libserialport does not know (ptys)
// ---------------------------------------------------------------------------------------------

struct SerialPort::Impl {
  std::string name;
  sp_port* sp = nullptr;
  int fd = -1;
  int lock_fd = -1;        // the lock file, flock()ed while the port is open
  std::string lock_path;

  ~Impl() {
    // Exclusive mode outlives our descriptor while anyone else keeps the tty open: clear it.
    int handle = fd;
    if (sp && sp_get_port_handle(sp, &handle) != SP_OK) handle = -1;
    if (handle >= 0) ::ioctl(handle, TIOCNXCL);
    if (sp) {
      sp_close(sp);
      sp_free_port(sp);
    }
    if (fd >= 0) ::close(fd);
    if (lock_fd >= 0) {
      ::unlink(lock_path.c_str());  // while still locked: nobody else holds this file
      ::close(lock_fd);
    }
  }
};

namespace {

[[noreturn]] void open_failed(const std::string& name, const std::string& why) {
  throw InputError("could not open serial port '" + name + "': " + why);
}

// The lock file of a port: LCK..<device> (UUCP's name; "/" after /dev/ becomes "_") in
// $WIRESCULPT_LOCK_DIR, else /var/lock when writable, else /tmp. Held with flock(), which the
// system releases when the process ends, so a crash leaves no stale lock.
std::string lock_path_for(const std::string& port) {
  std::string device = port;
  char resolved[4096];
  if (::realpath(port.c_str(), resolved)) device = resolved;
  if (device.rfind("/dev/", 0) == 0) device.erase(0, 5);
  std::replace(device.begin(), device.end(), '/', '_');
  std::string dir;
  if (const char* env = std::getenv("WIRESCULPT_LOCK_DIR"); env && *env) dir = env;
  else if (::access("/var/lock", W_OK) == 0) dir = "/var/lock";
  else dir = "/tmp";
  return dir + "/LCK.." + device;
}

// Who holds the lock file: "process 1234 (blender)", from the pid written in it.
std::string holder_of(const std::string& path) {
  std::ifstream in(path);
  long pid = 0;
  if (!(in >> pid) || pid <= 0) return "another program";
  std::string who = "process " + std::to_string(pid);
  std::ifstream comm("/proc/" + std::to_string(pid) + "/comm");
  std::string name;
  if (std::getline(comm, name) && !name.empty()) who += " (" + name + ")";
  if (pid == static_cast<long>(::getpid())) who += ", this program";
  return who;
}

void take_lock(SerialPort::Impl& impl) {
  impl.lock_path = lock_path_for(impl.name);
  for (int attempt = 0; attempt < 5; ++attempt) {
    const int fd = ::open(impl.lock_path.c_str(), O_RDWR | O_CREAT | O_CLOEXEC | O_NOFOLLOW, 0644);
    if (fd < 0)
      open_failed(impl.name, "cannot create its lock file " + impl.lock_path + ": " + std::strerror(errno));
    if (::flock(fd, LOCK_EX | LOCK_NB) != 0) {
      ::close(fd);
      throw InputError("serial port '" + impl.name + "' is in use by " + holder_of(impl.lock_path) +
                       " (lock file " + impl.lock_path + "); stop that stream first");
    }
    // The holder before us may have removed the file between our open and our lock: lock the
    // file that is at the path now.
    struct stat here {}, there {};
    if (::fstat(fd, &here) != 0 || ::stat(impl.lock_path.c_str(), &there) != 0 || here.st_ino != there.st_ino ||
        here.st_dev != there.st_dev) {
      ::close(fd);
      continue;
    }
    const std::string pid = std::to_string(::getpid()) + "\n";
    if (::ftruncate(fd, 0) != 0 || ::write(fd, pid.data(), pid.size()) < 0) { /* the lock itself holds */ }
    impl.lock_fd = fd;
    return;
  }
  open_failed(impl.name, "its lock file " + impl.lock_path + " keeps changing");
}

// TIOCEXCL: further open() calls on the tty fail with EBUSY (for other users than root) while we
// hold it; the lock file covers everyone who asks (and names the holder).
void make_exclusive(int fd) {
  if (fd >= 0) ::ioctl(fd, TIOCEXCL);
}

speed_t posix_speed(int baud) {
  switch (baud) {
    case 9600: return B9600;
    case 19200: return B19200;
    case 38400: return B38400;
    case 57600: return B57600;
    case 115200: return B115200;
    case 230400: return B230400;
    case 460800: return B460800;
    case 921600: return B921600;
    default: return B0;
  }
}

void open_posix(SerialPort::Impl& impl, const SerialSettings& s) {
  impl.fd = ::open(impl.name.c_str(), O_RDWR | O_NOCTTY | O_NONBLOCK | O_CLOEXEC);
  if (impl.fd < 0) open_failed(impl.name, std::strerror(errno));
  if (!::isatty(impl.fd)) open_failed(impl.name, "not a serial device");
  termios t{};
  if (::tcgetattr(impl.fd, &t) != 0) open_failed(impl.name, std::strerror(errno));
  ::cfmakeraw(&t);
  const speed_t speed = posix_speed(s.baud);
  if (speed == B0) open_failed(impl.name, "baud rate " + std::to_string(s.baud) + " is not supported");
  ::cfsetispeed(&t, speed);
  ::cfsetospeed(&t, speed);
  t.c_cflag &= ~static_cast<tcflag_t>(CSIZE | PARENB | PARODD | CSTOPB | CRTSCTS);
  t.c_cflag |= CLOCAL | CREAD;
  switch (s.data_bits) {
    case 5: t.c_cflag |= CS5; break;
    case 6: t.c_cflag |= CS6; break;
    case 7: t.c_cflag |= CS7; break;
    default: t.c_cflag |= CS8; break;
  }
  if (s.parity != SerialSettings::Parity::none) t.c_cflag |= PARENB;
  if (s.parity == SerialSettings::Parity::odd) t.c_cflag |= PARODD;
  if (s.stop_bits == 2) t.c_cflag |= CSTOPB;
  t.c_iflag &= ~static_cast<tcflag_t>(IXON | IXOFF | IXANY);
  if (s.flow_control == SerialSettings::FlowControl::rts_cts) t.c_cflag |= CRTSCTS;
  if (s.flow_control == SerialSettings::FlowControl::xon_xoff) t.c_iflag |= IXON | IXOFF;
  t.c_cc[VMIN] = 0;
  t.c_cc[VTIME] = 0;
  if (::tcsetattr(impl.fd, TCSANOW, &t) != 0) open_failed(impl.name, std::strerror(errno));
}

void open_libserialport(SerialPort::Impl& impl, const SerialSettings& s) {
  auto check = [&](sp_return r, const char* what) {
    if (r != SP_OK) {
      char* msg = sp_last_error_message();
      const std::string why = std::string(what) + (msg ? std::string(": ") + msg : std::string());
      if (msg) sp_free_error_message(msg);
      open_failed(impl.name, why);
    }
  };
  check(sp_open(impl.sp, SP_MODE_READ_WRITE), "open failed");
  check(sp_set_baudrate(impl.sp, s.baud), "baud rate not accepted");
  check(sp_set_bits(impl.sp, s.data_bits), "data bits not accepted");
  const sp_parity parity = s.parity == SerialSettings::Parity::odd    ? SP_PARITY_ODD
                           : s.parity == SerialSettings::Parity::even ? SP_PARITY_EVEN
                                                                      : SP_PARITY_NONE;
  check(sp_set_parity(impl.sp, parity), "parity not accepted");
  check(sp_set_stopbits(impl.sp, s.stop_bits), "stop bits not accepted");
  const sp_flowcontrol flow = s.flow_control == SerialSettings::FlowControl::rts_cts    ? SP_FLOWCONTROL_RTSCTS
                              : s.flow_control == SerialSettings::FlowControl::xon_xoff ? SP_FLOWCONTROL_XONXOFF
                                                                                        : SP_FLOWCONTROL_NONE;
  check(sp_set_flowcontrol(impl.sp, flow), "flow control not accepted");
}

}  // namespace

SerialPort::SerialPort(const std::string& name, const SerialSettings& settings) : impl_(std::make_unique<Impl>()) {
  impl_->name = name;
  if (name.empty()) open_failed(name, "no port name given");
  take_lock(*impl_);
  if (sp_get_port_by_name(name.c_str(), &impl_->sp) == SP_OK) {
    open_libserialport(*impl_, settings);
    int handle = -1;
    if (sp_get_port_handle(impl_->sp, &handle) == SP_OK) make_exclusive(handle);
  } else {
    impl_->sp = nullptr;
    open_posix(*impl_, settings);
    make_exclusive(impl_->fd);
  }
}

SerialPort::~SerialPort() = default;

const std::string& SerialPort::name() const { return impl_->name; }

bool SerialPort::write(const std::string& bytes, int timeout_ms) {
  if (impl_->sp) {
    // A zero timeout would mean "wait forever" to libserialport: never pass one.
    const sp_return r = sp_blocking_write(impl_->sp, bytes.data(), bytes.size(),
                                          static_cast<unsigned>(std::max(timeout_ms, 1)));
    return r == static_cast<sp_return>(bytes.size());
  }
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::milliseconds(timeout_ms);
  std::size_t done = 0;
  while (done < bytes.size()) {
    const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(deadline - std::chrono::steady_clock::now());
    if (left.count() <= 0) return false;
    pollfd p{impl_->fd, POLLOUT, 0};
    const int pr = ::poll(&p, 1, static_cast<int>(left.count()));
    if (pr < 0 && errno == EINTR) continue;
    if (pr <= 0) return false;
    if (p.revents & (POLLERR | POLLHUP | POLLNVAL)) return false;
    const ssize_t w = ::write(impl_->fd, bytes.data() + done, bytes.size() - done);
    if (w < 0) {
      if (errno == EAGAIN || errno == EINTR) continue;
      return false;
    }
    done += static_cast<std::size_t>(w);
  }
  return true;
}

int SerialPort::read(char* buffer, int size, int timeout_ms) {
  if (size <= 0) return 0;
  if (impl_->sp) {
    const sp_return r = sp_blocking_read_next(impl_->sp, buffer, static_cast<std::size_t>(size),
                                              static_cast<unsigned>(std::max(timeout_ms, 1)));
    return r < 0 ? -1 : static_cast<int>(r);
  }
  pollfd p{impl_->fd, POLLIN, 0};
  int pr;
  do pr = ::poll(&p, 1, std::max(timeout_ms, 0));
  while (pr < 0 && errno == EINTR);
  if (pr < 0) return -1;
  if (pr == 0) return 0;
  if (p.revents & POLLIN) {
    const ssize_t n = ::read(impl_->fd, buffer, static_cast<std::size_t>(size));
    if (n > 0) return static_cast<int>(n);
    if (n < 0 && (errno == EAGAIN || errno == EINTR)) return 0;
    return -1;  // 0 bytes on a readable tty, or EIO: the other end is gone
  }
  return -1;  // POLLHUP / POLLERR without data
}

void SerialPort::drain_input(int timeout_ms) {
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::milliseconds(timeout_ms);
  char buf[256];
  while (std::chrono::steady_clock::now() < deadline)
    if (read(buf, sizeof buf, 20) <= 0) break;
}
#endif  // WIRESCULPT_NO_SERIAL_PORT

// ---------------------------------------------------------------------------------------------
// Program validation
// ---------------------------------------------------------------------------------------------

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

void validate_program(const std::vector<std::string>& lines, const MachineProfile& profile) {
  const std::string allowed = std::string("GMFSPNT") + profile.axes.feed_axis + profile.axes.bend_axis +
                              (profile.axes.pin_axis ? std::string(1, profile.axes.pin_axis) : std::string());
  for (std::size_t i = 0; i < lines.size(); ++i) {
    const std::string& line = lines[i];
    const std::string who = "line " + std::to_string(i + 1);
    if (line.empty()) throw InputError(who + " is empty; remove blank lines (stream_lines() does)");
    if (line.size() > 79)
      throw InputError(who + " has " + std::to_string(line.size()) + " characters; GRBL accepts at most 79");
    for (char c : line) {
      const unsigned char u = static_cast<unsigned char>(c);
      if (u < 0x20 || u >= 0x7f) throw InputError(who + " contains a non-printable character");
      if (c == '!' || c == '~' || c == '?')
        throw InputError(who + " contains '" + std::string(1, c) + "', which GRBL executes as a realtime command");
      if (c == '(' || c == ';')
        throw InputError(who + " contains a comment; strip comments with stream_lines() before streaming");
    }
    if (line[0] == '$') continue;
    std::size_t k = 0;
    while (k < line.size()) {
      if (line[k] == ' ') { ++k; continue; }
      const char letter = static_cast<char>(std::toupper(static_cast<unsigned char>(line[k])));
      if (letter < 'A' || letter > 'Z' || allowed.find(letter) == std::string::npos)
        throw InputError(who + " ('" + line + "'): '" + std::string(1, line[k]) +
                         "' is not a G-code word this machine uses (allowed: " + allowed + ")");
      ++k;
      while (k < line.size() && line[k] == ' ') ++k;
      const std::size_t start = k;
      if (k < line.size() && (line[k] == '-' || line[k] == '+')) ++k;
      bool digits = false;
      while (k < line.size() && (std::isdigit(static_cast<unsigned char>(line[k])) || line[k] == '.')) {
        digits = digits || line[k] != '.';
        ++k;
      }
      if (!digits || k == start)
        throw InputError(who + " ('" + line + "'): the word '" + std::string(1, letter) + "' has no number");
    }
  }
}

// ---------------------------------------------------------------------------------------------
// Streaming
// ---------------------------------------------------------------------------------------------

namespace {

// The device's bytes as message text: "\r" dropped, any other byte outside printable ASCII
// (invalid UTF-8 included) shown as \xNN, so an answer always reaches the user as a string.
std::string printable(const std::string& raw) {
  static const char* hex = "0123456789abcdef";
  std::string out;
  for (char c : raw) {
    const unsigned char u = static_cast<unsigned char>(c);
    if (u == '\r') continue;
    if (u >= 0x20 && u < 0x7f) {
      out += c;
    } else {
      out += "\\x";
      out += hex[u >> 4];
      out += hex[u & 15];
    }
  }
  return out;
}

bool starts_with(const std::string& s, const char* prefix) { return s.rfind(prefix, 0) == 0; }

int code_after_colon(const std::string& s) {
  const std::size_t c = s.find(':');
  if (c == std::string::npos) return 0;
  try {
    return std::stoi(s.substr(c + 1));
  } catch (...) {
    return 0;
  }
}

}  // namespace

GrblAnswer parse_answer(const std::string& raw) {
  GrblAnswer a;
  a.text = printable(raw);
  if (a.text == "ok") {
    a.kind = GrblAnswer::Kind::ok;
  } else if (starts_with(a.text, "error:")) {
    a.kind = GrblAnswer::Kind::error;
    a.code = code_after_colon(a.text);
  } else if (starts_with(a.text, "ALARM")) {
    a.kind = GrblAnswer::Kind::alarm;
    a.code = code_after_colon(a.text);
  } else if (starts_with(a.text, "Grbl ")) {
    a.kind = GrblAnswer::Kind::banner;
  }
  return a;
}

namespace {

using Clock = std::chrono::steady_clock;

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

// A line that only sets modes (units, distance mode, feed-rate mode, plane): G17-G19, G20/G21,
// G90/G91, G93/G94, nothing else but comments.
bool is_modal_setup(const std::string& line) {
  std::string code = line.substr(0, line.find(';'));
  for (std::size_t open; (open = code.find('(')) != std::string::npos;) {
    const std::size_t close = code.find(')', open);
    code.erase(open, close == std::string::npos ? std::string::npos : close - open + 1);
  }
  std::istringstream words(code);
  std::string word;
  int count = 0;
  while (words >> word) {
    for (char& c : word) c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
    static const char* const modal[] = {"G17", "G18", "G19", "G20", "G21", "G90", "G91", "G93", "G94"};
    if (std::find(std::begin(modal), std::end(modal), word) == std::end(modal)) return false;
    ++count;
  }
  return count > 0;
}

// The words of a (validated) program line: upper-case letter and number. "$" lines have none.
struct Word {
  char letter;
  double value;
};
std::vector<Word> words_of(const std::string& line) {
  std::vector<Word> out;
  if (line.empty() || line[0] == '$') return out;
  std::string compact;
  for (char c : line)
    if (c != ' ' && c != '\t') compact += c;
  for (std::size_t k = 0; k < compact.size();) {
    const unsigned char c = static_cast<unsigned char>(compact[k]);
    if (!std::isalpha(c)) {
      ++k;
      continue;
    }
    std::size_t e = k + 1;
    std::string number;
    while (e < compact.size() && (std::isdigit(static_cast<unsigned char>(compact[e])) || compact[e] == '.' ||
                                  compact[e] == '-' || compact[e] == '+'))
      number += compact[e++];
    char* end = nullptr;
    const double v = number.empty() ? 0.0 : std::strtod(number.c_str(), &end);
    out.push_back({static_cast<char>(std::toupper(c)), std::isfinite(v) ? v : 0.0});
    k = e;
  }
  return out;
}

// A dwell (G4) or a program end (M2, M30): GRBL answers it only when every queued move has run,
// so its "ok" says that every line before it was executed, not only queued.
bool is_sync(const std::string& line) {
  for (const Word& w : words_of(line))
    if ((w.letter == 'G' && w.value == 4.0) || (w.letter == 'M' && (w.value == 2.0 || w.value == 30.0))) return true;
  return false;
}

bool is_dwell(const std::string& line) {
  for (const Word& w : words_of(line))
    if (w.letter == 'G' && w.value == 4.0) return true;
  return false;
}

// A line that moves nothing: done when its "ok" arrives with nothing queued before it.
bool is_motionless(const std::string& line) { return (!line.empty() && line[0] == '$') || is_modal_setup(line); }

std::string mm3(double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.3f", v);
  return std::string(std::strcmp(buf, "-0.000") == 0 ? "0.000" : buf);
}

// What lines a..b (0-based, inclusive) move: "feed 40.000 mm, bend 90.000 deg" (the bend as
// commanded, the first bend-axis move; the head's return is not repeated).
std::string moves_of(const std::vector<std::string>& lines, const MachineProfile& profile, std::size_t a,
                     std::size_t b) {
  const AxisMapping& ax = profile.axes;
  const auto up = [](char c) { return static_cast<char>(std::toupper(static_cast<unsigned char>(c))); };
  double feed = 0.0, bend = 0.0;
  bool fed = false, bent = false, pin = false;
  for (std::size_t j = a; j <= b && j < lines.size(); ++j)
    for (const Word& w : words_of(lines[j])) {
      if (w.letter == up(ax.feed_axis)) {
        feed += w.value;
        fed = true;
      } else if (w.letter == up(ax.bend_axis) && !bent && w.value != 0.0) {
        bend = w.value;
        bent = true;
      } else if (ax.pin_axis != '\0' && w.letter == up(ax.pin_axis)) {
        pin = true;
      }
    }
  std::string out;
  auto add = [&](const std::string& part) { out += (out.empty() ? "" : ", ") + part; };
  if (fed) add("feed " + mm3(feed / ax.feed_units_per_mm) + " mm");
  if (pin) add("pin moved");
  if (bent) add("bend " + mm3(bend / ax.bend_units_per_deg * (profile.left_is_positive ? 1.0 : -1.0)) + " deg");
  return out.empty() ? "no feed or bend" : out;
}

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

StreamResult stream_program(SerialPort& port, const std::vector<std::string>& lines, const MachineProfile& profile,
                            StreamState& state, const StreamOptions& options, const ProgressFn& progress) {
  validate(options);
  validate(profile);
  validate_program(lines, profile);
  if (state.next_line > lines.size())
    throw InputError("the stream state's next line (" + std::to_string(state.next_line) +
                     ") is past the program's " + std::to_string(lines.size()) + " lines");
  state.confirmed = std::min(state.confirmed, state.next_line);
  StreamResult r;
  r.last_acknowledged = static_cast<long>(state.next_line) - 1;
  const std::size_t total = lines.size();
  const int write_ms = std::max(1, to_ms(options.write_timeout));
  const int answer_ms = std::max(1, to_ms(options.response_timeout));
  constexpr int kSliceMs = 20;  // how often control switches are looked at while waiting
  StreamControl* control = options.control;
  LineReader reader(port);

  auto fraction = [&] { return total ? static_cast<double>(state.next_line) / static_cast<double>(total) : 1.0; };
  auto wants_abort = [&] { return control && control->abort.load(); };
  auto stop = [&](StreamStatus status, long line, std::string message) {
    r.status = status;
    r.failed_line = line;
    r.message = std::move(message);
    return r;
  };
  // Where a resume goes on after a stop: "; N lines are done; resume from line N+1".
  auto resume_at = [&] {
    return "; " + std::to_string(state.next_line) + " lines are done; resume from line " +
           std::to_string(state.next_line + 1);
  };
  // A stop after which the controller's queued moves may be lost (a dropped link or a timeout,
  // then the reset of reopening the port; an alarm; our own soft reset; a restart; a feed hold
  // left in place). GRBL answers "ok" when it queues a line, so the lines acknowledged since the
  // last sync line (state.confirmed) are in doubt: the message names that step, and state.next_line
  // goes back to its first line, so that a resume makes the whole step again.
  auto interrupted = [&](StreamStatus status, long line, const std::string& cause) {
    if (state.next_line <= state.confirmed) return stop(status, line, cause + resume_at());
    const std::size_t a = state.confirmed, acked = state.next_line - 1;
    std::size_t b = a;
    while (b + 1 < total && !is_sync(lines[b])) ++b;  // the step's end: its sync line (or the last line)
    bool steps = false;
    std::size_t step = 1;
    for (std::size_t j = 0; j < total; ++j)
      if (is_dwell(lines[j])) {
        steps = true;
        if (j < a) ++step;
      }
    const std::string span = std::to_string(a + 1) + "-" + std::to_string(b + 1);
    const std::string what = (steps ? "step " + std::to_string(step) + " (lines " : "the moves of lines (") + span +
                             ": " + moves_of(lines, profile, a, b) + ")";
    const std::string done = a ? "lines 1-" + std::to_string(a) + " are done" : "no line is known done";
    state.next_line = a;
    return stop(status, line,
                cause + "; " + what + " may be half made: GRBL answers 'ok' when it queues a line, and " +
                    (acked > a ? "lines " + std::to_string(a + 1) + "-" + std::to_string(acked + 1) + " were"
                               : "line " + std::to_string(a + 1) + " was") +
                    " acknowledged but not " + quoted(lines, b) +
                    ", which is answered only when the moves have run; a reset of the controller drops queued "
                    "moves; check the wire: the resume restarts " + (steps ? "the step" : "these lines") +
                    " from line " + std::to_string(a + 1) + " (" + done + "); if the wire shows " +
                    (steps ? "the step" : "them") + " made in full, continue from line " + std::to_string(b + 2) +
                    " instead (next_line " + std::to_string(b + 1) + ")");
  };
  auto abort_machine = [&](long line) {
    port.write(std::string("!") + '\x18', write_ms);  // feed hold, then soft reset
    return interrupted(StreamStatus::aborted, line,
                       "aborted by request before " +
                           (line >= 0 ? quoted(lines, static_cast<std::size_t>(line)) : std::string("the end")) +
                           " was acknowledged; the machine was stopped with a feed hold and a soft reset");
  };
  auto report = [&] { return !progress || progress("stream", fraction()); };
  // An answer with no line of ours outstanding (before a line is sent, or while paused). `held`:
  // the machine is in a feed hold, so its queued moves have not run.
  auto unexpected = [&](const GrblAnswer& answer, long li, const std::string& when,
                        bool held) -> std::optional<StreamResult> {
    if (answer.kind == Kind::banner)
      return interrupted(StreamStatus::disconnected, li,
                         "the controller restarted " + when + " (its banner '" + answer.text +
                             "' arrived): it is back in its default modes and dropped its queued moves; the resume "
                             "restores the program's modes first");
    if (answer.kind == Kind::alarm) {
      r.code = answer.code;
      return interrupted(StreamStatus::alarm, li,
                         "GRBL raised " + answer.text + " " + when + "; the machine is locked: " + kUnlock);
    }
    if (answer.kind == Kind::ok || answer.kind == Kind::error) {
      const std::string cause = "protocol error: the controller sent an unexpected '" + answer.text +
                                "' (more answers than lines sent) " + when + "; " +
                                std::to_string(state.next_line) +
                                " lines are acknowledged; check the device and the port settings";
      if (held) return interrupted(StreamStatus::protocol_error, li, cause + " (the machine is in a feed hold)");
      return stop(StreamStatus::protocol_error, li, cause + ", then resume from line " + std::to_string(li + 1));
    }
    return std::nullopt;  // [MSG:...], <status>, blank: informational
  };

  if (!report()) return abort_machine(static_cast<long>(state.next_line));

  // Resuming mid-program: GRBL comes back from any reset (reopening the port, our own abort, an
  // alarm cleared with a reset) in its default modes (G21 G90 G94), so the program's mode lines
  // before the resume point are sent again first; relative feeds run as absolute moves otherwise.
  // They change no position, so sending them twice is harmless; next_line does not move.
  for (std::size_t j = 0; j < state.next_line && j < total; ++j) {
    if (!is_modal_setup(lines[j])) continue;
    const long lj = static_cast<long>(state.next_line);
    const std::string resume = "; resume from line " + std::to_string(state.next_line + 1) + " again";
    if (!port.write(lines[j] + "\n", write_ms))
      return stop(StreamStatus::disconnected, lj, "the link to " + port.name() + " dropped while restoring the "
                  "machine's modes (" + quoted(lines, j) + ") before resuming" + resume);
    const auto deadline = Clock::now() + std::chrono::milliseconds(answer_ms);
    for (bool ok = false; !ok;) {
      if (wants_abort()) return abort_machine(lj);
      const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(deadline - Clock::now()).count();
      if (left <= 0)
        return stop(StreamStatus::timeout, lj, "no answer to " + quoted(lines, j) +
                    " while restoring the machine's modes before resuming" + resume);
      GrblAnswer answer;
      const auto got = reader.next(answer, static_cast<int>(std::min<long long>(left, kSliceMs)));
      if (got == LineReader::Got::lost)
        return stop(StreamStatus::disconnected, lj, "the link to " + port.name() +
                    " dropped while restoring the machine's modes before resuming" + resume);
      if (got == LineReader::Got::nothing) continue;
      if (answer.kind == Kind::ok) ok = true;
      else if (answer.kind == Kind::error || answer.kind == Kind::alarm)
        return stop(answer.kind == Kind::error ? StreamStatus::error : StreamStatus::alarm, lj,
                    "GRBL answered " + answer.text + " to " + quoted(lines, j) +
                    " while its modes were restored before resuming (" + kUnlock + ")" + resume);
      else if (answer.kind == Kind::banner)
        return stop(StreamStatus::disconnected, lj, "the controller restarted (its banner '" + answer.text +
                    "' arrived) while its modes were restored before resuming" + resume);
    }
  }

  while (state.next_line < total) {
    const std::size_t i = state.next_line;
    const long li = static_cast<long>(i);
    if (wants_abort()) return abort_machine(li);
    if (control && control->pause.load()) {
      if (!port.write("!", write_ms))
        return interrupted(StreamStatus::disconnected, li, "the link to " + port.name() + " dropped while pausing");
      // Nothing is outstanding while paused: every answer is news (a restart, an alarm, a stray ok).
      while (control->pause.load()) {
        if (wants_abort() || !report()) return abort_machine(li);
        GrblAnswer answer;
        const auto got = reader.next(answer, kSliceMs * 5);
        if (got == LineReader::Got::lost)
          return interrupted(StreamStatus::disconnected, li, "the link to " + port.name() + " dropped while paused");
        if (got == LineReader::Got::line)
          if (auto stopped = unexpected(answer, li, "while the stream was paused (feed hold)", true)) return *stopped;
      }
      if (!port.write("~", write_ms))
        return interrupted(StreamStatus::disconnected, li, "the link to " + port.name() + " dropped on resuming");
    }

    // Strict accounting: with nothing outstanding, any answer already here is not for a line of
    // ours. An "ok" would otherwise be taken as the next line's acknowledgement (a device that
    // doubles its "ok" would skip a bend on resume), so it stops the stream; next_line stays.
    for (GrblAnswer early; reader.pending(early) == LineReader::Got::line;)
      if (auto stopped = unexpected(early, li, "before " + quoted(lines, i) + " was sent", false)) return *stopped;
    if (!port.write(lines[i] + "\n", write_ms))
      return interrupted(StreamStatus::disconnected, li,
                         "the link to " + port.name() + " dropped (or stopped accepting data) before " +
                             quoted(lines, i) + " was sent");
    ++r.sent;

    const auto deadline = Clock::now() + std::chrono::milliseconds(answer_ms);
    bool acknowledged = false;
    while (!acknowledged) {
      if (wants_abort()) return abort_machine(li);
      const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(deadline - Clock::now()).count();
      if (left <= 0)
        return interrupted(StreamStatus::timeout, li,
                           "no answer to " + quoted(lines, i) + " within " + std::to_string(answer_ms) +
                               " ms; it is not acknowledged, so a resume sends it again after you check the machine");
      GrblAnswer answer;
      const auto got = reader.next(answer, static_cast<int>(std::min<long long>(left, kSliceMs)));
      if (got == LineReader::Got::nothing) continue;
      if (got == LineReader::Got::lost)
        return interrupted(StreamStatus::disconnected, li,
                           "the link to " + port.name() + " dropped while " + quoted(lines, i) +
                               " was waiting for its answer");
      if (answer.kind == Kind::ok) {
        acknowledged = true;
      } else if (answer.kind == Kind::error) {
        r.code = answer.code;
        if (r.code == 9)  // "G-code locked out during alarm or jog state"
          return stop(StreamStatus::error, li,
                      "GRBL is locked (an alarm, or a jog in progress) and refused " + quoted(lines, i) + " with " +
                          answer.text + " (the line was not executed): " + kUnlock + ", then resume from line " +
                          std::to_string(i + 1));
        return stop(StreamStatus::error, li,
                    "GRBL rejected " + quoted(lines, i) + " with " + answer.text +
                        " (the line was not executed); fix it and resume from line " + std::to_string(i + 1));
      } else if (answer.kind == Kind::alarm) {
        r.code = answer.code;
        return interrupted(StreamStatus::alarm, li,
                           "GRBL raised " + answer.text + " while " + quoted(lines, i) +
                               " was in flight; the machine is locked: " + kUnlock);
      } else if (answer.kind == Kind::banner) {
        return interrupted(StreamStatus::disconnected, li,
                           "the controller restarted while " + quoted(lines, i) + " was in flight (its banner '" +
                               answer.text + "' arrived): it is back in its default modes and dropped its queued "
                               "moves; the resume restores the program's modes first");
      }
      // Anything else ([MSG:...], <status>, blank) is informational.
    }
    ++state.next_line;
    if (is_sync(lines[i]) || (state.confirmed == i && is_motionless(lines[i]))) state.confirmed = i + 1;
    ++r.acknowledged;
    r.last_acknowledged = li;
    if (!report()) return abort_machine(state.next_line < total ? static_cast<long>(state.next_line) : -1);
  }
  // An "ok" beyond the last line's means some acknowledgement was not for the line it was taken
  // for: the count is not to be trusted (the answer to the last line is already here when a
  // device doubles it).
  for (GrblAnswer late; reader.pending(late) == LineReader::Got::line;)
    if (late.kind == Kind::ok) {
      r.status = StreamStatus::protocol_error;
      r.failed_line = static_cast<long>(total) - 1;
      r.message = "protocol error: the controller sent an unexpected 'ok' after the last line (more answers than "
                  "lines sent), so its acknowledgements cannot be trusted; check the device and the port settings";
      return r;
    }
  r.status = StreamStatus::completed;
  r.message = "all " + std::to_string(total) + " lines acknowledged";
  return r;
}

StreamResult stream_program(const std::string& port_name, const std::vector<std::string>& lines,
                            const MachineProfile& profile, StreamState& state, const StreamOptions& options,
                            const ProgressFn& progress) {
  validate(options);
  validate(profile);
  validate_program(lines, profile);
  if (state.next_line > lines.size())
    throw InputError("the stream state's next line (" + std::to_string(state.next_line) +
                     ") is past the program's " + std::to_string(lines.size()) + " lines");
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
