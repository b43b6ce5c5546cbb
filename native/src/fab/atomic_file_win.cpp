// write_file_atomic on Windows (atomic_file.cpp is the POSIX one): the text goes to a temporary
// file beside the target, is flushed to the disk (FlushFileBuffers), and replaces the target in one
// MoveFileExW(MOVEFILE_REPLACE_EXISTING | MOVEFILE_WRITE_THROUGH); a failure removes the temporary
// file and leaves the target as it was.
#ifdef _WIN32
#include "wiresculpt/fab/atomic_file.hpp"

#include <windows.h>

#include <string>
#include <system_error>

#include "wiresculpt/error.hpp"

namespace wiresculpt::fab {
namespace {

[[noreturn]] void fail(const std::filesystem::path& path, const std::string& reason) {
  throw InputError("could not write '" + path.string() + "': " + reason);
}

std::string last_error() { return std::system_category().message(static_cast<int>(::GetLastError())); }

}  // namespace

void write_file_atomic(const std::filesystem::path& path, std::string_view text) {
  if (path.empty() || !path.has_filename()) fail(path, "the path names no file");
  const std::filesystem::path folder = path.has_parent_path() ? path.parent_path() : std::filesystem::path(".");
  HANDLE handle = INVALID_HANDLE_VALUE;
  std::filesystem::path temp;
  for (unsigned attempt = 0; attempt < 100 && handle == INVALID_HANDLE_VALUE; ++attempt) {
    temp = folder / (L"." + path.filename().wstring() + L".tmp-" + std::to_wstring(::GetCurrentProcessId()) + L"-" +
                     std::to_wstring(::GetTickCount64() + attempt));
    handle = ::CreateFileW(temp.c_str(), GENERIC_WRITE, 0, nullptr, CREATE_NEW, FILE_ATTRIBUTE_NORMAL, nullptr);
    if (handle == INVALID_HANDLE_VALUE && ::GetLastError() != ERROR_FILE_EXISTS) fail(path, last_error());
  }
  if (handle == INVALID_HANDLE_VALUE) fail(path, "no temporary file name was free beside it");
  auto abandon = [&](const std::string& reason) {
    ::CloseHandle(handle);
    ::DeleteFileW(temp.c_str());
    fail(path, reason);
  };
  const char* data = text.data();
  std::size_t left = text.size();
  while (left > 0) {
    const DWORD chunk = static_cast<DWORD>(left < (1u << 30) ? left : (1u << 30));
    DWORD written = 0;
    if (!::WriteFile(handle, data, chunk, &written, nullptr)) abandon(last_error());
    data += written;
    left -= written;
  }
  if (!::FlushFileBuffers(handle)) abandon(last_error());
  if (!::CloseHandle(handle)) {
    const std::string reason = last_error();
    ::DeleteFileW(temp.c_str());
    fail(path, reason);
  }
  if (!::MoveFileExW(temp.c_str(), path.c_str(), MOVEFILE_REPLACE_EXISTING | MOVEFILE_WRITE_THROUGH)) {
    const std::string reason = last_error();
    ::DeleteFileW(temp.c_str());
    fail(path, reason);
  }
}

}  // namespace wiresculpt::fab
#endif  // _WIN32
