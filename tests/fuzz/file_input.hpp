#pragma once
// Helper for fuzz targets whose parser reads a file: writes the input to a per-process temporary
// file with the extension the format needs.
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <string>
#include <unistd.h>

namespace cleave::fuzz {

inline std::filesystem::path write_input(const std::uint8_t* data, std::size_t size, const std::string& extension) {
  const auto file = std::filesystem::temp_directory_path() / ("cleave_fuzz_" + std::to_string(::getpid()) + extension);
  std::ofstream out(file, std::ios::binary | std::ios::trunc);
  out.write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(size));
  return file;
}

}  // namespace cleave::fuzz
