// The serial port in a build without serial ports (WIRESCULPT_SERIAL_BACKEND=none, or
// WIRESCULPT_SERIAL_PORT=OFF). The protocol
// (grbl_protocol.cpp) and the streamer are built as always (validation, dry runs, parse_answer);
// no port is listed, and opening one throws an InputError that says why, which reaches the user
// as the stream's message.
#ifdef WIRESCULPT_SERIAL_BACKEND_NONE
#include <string>
#include <vector>

#include "wiresculpt/error.hpp"
#include "wiresculpt/fab/serial.hpp"

namespace wiresculpt::fab {

const char* serial_backend() { return "none"; }

std::vector<PortInfo> list_ports() { return {}; }

struct SerialPort::Impl {
  std::string name;
};

SerialPort::SerialPort(const std::string& name, const SerialSettings& /*settings*/) : impl_(std::make_unique<Impl>()) {
  impl_->name = name;
  throw InputError("could not open serial port '" + name + "': this build of the solver has no serial ports "
                   "(it is made without a serial back end); export the G-code files and send them "
                   "with the machine's own sender");
}

SerialPort::~SerialPort() = default;

const std::string& SerialPort::name() const { return impl_->name; }

bool SerialPort::write(const std::string& /*bytes*/, int /*timeout_ms*/) { return false; }

int SerialPort::read(char* /*buffer*/, int /*size*/, int /*timeout_ms*/) { return -1; }

void SerialPort::drain_input(int /*timeout_ms*/) {}

}  // namespace wiresculpt::fab
#endif  // WIRESCULPT_SERIAL_BACKEND_NONE
