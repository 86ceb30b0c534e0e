#pragma once
// Writing files so that nothing already saved is lost: the content goes to a temporary file in
// the same folder, is flushed to disk, and then renamed over the target in one step.
#include <cstdint>
#include <filesystem>
#include <string>
#include <string_view>

namespace cleave {

/// Writes `content` to `file` atomically (temporary + fsync + rename). Creates missing parent
/// folders. Throws InputError naming the file when it cannot be written.
void write_file_atomically(const std::filesystem::path& file, std::string_view content);

/// Reads a whole file; throws InputError naming the file when it is missing or unreadable.
/// Refuses files larger than `max_bytes` (InputError saying the size and the limit).
std::string read_file(const std::filesystem::path& file, std::uintmax_t max_bytes = std::uintmax_t{1} << 32);

}  // namespace cleave
