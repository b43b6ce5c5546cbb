// A serial port as a POSIX terminal device: see serial_tty.hpp.
#ifndef _WIN32
#include "serial_tty.hpp"

#include <dirent.h>
#include <fcntl.h>
#include <poll.h>
#include <sys/file.h>
#include <sys/ioctl.h>
#include <sys/select.h>
#include <sys/stat.h>
#include <termios.h>
#include <unistd.h>
#ifdef __APPLE__
#include <libproc.h>
#ifndef IOSSIOSPEED
#define IOSSIOSPEED _IOW('T', 2, speed_t)  // <IOKit/serial/ioss.h>: any baud on a macOS serial driver
#endif
#endif

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <chrono>
#include <climits>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <string>

#include "wiresculpt/error.hpp"

namespace wiresculpt::fab::tty {

void open_failed(const std::string& name, const std::string& why) {
  throw InputError("could not open serial port '" + name + "': " + why);
}

// ---------------------------------------------------------------------------------------------
// The lock file
// ---------------------------------------------------------------------------------------------

Lock::~Lock() {
  if (fd >= 0) {
    ::unlink(path.c_str());
    ::close(fd);
  }
}

std::string lock_path_for(const std::string& port) {
  std::string device = port;
  char resolved[PATH_MAX];
  if (::realpath(port.c_str(), resolved)) device = resolved;
  if (device.rfind("/dev/", 0) == 0) device.erase(0, 5);
  std::replace(device.begin(), device.end(), '/', '_');
  std::string dir;
  if (const char* env = std::getenv("WIRESCULPT_LOCK_DIR"); env && *env) dir = env;
  else if (::access("/var/lock", W_OK) == 0) dir = "/var/lock";
  else dir = "/tmp";
  return dir + "/LCK.." + device;
}

namespace {

// The name of process `pid`, "" when the system does not say.
std::string process_name(long pid) {
#ifdef __APPLE__
  char name[256] = {};
  if (::proc_name(static_cast<int>(pid), name, sizeof name) > 0) return name;
  return {};
#else
  std::ifstream comm("/proc/" + std::to_string(pid) + "/comm");
  std::string name;
  std::getline(comm, name);
  return name;
#endif
}

// Who holds the lock file: "process 1234 (blender)", from the pid written in it.
std::string holder_of(const std::string& path) {
  std::ifstream in(path);
  long pid = 0;
  if (!(in >> pid) || pid <= 0) return "another program";
  std::string who = "process " + std::to_string(pid);
  if (const std::string name = process_name(pid); !name.empty()) who += " (" + name + ")";
  if (pid == static_cast<long>(::getpid())) who += ", this program";
  return who;
}

}  // namespace

void take_lock(const std::string& port, Lock& lock) {
  lock.path = lock_path_for(port);
  for (int attempt = 0; attempt < 5; ++attempt) {
    const int fd = ::open(lock.path.c_str(), O_RDWR | O_CREAT | O_CLOEXEC | O_NOFOLLOW, 0644);
    if (fd < 0) open_failed(port, "cannot create its lock file " + lock.path + ": " + std::strerror(errno));
    if (::flock(fd, LOCK_EX | LOCK_NB) != 0) {
      ::close(fd);
      throw InputError("serial port '" + port + "' is in use by " + holder_of(lock.path) + " (lock file " +
                       lock.path + "); stop that stream first");
    }
    // The holder before us may have removed the file between our open and our lock: lock the
    // file that is at the path now.
    struct stat here {}, there {};
    if (::fstat(fd, &here) != 0 || ::stat(lock.path.c_str(), &there) != 0 || here.st_ino != there.st_ino ||
        here.st_dev != there.st_dev) {
      ::close(fd);
      continue;
    }
    const std::string pid = std::to_string(::getpid()) + "\n";
    if (::ftruncate(fd, 0) != 0 || ::write(fd, pid.data(), pid.size()) < 0) { /* the lock itself holds */ }
    lock.fd = fd;
    return;
  }
  open_failed(port, "its lock file " + lock.path + " keeps changing");
}

// ---------------------------------------------------------------------------------------------
// The device
// ---------------------------------------------------------------------------------------------

namespace {

speed_t posix_speed(int baud) {
  switch (baud) {
    case 9600: return B9600;
    case 19200: return B19200;
    case 38400: return B38400;
    case 57600: return B57600;
    case 115200: return B115200;
    case 230400: return B230400;
#ifdef B460800
    case 460800: return B460800;
#endif
#ifdef B921600
    case 921600: return B921600;
#endif
    default: return B0;
  }
}

// Closes fd (the open failed part way) and throws.
[[noreturn]] void fail_open(int fd, const std::string& name, const std::string& why) {
  ::close(fd);
  open_failed(name, why);
}

}  // namespace

int open_device(const std::string& name, const SerialSettings& s) {
  if (name.empty()) open_failed(name, "no port name given");
  const int fd = ::open(name.c_str(), O_RDWR | O_NOCTTY | O_NONBLOCK | O_CLOEXEC);
  if (fd < 0) {
    if (errno == ENOENT) open_failed(name, "no such port");
    if (errno == EBUSY)  // TIOCEXCL of another program
      throw InputError("serial port '" + name + "' is in use by another program; stop that stream first");
    open_failed(name, std::strerror(errno));
  }
  if (!::isatty(fd)) fail_open(fd, name, "not a serial device");
  if (::flock(fd, LOCK_EX | LOCK_NB) != 0) {
    ::close(fd);
    throw InputError("serial port '" + name + "' is in use by another program (it holds the device's lock); "
                     "stop that stream first");
  }
  termios t{};
  if (::tcgetattr(fd, &t) != 0) fail_open(fd, name, std::strerror(errno));
  ::cfmakeraw(&t);
  speed_t speed = posix_speed(s.baud);
#ifdef __APPLE__
  const bool any_speed = speed == B0 && s.baud > 0;  // set by IOSSIOSPEED below
  if (any_speed) speed = B9600;
#endif
  if (speed == B0) fail_open(fd, name, "baud rate " + std::to_string(s.baud) + " is not supported");
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
  if (::tcsetattr(fd, TCSANOW, &t) != 0) fail_open(fd, name, std::strerror(errno));
#ifdef __APPLE__
  if (any_speed) {
    speed_t exact = static_cast<speed_t>(s.baud);
    if (::ioctl(fd, IOSSIOSPEED, &exact) != 0)
      fail_open(fd, name, "baud rate " + std::to_string(s.baud) + " is not supported: " + std::strerror(errno));
  }
#endif
  // TIOCEXCL: further open() calls on the tty fail with EBUSY (for other users than root) while we
  // hold it; the lock file covers everyone who asks (and names the holder).
  ::ioctl(fd, TIOCEXCL);
  return fd;
}

void close_device(int fd) {
  if (fd < 0) return;
  ::ioctl(fd, TIOCNXCL);
  ::close(fd);
}

// ---------------------------------------------------------------------------------------------
// Waiting, reading, writing
// ---------------------------------------------------------------------------------------------

Ready wait_ready_poll(int fd, bool for_write, int timeout_ms) {
  pollfd p{fd, static_cast<short>(for_write ? POLLOUT : POLLIN), 0};
  int pr;
  do pr = ::poll(&p, 1, std::max(timeout_ms, 0));
  while (pr < 0 && errno == EINTR);
  if (pr < 0) return Ready::failed;
  if (pr == 0) return Ready::timeout;
  if (p.revents & (for_write ? POLLOUT : POLLIN)) return Ready::ready;  // a read/write says the rest
  if (p.revents & POLLHUP) return Ready::hangup;
  return Ready::failed;  // POLLERR, POLLNVAL
}

Ready wait_ready_select(int fd, bool for_write, int timeout_ms) {
  if (fd < 0 || fd >= FD_SETSIZE) return Ready::failed;
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::milliseconds(std::max(timeout_ms, 0));
  for (;;) {
    const long long left = std::max<long long>(
        0, std::chrono::duration_cast<std::chrono::microseconds>(deadline - std::chrono::steady_clock::now()).count());
    fd_set set, errors;
    FD_ZERO(&set);
    FD_ZERO(&errors);
    FD_SET(fd, &set);
    FD_SET(fd, &errors);
    timeval tv{};
    tv.tv_sec = static_cast<decltype(tv.tv_sec)>(left / 1000000);
    tv.tv_usec = static_cast<decltype(tv.tv_usec)>(left % 1000000);
    const int r = ::select(fd + 1, for_write ? nullptr : &set, for_write ? &set : nullptr, &errors, &tv);
    if (r < 0 && errno == EINTR) continue;
    if (r < 0) return Ready::failed;
    if (r == 0) return Ready::timeout;
    // A hung-up tty is readable (read() then says 0 or EIO) and writable (write() says EIO).
    return FD_ISSET(fd, &set) ? Ready::ready : Ready::failed;
  }
}

Ready wait_ready(int fd, bool for_write, int timeout_ms) {
#ifdef __APPLE__
  return wait_ready_select(fd, for_write, timeout_ms);
#else
  return wait_ready_poll(fd, for_write, timeout_ms);
#endif
}

bool write_all(int fd, const std::string& bytes, int timeout_ms) {
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::milliseconds(timeout_ms);
  std::size_t done = 0;
  while (done < bytes.size()) {
    const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(deadline - std::chrono::steady_clock::now());
    if (left.count() <= 0) return false;
    if (wait_ready(fd, true, static_cast<int>(left.count())) != Ready::ready) return false;
    const ssize_t w = ::write(fd, bytes.data() + done, bytes.size() - done);
    if (w < 0) {
      if (errno == EAGAIN || errno == EINTR) continue;
      return false;  // EIO: the device is gone
    }
    done += static_cast<std::size_t>(w);
  }
  return true;
}

int read_some(int fd, char* buffer, int size, int timeout_ms) {
  if (size <= 0) return 0;
  switch (wait_ready(fd, false, timeout_ms)) {
    case Ready::timeout: return 0;
    case Ready::hangup:
    case Ready::failed: return -1;
    case Ready::ready: break;
  }
  const ssize_t n = ::read(fd, buffer, static_cast<std::size_t>(size));
  if (n > 0) return static_cast<int>(n);
  if (n < 0 && (errno == EAGAIN || errno == EINTR)) return 0;
  return -1;  // 0 bytes on a readable tty, or EIO: the other end is gone
}

void drain(int fd, int timeout_ms) {
  ::tcflush(fd, TCIFLUSH);
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::milliseconds(timeout_ms);
  char buf[256];
  while (std::chrono::steady_clock::now() < deadline)
    if (read_some(fd, buf, sizeof buf, 20) <= 0) break;
}

// ---------------------------------------------------------------------------------------------
// Listing
// ---------------------------------------------------------------------------------------------

namespace {

// Splits runs of digits off so that they compare as numbers: ttyUSB2 < ttyUSB10.
bool natural_less(const std::string& a, const std::string& b) {
  std::size_t i = 0, j = 0;
  while (i < a.size() && j < b.size()) {
    const bool da = std::isdigit(static_cast<unsigned char>(a[i])) != 0;
    const bool db = std::isdigit(static_cast<unsigned char>(b[j])) != 0;
    if (da && db) {
      std::size_t ei = i, ej = j;
      while (ei < a.size() && std::isdigit(static_cast<unsigned char>(a[ei]))) ++ei;
      while (ej < b.size() && std::isdigit(static_cast<unsigned char>(b[ej]))) ++ej;
      const std::string na = a.substr(i, ei - i), nb = b.substr(j, ej - j);
      const std::size_t za = na.find_first_not_of('0'), zb = nb.find_first_not_of('0');
      const std::string ta = za == std::string::npos ? "" : na.substr(za);
      const std::string tb = zb == std::string::npos ? "" : nb.substr(zb);
      if (ta.size() != tb.size()) return ta.size() < tb.size();
      if (ta != tb) return ta < tb;
      i = ei;
      j = ej;
    } else {
      if (a[i] != b[j]) return a[i] < b[j];
      ++i;
      ++j;
    }
  }
  return a.size() - i < b.size() - j;
}

std::string first_line(const std::string& path) {
  std::ifstream in(path);
  std::string line;
  std::getline(in, line);
  while (!line.empty() && (line.back() == '\r' || line.back() == ' ')) line.pop_back();
  return line;
}

// The USB product string of a tty: sysfs's product file a few levels above its device.
std::string usb_product(const std::string& sys_class_tty, const std::string& name) {
  if (sys_class_tty.empty()) return {};
  char resolved[PATH_MAX];
  if (!::realpath((sys_class_tty + "/" + name + "/device").c_str(), resolved)) return {};
  std::string dir = resolved;
  for (int up = 0; up < 3 && dir.size() > 1; ++up) {
    if (const std::string p = first_line(dir + "/product"); !p.empty()) return p;
    dir.erase(dir.find_last_of('/'));
  }
  return {};
}

}  // namespace

std::vector<PortInfo> list_devices(const std::string& dir, const std::vector<std::string>& prefixes,
                                   const std::string& sys_class_tty) {
  std::vector<PortInfo> out;
  DIR* d = ::opendir(dir.c_str());
  if (!d) return out;
  while (const dirent* e = ::readdir(d)) {
    const std::string name = e->d_name;
    const auto match = std::find_if(prefixes.begin(), prefixes.end(), [&](const std::string& p) {
      return name.size() > p.size() && name.rfind(p, 0) == 0;
    });
    if (match == prefixes.end()) continue;
    PortInfo info;
    info.name = dir + "/" + name;
    info.description = usb_product(sys_class_tty, name);
    if (info.description.empty()) info.description = name.rfind("cu.", 0) == 0 ? name.substr(3) : name;
    out.push_back(info);
  }
  ::closedir(d);
  std::sort(out.begin(), out.end(), [](const PortInfo& a, const PortInfo& b) { return natural_less(a.name, b.name); });
  return out;
}

std::vector<PortInfo> list_system_devices() {
#ifdef __APPLE__
  // The call-out devices: opening them does not wait for the carrier (the tty.* twins do).
  return list_devices("/dev", {"cu."}, "");
#else
  return list_devices("/dev", {"ttyUSB", "ttyACM"}, "/sys/class/tty");
#endif
}

}  // namespace wiresculpt::fab::tty

#endif  // !_WIN32
