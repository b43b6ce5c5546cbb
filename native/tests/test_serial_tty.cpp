// The POSIX terminal parts of the serial back ends (serial_tty.cpp: the posix back end, macOS's,
// and libserialport's pty path), one by one: the port list from a directory, the settings a
// device is left with (read back from the other descriptor of a pty pair), the refusals, and the
// two ways of waiting (poll; select, macOS's), with a hang-up as each sees it. Run in both the
// main test binary and the posix back end's (wiresculpt_serial_posix_tests).
#include <catch2/catch.hpp>
#include <fcntl.h>
#include <pty.h>
#include <sys/stat.h>
#include <termios.h>
#include <unistd.h>

#include <chrono>
#include <cstdlib>
#include <fstream>
#include <string>
#include <vector>

#include "fab/serial_tty.hpp"
#include "wiresculpt/error.hpp"
#include "wiresculpt/fab/serial.hpp"

using namespace wiresculpt;
using namespace wiresculpt::fab;
using Catch::Matchers::Contains;

namespace {

struct TempDir {
  std::string path;
  TempDir() {
    char tmpl[] = "/tmp/wiresculpt-tty-XXXXXX";
    REQUIRE(::mkdtemp(tmpl) != nullptr);
    path = tmpl;
  }
  ~TempDir() {
    const std::string cmd = "rm -rf '" + path + "'";
    if (std::system(cmd.c_str()) != 0) { /* a leftover temp folder */ }
  }
  void touch(const std::string& rel, const std::string& text = "") const {
    std::ofstream(path + "/" + rel) << text;
  }
  void mkdirs(const std::string& rel) const {
    const std::string cmd = "mkdir -p '" + path + "/" + rel + "'";
    REQUIRE(std::system(cmd.c_str()) == 0);
  }
};

struct Pty {
  int master = -1, slave = -1;
  std::string path;
  Pty() {
    char name[256] = {};
    REQUIRE(::openpty(&master, &slave, name, nullptr, nullptr) == 0);
    path = name;
  }
  ~Pty() {
    if (master >= 0) ::close(master);
    if (slave >= 0) ::close(slave);
  }
  void hang_up() {
    ::close(master);
    master = -1;
  }
};

std::vector<std::string> names(const std::vector<PortInfo>& ports) {
  std::vector<std::string> out;
  for (const auto& p : ports) out.push_back(p.name);
  return out;
}

}  // namespace

TEST_CASE("serial: the build's serial back end is the one configured", "[fab][serial]") {
  CHECK(std::string(serial_backend()) == WIRESCULPT_TEST_SERIAL_BACKEND);
}

TEST_CASE("serial tty: the ports listed are the devices with the platform's prefixes, numbers in order",
          "[fab][serial]") {
  TempDir dev;
  for (const char* n : {"ttyUSB10", "ttyUSB2", "ttyACM0", "ttyS0", "ttyUSB", "tty", "cu.usbserial-1410",
                        "tty.usbserial-1410", "cu.Bluetooth-Incoming-Port"})
    dev.touch(n);
  const auto linux_ports = tty::list_devices(dev.path, {"ttyUSB", "ttyACM"}, "");
  CHECK(names(linux_ports) ==
        std::vector<std::string>{dev.path + "/ttyACM0", dev.path + "/ttyUSB2", dev.path + "/ttyUSB10"});
  CHECK(linux_ports[1].description == "ttyUSB2");  // no sysfs: the name
  const auto mac_ports = tty::list_devices(dev.path, {"cu."}, "");
  CHECK(names(mac_ports) ==
        std::vector<std::string>{dev.path + "/cu.Bluetooth-Incoming-Port", dev.path + "/cu.usbserial-1410"});
  CHECK(mac_ports[1].description == "usbserial-1410");
  CHECK(tty::list_devices(dev.path + "/missing", {"ttyUSB"}, "").empty());
}

TEST_CASE("serial tty: a port's description is its USB product string from sysfs", "[fab][serial]") {
  // Linux's layout: class/tty/<name>/device links to the port's device (ttyUSB: the usb-serial
  // port below the interface; ttyACM: the interface), the product string on the USB device above.
  TempDir sys;
  sys.mkdirs("devices/usb1/1-1/1-1:1.0/ttyUSB0");
  sys.mkdirs("devices/usb1/1-2/1-2:1.0");
  sys.touch("devices/usb1/1-1/product", "USB2.0-Serial\n");
  sys.touch("devices/usb1/1-2/product", "Arduino Uno\n");
  sys.mkdirs("class/tty/ttyUSB0");
  sys.mkdirs("class/tty/ttyACM0");
  REQUIRE(::symlink((sys.path + "/devices/usb1/1-1/1-1:1.0/ttyUSB0").c_str(),
                    (sys.path + "/class/tty/ttyUSB0/device").c_str()) == 0);
  REQUIRE(::symlink((sys.path + "/devices/usb1/1-2/1-2:1.0").c_str(), (sys.path + "/class/tty/ttyACM0/device").c_str()) ==
          0);
  TempDir dev;
  dev.touch("ttyUSB0");
  dev.touch("ttyACM0");
  dev.touch("ttyUSB1");  // no sysfs entry
  const auto ports = tty::list_devices(dev.path, {"ttyUSB", "ttyACM"}, sys.path + "/class/tty");
  REQUIRE(ports.size() == 3);
  CHECK(ports[0].description == "Arduino Uno");    // ttyACM0
  CHECK(ports[1].description == "USB2.0-Serial");  // ttyUSB0
  CHECK(ports[2].description == "ttyUSB1");
}

