// The serial link on Windows, with Windows' own communications API (no libserialport: its
// source is not among the packages reached here, and the API it would wrap is small): the port
// is opened with CreateFileW on \\.\COMn, configured with SetCommState, and every read and write
// is bounded by SetCommTimeouts, so nothing here can hang. Windows opens a COM port for one
// program at a time (share mode 0); a named kernel object per port ("Local\wiresculpt-serial-
// COMn", gone with the process) keeps two wiresculpt streams off one port where the system does
// not (Wine lets a second handle open a COM port), as the POSIX back ends' lock file does.
// The ports listed are those Windows records under HKLM\HARDWARE\DEVICEMAP\SERIALCOMM.
#ifdef WIRESCULPT_SERIAL_BACKEND_WIN32
#ifndef WIN32_LEAN_AND_MEAN
#define WIN32_LEAN_AND_MEAN
#endif
#include <windows.h>

#include <algorithm>
#include <chrono>
#include <string>
#include <utility>
#include <vector>

#include "wiresculpt/error.hpp"
#include "wiresculpt/fab/serial.hpp"

namespace wiresculpt::fab {

namespace {
namespace win32 {

struct ReadTimeouts {
  DWORD interval, multiplier, constant;
};

std::string device_path(const std::string& name) {
  if (name.rfind("\\\\.\\", 0) == 0 || name.rfind("\\\\?\\", 0) == 0) return name;
  return "\\\\.\\" + name;  // COM10 and above open only by this path; COM1-9 by it too
}

ReadTimeouts read_timeouts(int timeout_ms) {
  // Documented special case: interval and multiplier MAXDWORD with a constant between 1 and
  // MAXDWORD-1 make ReadFile return at once with what is buffered, else as soon as one byte
  // arrives, else after the constant. Interval MAXDWORD with the rest 0 returns at once.
  if (timeout_ms <= 0) return {MAXDWORD, 0, 0};
  return {MAXDWORD, MAXDWORD, static_cast<DWORD>(std::min(timeout_ms, 24 * 3600 * 1000))};
}

// Sorting key: COM2 before COM10; names of another form after the COM ports, by name.
std::pair<long long, std::string> port_order(const std::string& name) {
  if (name.size() > 3 && (name.rfind("COM", 0) == 0 || name.rfind("com", 0) == 0) &&
      std::all_of(name.begin() + 3, name.end(), [](char c) { return c >= '0' && c <= '9'; }) && name.size() < 12)
    return {std::stoll(name.substr(3)), name};
  return {1LL << 40, name};
}

void fill_dcb(const SerialSettings& s, DCB& dcb) {
  dcb.DCBlength = sizeof(DCB);
  dcb.BaudRate = static_cast<DWORD>(s.baud);
  dcb.fBinary = TRUE;
  dcb.ByteSize = static_cast<BYTE>(s.data_bits);
  dcb.fParity = s.parity != SerialSettings::Parity::none;
  dcb.Parity = s.parity == SerialSettings::Parity::odd    ? ODDPARITY
               : s.parity == SerialSettings::Parity::even ? EVENPARITY
                                                          : NOPARITY;
  dcb.StopBits = s.stop_bits == 2 ? TWOSTOPBITS : ONESTOPBIT;
  const bool rts_cts = s.flow_control == SerialSettings::FlowControl::rts_cts;
  const bool xon_xoff = s.flow_control == SerialSettings::FlowControl::xon_xoff;
  dcb.fOutxCtsFlow = rts_cts;
  dcb.fRtsControl = rts_cts ? RTS_CONTROL_HANDSHAKE : RTS_CONTROL_ENABLE;
  dcb.fOutxDsrFlow = FALSE;
  dcb.fDsrSensitivity = FALSE;
  dcb.fDtrControl = DTR_CONTROL_ENABLE;  // as a POSIX open raises DTR (an Arduino GRBL restarts on it)
  dcb.fOutX = xon_xoff;
  dcb.fInX = xon_xoff;
  dcb.fTXContinueOnXoff = TRUE;
  dcb.XonChar = 0x11;
  dcb.XoffChar = 0x13;
  dcb.XonLim = 512;
  dcb.XoffLim = 512;
  dcb.fErrorChar = FALSE;
  dcb.fNull = FALSE;
  dcb.fAbortOnError = FALSE;  // a framing error must not stall every later read and write
}

}  // namespace win32

std::wstring widen(const std::string& utf8) {
  if (utf8.empty()) return {};
  const int n = ::MultiByteToWideChar(CP_UTF8, 0, utf8.data(), static_cast<int>(utf8.size()), nullptr, 0);
  std::wstring out(static_cast<std::size_t>(std::max(n, 0)), L'\0');
  if (n > 0) ::MultiByteToWideChar(CP_UTF8, 0, utf8.data(), static_cast<int>(utf8.size()), out.data(), n);
  return out;
}

std::string narrow(const wchar_t* text, int length) {
  if (length <= 0) return {};
  const int n = ::WideCharToMultiByte(CP_UTF8, 0, text, length, nullptr, 0, nullptr, nullptr);
  std::string out(static_cast<std::size_t>(std::max(n, 0)), '\0');
  if (n > 0) ::WideCharToMultiByte(CP_UTF8, 0, text, length, out.data(), n, nullptr, nullptr);
  return out;
}

// Windows' sentence for an error code, without its trailing ".\r\n"; the code when it has none.
std::string system_message(DWORD code) {
  wchar_t* text = nullptr;
  const DWORD n = ::FormatMessageW(FORMAT_MESSAGE_ALLOCATE_BUFFER | FORMAT_MESSAGE_FROM_SYSTEM |
                                       FORMAT_MESSAGE_IGNORE_INSERTS,
                                   nullptr, code, 0, reinterpret_cast<wchar_t*>(&text), 0, nullptr);
  std::string out = n ? narrow(text, static_cast<int>(n)) : std::string();
  if (text) ::LocalFree(text);
  while (!out.empty() && (out.back() == '\n' || out.back() == '\r' || out.back() == ' ' || out.back() == '.'))
    out.pop_back();
  return out.empty() ? "Windows error " + std::to_string(code) : out + " (Windows error " + std::to_string(code) + ")";
}

[[noreturn]] void open_failed(const std::string& name, const std::string& why) {
  throw InputError("could not open serial port '" + name + "': " + why);
}

}  // namespace

const char* serial_backend() { return "win32"; }

std::vector<PortInfo> list_ports() {
  std::vector<PortInfo> out;
  HKEY key = nullptr;
  if (::RegOpenKeyExW(HKEY_LOCAL_MACHINE, L"HARDWARE\\DEVICEMAP\\SERIALCOMM", 0, KEY_READ, &key) != ERROR_SUCCESS)
    return out;  // no serial devices at all: Windows makes the key with the first one
  for (DWORD i = 0;; ++i) {
    wchar_t device[256];
    wchar_t port[256];
    DWORD device_len = 256, port_bytes = sizeof port, type = 0;
    const LONG r = ::RegEnumValueW(key, i, device, &device_len, nullptr, &type, reinterpret_cast<BYTE*>(port),
                                   &port_bytes);
    if (r == ERROR_NO_MORE_ITEMS) break;
    if (r != ERROR_SUCCESS || type != REG_SZ) continue;
    int chars = static_cast<int>(port_bytes / sizeof(wchar_t));
    while (chars > 0 && port[chars - 1] == L'\0') --chars;
    PortInfo info;
    info.name = narrow(port, chars);
    info.description = narrow(device, static_cast<int>(device_len));  // e.g. \Device\USBSER000
    if (!info.name.empty()) out.push_back(info);
  }
  ::RegCloseKey(key);
  std::sort(out.begin(), out.end(), [](const PortInfo& a, const PortInfo& b) {
    return win32::port_order(a.name) < win32::port_order(b.name);
  });
  return out;
}

struct SerialPort::Impl {
  std::string name;
  HANDLE handle = INVALID_HANDLE_VALUE;
  HANDLE claim = nullptr;  // the port's named object while this stream holds it
  COMMTIMEOUTS timeouts{};  // what the port has now: set again only when a call needs others
  bool timeouts_set = false;

