#include "studio/message_handler.hpp"

#include <fmt/format.h>

#include "cleave/core/error.hpp"
#include "cleave/io/json_fields.hpp"
#include "studio/design_edit.hpp"
#include "studio/design_limits.hpp"
#include "studio/path_safety.hpp"

namespace cleave::studio {
namespace {

constexpr std::size_t kMaxRequestTagBytes = 64;
constexpr const char* kCommandList =
    "hello, get_state, ping, undo, redo, save, load, export, add_stroke, move_stroke, delete_stroke, "
    "add_control_point, set_control_point, delete_control_point, add_cut, delete_cut, reset_cuts";

nlohmann::json error_reply(const nlohmann::json& req, const std::string& message) {
  nlohmann::json r = {{"type", "error"}, {"message", message}};
  if (!req.is_null()) r["req"] = req;
  return r;
}

std::string file_field(const nlohmann::json& message, const std::string& cmd) {
  const nlohmann::json* file = json_find(message, "file");
  if (!file) json_missing(JsonPath{cmd, "/file"}, "a file name inside the session folder");
  return json_string(*file, JsonPath{cmd, "/file"});
}

ExportFormat export_format(const nlohmann::json& message) {
  const nlohmann::json* f = json_find(message, "format");
  if (!f) json_missing(JsonPath{"export", "/format"}, "\"vtu\", \"ply\" or \"gltf\"");
  const std::string s = json_string(*f, JsonPath{"export", "/format"});
  if (s == "vtu") return ExportFormat::vtu;
  if (s == "ply") return ExportFormat::ply;
  if (s == "gltf") return ExportFormat::gltf;
  json_error(JsonPath{"export", "/format"}, *f, "\"vtu\", \"ply\" or \"gltf\"");
}

MessageOutcome dispatch(StudioSession& session, const nlohmann::json& message,
                        const ExportFn& exporter) {
  const nlohmann::json* cmd_value = json_find(message, "cmd");
  if (!cmd_value || !cmd_value->is_string())
    throw InputError(fmt::format("message: \"cmd\" is {}; expected a command name ({})",
                                 cmd_value ? utf8_prefix(cmd_value->dump(), 80) : "missing", kCommandList));
  const std::string cmd = cmd_value->get<std::string>();
  MessageOutcome out;
  if (cmd == "hello" || cmd == "get_state") {
    out.reply = session.state_message();
  } else if (cmd == "ping") {
    out.reply = {{"type", "pong"}};
  } else if (cmd == "undo" || cmd == "redo" || is_design_edit(cmd)) {
    nlohmann::json edit = message;
    edit.erase("req");
    const std::uint64_t seq = session.apply_edit(edit);
    out.reply = {{"type", "ack"}, {"cmd", cmd}, {"seq", seq}};
    out.design_changed = true;
  } else if (cmd == "save") {
    const auto file = session.save_case(file_field(message, cmd));
    out.reply = {{"type", "saved"}, {"file", file.filename().string()}};
  } else if (cmd == "load") {
    const std::uint64_t seq = session.apply_edit(session.load_case_edit(file_field(message, cmd)));
    out.reply = {{"type", "ack"}, {"cmd", cmd}, {"seq", seq}};
    out.design_changed = true;
  } else if (cmd == "export") {
    const ExportFormat format = export_format(message);
    const std::string name = file_field(message, cmd);
    const auto file = require_inside(session.folder(), name, "export: file");
    const char* expected = format == ExportFormat::vtu ? ".vtu" : format == ExportFormat::ply ? ".ply" : ".gltf";
    if (file.extension() != expected) throw InputError(fmt::format("export: file '{}' must end in {}", name, expected));
    if (!exporter) throw InputError("export: no result to export yet");
    exporter(format, file);
    out.reply = {{"type", "exported"}, {"file", file.filename().string()}};
  } else {
    throw InputError(fmt::format("unknown command '{}'; expected one of {}", utf8_prefix(cmd, 80), kCommandList));
  }
  return out;
}

}  // namespace

MessageOutcome handle_message(StudioSession& session, std::string_view text, const ExportFn& exporter) {
  if (text.size() > kMaxMessageBytes)
    return {error_reply(nullptr, fmt::format("message of {} bytes is over the limit of {} bytes", text.size(), kMaxMessageBytes)),
            false};
  nlohmann::json message;
  try {
    message = parse_json_text(std::string(text), "message");
  } catch (const InputError& e) {
    return {error_reply(nullptr, e.what()), false};
  }
  if (!message.is_object()) return {error_reply(nullptr, "message: expected a JSON object {\"cmd\": ...}"), false};
  nlohmann::json req;
  if (const auto* r = json_find(message, "req")) {
    if (r->dump().size() > kMaxRequestTagBytes)
      return {error_reply(nullptr, fmt::format("message: \"req\" is longer than {} bytes", kMaxRequestTagBytes)), false};
    req = *r;
  }
  try {
    MessageOutcome out = dispatch(session, message, exporter);
    if (!req.is_null()) out.reply["req"] = req;
    return out;
  } catch (const InputError& e) {
    return {error_reply(req, e.what()), false};
  } catch (const ComputeError& e) {
    return {error_reply(req, std::string("computation failed: ") + e.what()), false};
  }
}

}  // namespace cleave::studio
