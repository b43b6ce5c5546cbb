#pragma once
// Writing result files so that an interrupted export loses nothing: the text goes to a temporary
// file in the same folder, is flushed to disk, then std::filesystem::rename replaces the target
// in one step. Readers see the old file or the new one, never a partial one.
#include <filesystem>
#include <string_view>

namespace wiresculpt::fab {

/// Writes `text` to `path` atomically. Throws InputError naming the path (and the system's
/// reason) when the folder is missing or not writable, the disk is full, or the rename fails;
/// in every failure the temporary file is removed and an existing `path` is left untouched.
void write_file_atomic(const std::filesystem::path& path, std::string_view text);

}  // namespace wiresculpt::fab
