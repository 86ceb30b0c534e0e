#include "cleave/io/atomic_file.hpp"

#include <cerrno>
#include <cstring>
#include <fcntl.h>
#include <fmt/format.h>
#include <fstream>
#include <sstream>
#include <unistd.h>

#include "cleave/core/error.hpp"

namespace cleave {

void write_file_atomically(const std::filesystem::path& file, std::string_view content) {
  std::error_code ec;
  if (file.has_parent_path()) std::filesystem::create_directories(file.parent_path(), ec);
  const std::filesystem::path temp = file.string() + ".tmp" + std::to_string(::getpid());
  const int fd = ::open(temp.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (fd < 0) throw InputError(fmt::format("{}: cannot write ({})", file.string(), std::strerror(errno)));
  std::size_t written = 0;
  while (written < content.size()) {
    const ssize_t n = ::write(fd, content.data() + written, content.size() - written);
    if (n < 0) {
      if (errno == EINTR) continue;
      const int err = errno;
      ::close(fd);
      std::filesystem::remove(temp, ec);
      throw InputError(fmt::format("{}: cannot write ({})", file.string(), std::strerror(err)));
    }
    written += static_cast<std::size_t>(n);
  }
  ::fsync(fd);
  ::close(fd);
  std::filesystem::rename(temp, file, ec);
  if (ec) {
    std::filesystem::remove(temp, ec);
    throw InputError(fmt::format("{}: cannot replace the file ({})", file.string(), ec.message()));
  }
}

std::string read_file(const std::filesystem::path& file, std::uintmax_t max_bytes) {
  std::error_code ec;
  if (!std::filesystem::exists(file, ec)) throw InputError(fmt::format("{}: no such file", file.string()));
  if (std::filesystem::is_directory(file, ec)) throw InputError(fmt::format("{}: is a folder, expected a file", file.string()));
  const auto size = std::filesystem::file_size(file, ec);
  if (ec) throw InputError(fmt::format("{}: cannot read ({})", file.string(), ec.message()));
  if (size > max_bytes)
    throw InputError(fmt::format("{}: {} bytes is larger than the limit of {} bytes", file.string(), size, max_bytes));
  std::ifstream in(file, std::ios::binary);
  if (!in) throw InputError(fmt::format("{}: cannot open for reading", file.string()));
  std::ostringstream buffer;
  buffer << in.rdbuf();
  return buffer.str();
}

}  // namespace cleave
