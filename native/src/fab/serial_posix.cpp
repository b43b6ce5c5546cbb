// The serial link as a plain POSIX terminal device (termios), without libserialport: the back
// end of the macOS build (libserialport's source is not among the packages reached here), and of
// any POSIX build configured with WIRESCULPT_SERIAL_BACKEND=posix (the native tests build one on
// Linux, against the same pseudo-terminal GRBL emulator as the libserialport build). The device
// is opened O_RDWR|O_NOCTTY|O_NONBLOCK as raw bytes at the profile's settings (8N1 at the baud by
// default), every read and write waits at most its timeout, a hang-up (POLLHUP, read() == 0, EIO)
// is a lost link, and the lock file plus flock() on the device keep two streams off one port.
// The parts are in serial_tty.cpp, shared with the libserialport back end's pty path.
#ifdef WIRESCULPT_SERIAL_BACKEND_POSIX
#include <string>
#include <vector>

#include "serial_tty.hpp"
#include "wiresculpt/fab/serial.hpp"

namespace wiresculpt::fab {

const char* serial_backend() { return "posix"; }

std::vector<PortInfo> list_ports() { return tty::list_system_devices(); }

struct SerialPort::Impl {
  std::string name;
  tty::Lock lock;  // released after the device is closed (members are destroyed in reverse)
  int fd = -1;
  ~Impl() { tty::close_device(fd); }
};

SerialPort::SerialPort(const std::string& name, const SerialSettings& settings) : impl_(std::make_unique<Impl>()) {
  impl_->name = name;
  if (name.empty()) tty::open_failed(name, "no port name given");
  tty::take_lock(name, impl_->lock);
  impl_->fd = tty::open_device(name, settings);
}

SerialPort::~SerialPort() = default;

const std::string& SerialPort::name() const { return impl_->name; }

bool SerialPort::write(const std::string& bytes, int timeout_ms) { return tty::write_all(impl_->fd, bytes, timeout_ms); }

int SerialPort::read(char* buffer, int size, int timeout_ms) { return tty::read_some(impl_->fd, buffer, size, timeout_ms); }

void SerialPort::drain_input(int timeout_ms) { tty::drain(impl_->fd, timeout_ms); }

}  // namespace wiresculpt::fab

#endif  // WIRESCULPT_SERIAL_BACKEND_POSIX