TEST_CASE("serial tty: a device is left raw, 8N1 at the profile's baud", "[fab][serial]") {
  Pty pty;
  SerialSettings s;
  s.baud = 115200;
  const int fd = tty::open_device(pty.path, s);
  termios t{};
  REQUIRE(::tcgetattr(pty.slave, &t) == 0);  // the same terminal, asked through the other descriptor
  CHECK(::cfgetospeed(&t) == B115200);
  CHECK(::cfgetispeed(&t) == B115200);
  CHECK((t.c_cflag & CSIZE) == CS8);
  CHECK((t.c_cflag & (PARENB | CSTOPB | CRTSCTS)) == 0);
  CHECK((t.c_lflag & (ICANON | ECHO | ISIG)) == 0);
  CHECK((t.c_iflag & (IXON | IXOFF | ICRNL)) == 0);
  CHECK((t.c_oflag & OPOST) == 0);
  CHECK((::fcntl(fd, F_GETFL) & O_NONBLOCK) != 0);
  tty::close_device(fd);

  s.baud = 9600;
  s.parity = SerialSettings::Parity::even;
  s.stop_bits = 2;
  s.data_bits = 7;
  const int fd2 = tty::open_device(pty.path, s);
  REQUIRE(::tcgetattr(pty.slave, &t) == 0);
  CHECK(::cfgetospeed(&t) == B9600);
  CHECK((t.c_cflag & CSTOPB) != 0);  // (Linux's ptys keep CS8 without parity whatever is asked)
  tty::close_device(fd2);
}

TEST_CASE("serial tty: no such port, not a terminal, a baud the system lacks, a device already held",
          "[fab][serial][robustness]") {
  SerialSettings s;
  CHECK_THROWS_WITH(tty::open_device("/dev/does-not-exist", s),
                    Contains("'/dev/does-not-exist'") && Contains("no such port"));
  TempDir dir;
  dir.touch("plain");
  CHECK_THROWS_WITH(tty::open_device(dir.path + "/plain", s), Contains("not a serial device"));
  Pty pty;
  s.baud = 12345;
  CHECK_THROWS_WITH(tty::open_device(pty.path, s), Contains("baud rate 12345 is not supported"));
  s.baud = 115200;
  const int fd = tty::open_device(pty.path, s);
  // Held: flock() on the device (and TIOCEXCL, which does not stop root) refuses a second open.
  CHECK_THROWS_WITH(tty::open_device(pty.path, s), Contains("is in use by another program"));
  tty::close_device(fd);
  const int again = tty::open_device(pty.path, s);  // released with the descriptor
  CHECK(again >= 0);
  tty::close_device(again);
}

TEST_CASE("serial tty: reads wait at most their timeout, return what arrives, and see a hang-up",
          "[fab][serial][robustness]") {
  Pty pty;
  const int fd = tty::open_device(pty.path, SerialSettings{});
  char buf[64];
  const auto t0 = std::chrono::steady_clock::now();
  CHECK(tty::read_some(fd, buf, sizeof buf, 100) == 0);
  const double waited = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  CHECK(waited >= 0.09);
  CHECK(waited < 1.0);
  REQUIRE(::write(pty.master, "ok\r\n", 4) == 4);
  CHECK(tty::read_some(fd, buf, sizeof buf, 1000) == 4);
  CHECK(std::string(buf, 4) == "ok\r\n");
  CHECK(tty::write_all(fd, "G4 P0\n", 1000));
  char got[16] = {};
  REQUIRE(tty::wait_ready_poll(pty.master, false, 1000) == tty::Ready::ready);
  CHECK(::read(pty.master, got, sizeof got) == 6);
  CHECK(std::string(got, 6) == "G4 P0\n");
  // drain: what was sent before it is gone, nothing waits after it
  REQUIRE(::write(pty.master, "Grbl 1.1h\r\n", 11) == 11);
  tty::drain(fd, 100);
  CHECK(tty::read_some(fd, buf, sizeof buf, 50) == 0);
  pty.hang_up();
  CHECK(tty::read_some(fd, buf, sizeof buf, 1000) == -1);
  CHECK_FALSE(tty::write_all(fd, "G1 X1\n", 200));
  tty::close_device(fd);
}

TEST_CASE("serial tty: select(), macOS's way of waiting, times out, wakes on data and on a hang-up",
          "[fab][serial][robustness]") {
  Pty pty;
  const int fd = tty::open_device(pty.path, SerialSettings{});
  const auto t0 = std::chrono::steady_clock::now();
  CHECK(tty::wait_ready_select(fd, false, 100) == tty::Ready::timeout);
  const double waited = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  CHECK(waited >= 0.09);
  CHECK(waited < 1.0);
  CHECK(tty::wait_ready_select(fd, true, 100) == tty::Ready::ready);
  REQUIRE(::write(pty.master, "ok\r\n", 4) == 4);
  CHECK(tty::wait_ready_select(fd, false, 1000) == tty::Ready::ready);
  char buf[16];
  CHECK(::read(fd, buf, sizeof buf) == 4);
  pty.hang_up();
  // A hung-up terminal is readable, and the read says it is gone: 0 bytes (macOS) or EIO (Linux).
  CHECK(tty::wait_ready_select(fd, false, 1000) == tty::Ready::ready);
  CHECK(::read(fd, buf, sizeof buf) <= 0);
  CHECK(tty::wait_ready_select(-1, false, 10) == tty::Ready::failed);
  tty::close_device(fd);
}
