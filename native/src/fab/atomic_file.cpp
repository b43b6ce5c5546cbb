#include "wiresculpt/fab/atomic_file.hpp"

#ifndef _WIN32  // Windows: atomic_file_win.cpp
#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <string>
#include <system_error>
#include <vector>

#include "wiresculpt/error.hpp"

namespace wiresculpt::fab {
namespace {

[[noreturn]] void fail(const std::filesystem::path& path, const std::string& reason) {
  throw InputError("could not write '" + path.string() + "': " + reason);
}

}  // namespace

void write_file_atomic(const std::filesystem::path& path, std::string_view text) {
  if (path.empty() || !path.has_filename()) fail(path, "the path names no file");
  const std::filesystem::path folder = path.has_parent_path() ? path.parent_path() : std::filesystem::path(".");
  std::string temp_name = ".";
  temp_name.append(path.filename().string());
  temp_name.append(".tmp-XXXXXX");
  const std::string pattern = (folder / temp_name).string();
  std::vector<char> name(pattern.begin(), pattern.end());
  name.push_back('\0');
  const int fd = ::mkstemp(name.data());
  if (fd < 0) fail(path, std::strerror(errno));
  const std::filesystem::path temp(name.data());
  auto abandon = [&](const std::string& reason) {
    ::close(fd);
    std::error_code ignored;
    std::filesystem::remove(temp, ignored);
    fail(path, reason);
  };
  const char* data = text.data();
  std::size_t left = text.size();
  while (left > 0) {
    const ssize_t w = ::write(fd, data, left);
    if (w < 0) {
      if (errno == EINTR) continue;
      abandon(std::strerror(errno));
    }
    data += w;
    left -= static_cast<std::size_t>(w);
  }
  if (::fchmod(fd, 0644) != 0) abandon(std::strerror(errno));
  if (::fsync(fd) != 0) abandon(std::strerror(errno));
  if (::close(fd) != 0) {
    const std::string reason = std::strerror(errno);
    std::error_code ignored;
    std::filesystem::remove(temp, ignored);
    fail(path, reason);
  }
  std::error_code ec;
  std::filesystem::rename(temp, path, ec);
  if (ec) {
    std::error_code ignored;
    std::filesystem::remove(temp, ignored);
    fail(path, ec.message());
  }
}

}  // namespace wiresculpt::fab
#endif  // _WIN32
