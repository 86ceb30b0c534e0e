// libFuzzer target: the studio's WebSocket text messages. The input is one or more messages
// separated by the record-separator byte 0x1e (so that sequences such as edit, undo, save, load
// are explored); each goes through handle_message on a fresh session (a small plate in a
// per-process temporary folder) exactly as the server does: the reply and, after an edit, the
// broadcast state must serialise (nlohmann's dump throws on invalid UTF-8). Any crash, leak,
// UB or escaping exception is a finding; error replies are the expected outcome.
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>
#include <string_view>
#include <unistd.h>

#include "studio/message_handler.hpp"
#include "studio/studio_session.hpp"

namespace {

constexpr std::size_t kMaxMessagesPerInput = 16;

nlohmann::json small_plate() {
  return {{"cleave_case", 1}, {"model", {{"source", "plate"}, {"resolution", {8, 8, 2}}}}};
}

std::filesystem::path session_folder() {
  return std::filesystem::temp_directory_path() / ("cleave_fuzz_studio_" + std::to_string(::getpid()));
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const auto folder = session_folder();
  std::filesystem::remove_all(folder);
  cleave::studio::StudioSession session(folder, small_plate());
  const std::string_view input(reinterpret_cast<const char*>(data), size);
  std::size_t start = 0;
  for (std::size_t n = 0; n < kMaxMessagesPerInput && start <= input.size(); ++n) {
    std::size_t end = input.find('\x1e', start);
    if (end == std::string_view::npos) end = input.size();
    const auto outcome = cleave::studio::handle_message(session, input.substr(start, end - start), nullptr);
    (void)outcome.reply.dump();
    if (outcome.design_changed) (void)session.state_message().dump();
    start = end + 1;
  }
  return 0;
}
