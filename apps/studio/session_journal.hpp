#pragma once
// The session journal: every acknowledged edit as one JSON line {"seq":N,"edit":{...}} in an
// append-only file, flushed to disk (fdatasync) before the edit is acknowledged. Reopening the
// file returns the entries to replay. A server killed in the middle of a write can leave only
// the last line incomplete: that torn tail is dropped (it was never acknowledged) and the file
// is truncated back to the last complete entry, so later appends stay well formed.
//
//   SessionJournal journal(folder / "journal.jsonl");
//   for (const auto& e : journal.entries()) replay(e["edit"]);
//   journal.append(edit);    // durable when this returns
//
// Errors: InputError naming the file and line for a corrupt line before the last one or a
// sequence gap (the file was edited by hand), or when the file cannot be opened or written.
#include <cstdint>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <vector>

namespace cleave::studio {

class SessionJournal {
 public:
  explicit SessionJournal(std::filesystem::path file);
  ~SessionJournal();
  SessionJournal(const SessionJournal&) = delete;
  SessionJournal& operator=(const SessionJournal&) = delete;

  /// The entries found when the file was opened, oldest first (each {"seq":N,"edit":{...}}).
  const std::vector<nlohmann::json>& entries() const { return entries_; }
  /// Bytes of an incomplete last line that were dropped on opening (0 normally).
  std::size_t torn_bytes_dropped() const { return torn_bytes_; }
  /// Sequence number of the last entry (0 when empty).
  std::uint64_t last_seq() const { return last_seq_; }

  /// Appends {"seq": last_seq()+1, "edit": edit}, flushes it to disk and returns its seq.
  std::uint64_t append(const nlohmann::json& edit);

  const std::filesystem::path& file() const { return file_; }

 private:
  std::filesystem::path file_;
  int fd_ = -1;
  std::vector<nlohmann::json> entries_;
  std::size_t torn_bytes_ = 0;
  std::uint64_t last_seq_ = 0;
};

}  // namespace cleave::studio