  ~Impl() {
    if (handle != INVALID_HANDLE_VALUE) ::CloseHandle(handle);
    if (claim) ::CloseHandle(claim);
  }

  bool use(const COMMTIMEOUTS& t) {
    if (timeouts_set && t.ReadIntervalTimeout == timeouts.ReadIntervalTimeout &&
        t.ReadTotalTimeoutMultiplier == timeouts.ReadTotalTimeoutMultiplier &&
        t.ReadTotalTimeoutConstant == timeouts.ReadTotalTimeoutConstant &&
        t.WriteTotalTimeoutMultiplier == timeouts.WriteTotalTimeoutMultiplier &&
        t.WriteTotalTimeoutConstant == timeouts.WriteTotalTimeoutConstant)
      return true;
    COMMTIMEOUTS copy = t;
    if (!::SetCommTimeouts(handle, &copy)) return false;
    timeouts = t;
    timeouts_set = true;
    return true;
  }
};

SerialPort::SerialPort(const std::string& name, const SerialSettings& settings) : impl_(std::make_unique<Impl>()) {
  impl_->name = name;
  if (name.empty()) open_failed(name, "no port name given");
  const std::wstring path = widen(win32::device_path(name));
  // The claim first: a second stream of this or another wiresculpt is refused before it touches
  // the port (the name is the port's, upper case, without the \\.\ prefix; "\" is not allowed in it).
  std::string key = name.rfind("\\\\", 0) == 0 ? name.substr(4) : name;
  for (char& c : key) c = c == '\\' ? '_' : static_cast<char>(c >= 'a' && c <= 'z' ? c - 'a' + 'A' : c);
  impl_->claim = ::CreateMutexW(nullptr, FALSE, widen("Local\\wiresculpt-serial-" + key).c_str());
  if (impl_->claim && ::GetLastError() == ERROR_ALREADY_EXISTS)
    throw InputError("serial port '" + name + "' is in use by another wiresculpt stream (in this or another "
                     "Blender); stop that stream first");
  // Share mode 0: no other program may open the port while we hold it, nor we while it does.
  impl_->handle = ::CreateFileW(path.c_str(), GENERIC_READ | GENERIC_WRITE, 0, nullptr, OPEN_EXISTING,
                                FILE_ATTRIBUTE_NORMAL, nullptr);
  if (impl_->handle == INVALID_HANDLE_VALUE) {
    const DWORD code = ::GetLastError();
    if (code == ERROR_ACCESS_DENIED || code == ERROR_SHARING_VIOLATION)
      throw InputError("serial port '" + name + "' is in use by another program (Windows lets one program open a "
                       "port at a time); stop that stream first");
    if (code == ERROR_FILE_NOT_FOUND || code == ERROR_PATH_NOT_FOUND)
      open_failed(name, "no such port (the ports Windows has are listed in Device Manager under Ports)");
    open_failed(name, system_message(code));
  }
  DCB dcb{};
  dcb.DCBlength = sizeof dcb;
  if (!::GetCommState(impl_->handle, &dcb)) open_failed(name, "not a serial device: " + system_message(::GetLastError()));
  win32::fill_dcb(settings, dcb);
  if (!::SetCommState(impl_->handle, &dcb))
    open_failed(name, "settings not accepted (baud " + std::to_string(settings.baud) + ", " +
                          std::to_string(settings.data_bits) + " data bits): " + system_message(::GetLastError()));
  const win32::ReadTimeouts r = win32::read_timeouts(0);
  COMMTIMEOUTS t{r.interval, r.multiplier, r.constant, 0, 2000};
  if (!impl_->use(t)) open_failed(name, "timeouts not accepted: " + system_message(::GetLastError()));
  ::PurgeComm(impl_->handle, PURGE_RXCLEAR | PURGE_TXCLEAR);
}

SerialPort::~SerialPort() = default;

const std::string& SerialPort::name() const { return impl_->name; }

bool SerialPort::write(const std::string& bytes, int timeout_ms) {
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::milliseconds(timeout_ms);
  std::size_t done = 0;
  while (done < bytes.size()) {
    const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(deadline - std::chrono::steady_clock::now());
    if (left.count() <= 0) return false;
    COMMTIMEOUTS t = impl_->timeouts;
    t.WriteTotalTimeoutMultiplier = 0;
    t.WriteTotalTimeoutConstant = static_cast<DWORD>(left.count());
    if (!impl_->use(t)) return false;
    DWORD written = 0;
    const DWORD chunk = static_cast<DWORD>(std::min<std::size_t>(bytes.size() - done, 1u << 20));
    if (!::WriteFile(impl_->handle, bytes.data() + done, chunk, &written, nullptr)) {
      DWORD errors = 0;
      ::ClearCommError(impl_->handle, &errors, nullptr);
      return false;  // the device is gone (unplugged) or refused the bytes
    }
    if (written == 0) return false;  // the time passed with nothing taken
    done += written;
  }
  return true;
}

int SerialPort::read(char* buffer, int size, int timeout_ms) {
  if (size <= 0) return 0;
  const win32::ReadTimeouts r = win32::read_timeouts(timeout_ms);
  COMMTIMEOUTS t = impl_->timeouts;
  t.ReadIntervalTimeout = r.interval;
  t.ReadTotalTimeoutMultiplier = r.multiplier;
  t.ReadTotalTimeoutConstant = r.constant;
  if (!impl_->use(t)) return -1;
  DWORD got = 0;
  DWORD errors = 0;
  if (!::ReadFile(impl_->handle, buffer, static_cast<DWORD>(size), &got, nullptr)) {
    ::ClearCommError(impl_->handle, &errors, nullptr);
    return -1;  // the device is gone (unplugged)
  }
  // Nothing in time: a quiet device, or one that hung up, which a read alone does not tell (Wine
  // reads a pty whose other end closed as silence); asking the port's state fails for the second.
  if (got == 0 && !::ClearCommError(impl_->handle, &errors, nullptr)) return -1;
  return static_cast<int>(got);
}

void SerialPort::drain_input(int timeout_ms) {
  ::PurgeComm(impl_->handle, PURGE_RXCLEAR);
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::milliseconds(timeout_ms);
  char buf[256];
  while (std::chrono::steady_clock::now() < deadline)
    if (read(buf, sizeof buf, 20) <= 0) break;
}

}  // namespace wiresculpt::fab

#endif  // WIRESCULPT_SERIAL_BACKEND_WIN32
