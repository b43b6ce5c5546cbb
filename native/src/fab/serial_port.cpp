// The serial link on Linux (and any POSIX system): the ports the system lists, the lock file that
// keeps two streams off one port, and the two back ends (libserialport, or a plain POSIX tty for
// devices libserialport does not know, such as pseudo-terminals), each read and write bounded by a
// timeout. Windows has serial_win32.cpp (its own API) instead; a build without libserialport
// (WIRESCULPT_NO_SERIAL_PORT: the macOS cross build) has serial_none.cpp. The protocol and the
// streamer are built as always.
#if !defined(_WIN32) && !defined(WIRESCULPT_NO_SERIAL_PORT)
#include <fcntl.h>
#include <libserialport.h>
#include <poll.h>
#include <sys/file.h>
#include <sys/ioctl.h>
#include <sys/stat.h>
#include <termios.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <string>

#include "wiresculpt/error.hpp"
#include "wiresculpt/fab/serial.hpp"

namespace wiresculpt::fab {

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

}  // namespace wiresculpt::fab

#endif  // !_WIN32 && !WIRESCULPT_NO_SERIAL_PORT
