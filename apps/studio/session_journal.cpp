#include "studio/session_journal.hpp"

#include <cerrno>
#include <cstring>
#include <fcntl.h>
#include <fmt/format.h>
#include <unistd.h>

#include "cleave/core/error.hpp"
#include "cleave/io/atomic_file.hpp"

namespace cleave::studio {
namespace {

constexpr std::uintmax_t kMaxJournalBytes = std::uintmax_t{1} << 31;  // 2 GiB

[[noreturn]] void io_failure(const std::filesystem::path& file, const char* action) {
  throw InputError(fmt::format("{}: cannot {} the session journal: {}", file.string(), action, std::strerror(errno)));
}

void sync_folder(const std::filesystem::path& folder) {
  const int dir = ::open(folder.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (dir < 0) return;
  ::fsync(dir);
  ::close(dir);
}

}  // namespace

SessionJournal::SessionJournal(std::filesystem::path file) : file_(std::move(file)) {
  const bool existed = std::filesystem::exists(file_);
  std::size_t good_bytes = 0;
  if (existed) {
    const std::string text = read_file(file_, kMaxJournalBytes);
    std::size_t begin = 0;
    std::size_t line_number = 0;
    while (begin < text.size()) {
      ++line_number;
      const std::size_t end = text.find('\n', begin);
      const bool complete = end != std::string::npos;
      const std::string line = text.substr(begin, complete ? end - begin : std::string::npos);
      const std::size_t next = complete ? end + 1 : text.size();
      nlohmann::json entry = nlohmann::json::parse(line, nullptr, /*allow_exceptions=*/false);
      const bool valid = complete && entry.is_object() && entry.contains("seq") && entry["seq"].is_number_unsigned() &&
                         entry.contains("edit") && entry["edit"].is_object();
      if (!valid) {
        if (next == text.size()) {  // the torn tail of a write that never completed
          torn_bytes_ = text.size() - begin;
          break;
        }
        throw InputError(fmt::format("{}: line {} is not a journal entry {{\"seq\":N,\"edit\":{{...}}}}; the journal "
                                     "was changed outside the studio",
                                     file_.string(), line_number));
      }
      const std::uint64_t seq = entry["seq"].get<std::uint64_t>();
      if (seq != last_seq_ + 1)
        throw InputError(fmt::format("{}: line {} has seq {}; expected {}", file_.string(), line_number, seq, last_seq_ + 1));
      last_seq_ = seq;
      entries_.push_back(std::move(entry));
      good_bytes = next;
      begin = next;
    }
  }
  fd_ = ::open(file_.c_str(), O_WRONLY | O_CREAT | O_APPEND | O_CLOEXEC, 0644);
  if (fd_ < 0) io_failure(file_, "open");
  if (torn_bytes_ > 0) {
    if (::ftruncate(fd_, static_cast<off_t>(good_bytes)) != 0 || ::fdatasync(fd_) != 0) io_failure(file_, "repair");
  }
  if (!existed) sync_folder(file_.parent_path().empty() ? std::filesystem::path(".") : file_.parent_path());
}

SessionJournal::~SessionJournal() {
  if (fd_ >= 0) ::close(fd_);
}

std::uint64_t SessionJournal::append(const nlohmann::json& edit) {
  const std::uint64_t seq = last_seq_ + 1;
  const std::string line = nlohmann::json{{"seq", seq}, {"edit", edit}}.dump() + "\n";
  std::size_t written = 0;
  while (written < line.size()) {
    const ssize_t n = ::write(fd_, line.data() + written, line.size() - written);
    if (n < 0) {
      if (errno == EINTR) continue;
      io_failure(file_, "append to");
    }
    written += static_cast<std::size_t>(n);
  }
  if (::fdatasync(fd_) != 0) io_failure(file_, "flush");
  last_seq_ = seq;
  return seq;
}

}  // namespace cleave::studio
