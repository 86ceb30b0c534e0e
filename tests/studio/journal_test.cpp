// The session journal: durable appends, replay, a torn tail dropped and repaired, corruption refused.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <unistd.h>

#include "cleave/core/error.hpp"
#include "cleave/io/atomic_file.hpp"
#include "studio/session_journal.hpp"

namespace cleave::studio {
namespace {

std::filesystem::path fresh_folder(const std::string& name) {
  const auto dir = std::filesystem::temp_directory_path() / ("cleave-studio-test-" + name + "-" + std::to_string(::getpid()));
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  return dir;
}

std::string read_all(const std::filesystem::path& f) { return read_file(f); }

TEST(SessionJournal, AppendsAreNumberedAndReplayedInOrder) {
  const auto file = fresh_folder("append") / "journal.jsonl";
  {
    SessionJournal j(file);
    EXPECT_TRUE(j.entries().empty());
    EXPECT_EQ(j.append({{"cmd", "a"}}), 1u);
    EXPECT_EQ(j.append({{"cmd", "b"}}), 2u);
    EXPECT_EQ(j.append({{"cmd", "c"}}), 3u);
  }
  SessionJournal j(file);
  ASSERT_EQ(j.entries().size(), 3u);
  EXPECT_EQ(j.entries()[0]["edit"]["cmd"], "a");
  EXPECT_EQ(j.entries()[2]["seq"], 3);
  EXPECT_EQ(j.last_seq(), 3u);
  EXPECT_EQ(j.append({{"cmd", "d"}}), 4u);
}

TEST(SessionJournal, TornLastLineIsDroppedAndTheFileRepaired) {
  const auto file = fresh_folder("torn") / "journal.jsonl";
  {
    SessionJournal j(file);
    j.append({{"cmd", "a"}});
    j.append({{"cmd", "b"}});
  }
  const std::string good = read_all(file);
  const std::string torn = R"({"seq":3,"edit":{"cmd":"add_str)";
  {
    std::ofstream out(file, std::ios::app | std::ios::binary);
    out << torn;
  }
  {
    SessionJournal j(file);
    EXPECT_EQ(j.entries().size(), 2u);
    EXPECT_EQ(j.torn_bytes_dropped(), torn.size());
    EXPECT_EQ(read_all(file), good);  // truncated back to the last complete entry
    EXPECT_EQ(j.append({{"cmd", "c"}}), 3u);
  }
  SessionJournal j(file);
  ASSERT_EQ(j.entries().size(), 3u);
  EXPECT_EQ(j.entries()[2]["edit"]["cmd"], "c");
  EXPECT_EQ(j.torn_bytes_dropped(), 0u);
}

TEST(SessionJournal, ACompleteButUnterminatedLastLineIsAlsoTorn) {
  // A line is acknowledged only with its newline: without it the write did not complete.
  const auto file = fresh_folder("noeol") / "journal.jsonl";
  {
    std::ofstream out(file, std::ios::binary);
    out << R"({"seq":1,"edit":{"cmd":"a"}})" << "\n" << R"({"seq":2,"edit":{"cmd":"b"}})";
  }
  SessionJournal j(file);
  EXPECT_EQ(j.entries().size(), 1u);
  EXPECT_GT(j.torn_bytes_dropped(), 0u);
}

TEST(SessionJournal, CorruptionBeforeTheLastLineIsRefusedWithTheLineNumber) {
  const auto file = fresh_folder("corrupt") / "journal.jsonl";
  {
    std::ofstream out(file, std::ios::binary);
    out << R"({"seq":1,"edit":{"cmd":"a"}})" << "\n" << "garbage\n" << R"({"seq":2,"edit":{"cmd":"b"}})" << "\n";
  }
  try {
    SessionJournal j(file);
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("line 2 is not a journal entry"), std::string::npos) << e.what();
  }
}

TEST(SessionJournal, ASequenceGapIsRefused) {
  const auto file = fresh_folder("gap") / "journal.jsonl";
  {
    std::ofstream out(file, std::ios::binary);
    out << R"({"seq":1,"edit":{"cmd":"a"}})" << "\n" << R"({"seq":3,"edit":{"cmd":"b"}})" << "\n";
  }
  try {
    SessionJournal j(file);
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("line 2 has seq 3; expected 2"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace cleave::studio
