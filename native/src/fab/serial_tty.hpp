#pragma once
// A serial port as a POSIX terminal device (termios), shared by the two POSIX back ends: the
// termios back end (serial_posix.cpp: macOS, or any POSIX system built with
// WIRESCULPT_SERIAL_BACKEND=posix) and the libserialport back end (serial_port.cpp), which opens
// the devices libserialport does not know (pseudo-terminals) this way. Compiled on every system
// but Windows; private to the core (the native tests include it to test its parts one by one).
#include <string>
#include <vector>

#include "wiresculpt/fab/serial.hpp"

namespace wiresculpt::fab::tty {

[[noreturn]] void open_failed(const std::string& name, const std::string& why);

/// The lock file that keeps two streams off one port, held with flock() (the system releases it
/// when the process ends, so a crash leaves no stale lock).
struct Lock {
  int fd = -1;
  std::string path;
  ~Lock();  ///< removes the file (while still locked: nobody else holds it) and closes it
};

/// LCK..<device> (UUCP's name; "/" after /dev/ becomes "_") in $WIRESCULPT_LOCK_DIR, else
/// /var/lock when writable, else /tmp.
std::string lock_path_for(const std::string& port);

/// Takes the lock of `port`; throws InputError "serial port '...' is in use by process N (name)"
/// when another stream holds it.
void take_lock(const std::string& port, Lock& lock);

/// Opens `port` read/write, without becoming its controlling terminal, non-blocking, as raw
/// bytes with the settings (8N1 at the baud by default), takes flock(LOCK_EX|LOCK_NB) on the
/// device itself (as pyserial's exclusive mode does) and TIOCEXCL. Returns the descriptor; throws
/// InputError naming the port and why (no such port, in use, not a serial device, settings).
int open_device(const std::string& port, const SerialSettings& settings);

/// Clears TIOCEXCL (it outlives our descriptor while anyone else keeps the tty open) and closes.
void close_device(int fd);

enum class Ready { ready, timeout, hangup, failed };

/// Waits until fd can be read (or written), at most timeout_ms. poll() where it works on
/// terminal devices; on macOS, whose poll() "does not support devices" (poll(2), BUGS), select().
Ready wait_ready(int fd, bool for_write, int timeout_ms);
Ready wait_ready_poll(int fd, bool for_write, int timeout_ms);
Ready wait_ready_select(int fd, bool for_write, int timeout_ms);

/// Writes all bytes within timeout_ms; false when the link is lost or the time passed.
bool write_all(int fd, const std::string& bytes, int timeout_ms);
/// Reads what is there, waiting at most timeout_ms for the first byte: the count, 0 (nothing in
/// time) or -1 (the other end hung up: POLLHUP, read() == 0 on a readable tty, or EIO).
int read_some(int fd, char* buffer, int size, int timeout_ms);
/// Discards what the system holds (tcflush), then what arrives within timeout_ms.
void drain(int fd, int timeout_ms);

/// The devices in `dir` whose names start with one of `prefixes`, sorted with numbers in
/// numeric order (ttyUSB2 before ttyUSB10). The description is the USB product string found
/// under `sys_class_tty`/<name>/device (Linux's sysfs; "" to skip), else the name's tail.
std::vector<PortInfo> list_devices(const std::string& dir, const std::vector<std::string>& prefixes,
                                   const std::string& sys_class_tty);

/// The serial devices of this system: /dev/cu.* on macOS; /dev/ttyUSB*, /dev/ttyACM* elsewhere.
std::vector<PortInfo> list_system_devices();

}  // namespace wiresculpt::fab::tty
