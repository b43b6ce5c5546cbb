// The serial link through libserialport (the Linux build): the ports libserialport lists, and
// the devices it opens; a device it does not know (a pseudo-terminal such as a socat or emulator
// port) is opened as a plain POSIX tty (serial_tty.cpp, the termios back end's parts). The lock
// file that keeps two streams off one port is serial_tty's too. Windows has serial_win32.cpp,
// macOS serial_posix.cpp (termios alone), a build without ports serial_none.cpp.
#ifdef WIRESCULPT_SERIAL_BACKEND_LIBSERIALPORT
#include <libserialport.h>
#include <sys/ioctl.h>

#include <algorithm>
#include <chrono>
#include <string>

#include "serial_tty.hpp"
#include "wiresculpt/error.hpp"
#include "wiresculpt/fab/serial.hpp"

namespace wiresculpt::fab {

const char* serial_backend() { return "libserialport"; }

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
  tty::Lock lock;  // released after the port is closed (members are destroyed in reverse)
  sp_port* sp = nullptr;
  int fd = -1;  // a device libserialport does not know, opened by serial_tty

  ~Impl() {
    if (sp) {
      // Exclusive mode outlives our descriptor while anyone else keeps the tty open: clear it.
      int handle = -1;
      if (sp_get_port_handle(sp, &handle) == SP_OK && handle >= 0) ::ioctl(handle, TIOCNXCL);
      sp_close(sp);
      sp_free_port(sp);
    }
    tty::close_device(fd);
  }
};

namespace {

void open_libserialport(SerialPort::Impl& impl, const SerialSettings& s) {
  auto check = [&](sp_return r, const char* what) {
    if (r != SP_OK) {
      char* msg = sp_last_error_message();
      const std::string why = std::string(what) + (msg ? std::string(": ") + msg : std::string());
      if (msg) sp_free_error_message(msg);
      tty::open_failed(impl.name, why);
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
  if (name.empty()) tty::open_failed(name, "no port name given");
  tty::take_lock(name, impl_->lock);
  if (sp_get_port_by_name(name.c_str(), &impl_->sp) == SP_OK) {
    open_libserialport(*impl_, settings);
    // TIOCEXCL: further open() calls on the tty fail with EBUSY (for other users than root).
    int handle = -1;
    if (sp_get_port_handle(impl_->sp, &handle) == SP_OK && handle >= 0) ::ioctl(handle, TIOCEXCL);
  } else {
    impl_->sp = nullptr;
    impl_->fd = tty::open_device(name, settings);
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
  return tty::write_all(impl_->fd, bytes, timeout_ms);
}

int SerialPort::read(char* buffer, int size, int timeout_ms) {
  if (size <= 0) return 0;
  if (impl_->sp) {
    const sp_return r = sp_blocking_read_next(impl_->sp, buffer, static_cast<std::size_t>(size),
                                              static_cast<unsigned>(std::max(timeout_ms, 1)));
    return r < 0 ? -1 : static_cast<int>(r);
  }
  return tty::read_some(impl_->fd, buffer, size, timeout_ms);
}

void SerialPort::drain_input(int timeout_ms) {
  if (!impl_->sp) return tty::drain(impl_->fd, timeout_ms);
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::milliseconds(timeout_ms);
  char buf[256];
  while (std::chrono::steady_clock::now() < deadline)
    if (read(buf, sizeof buf, 20) <= 0) break;
}

}  // namespace wiresculpt::fab

#endif  // WIRESCULPT_SERIAL_BACKEND_LIBSERIALPORT
