#pragma once
// The studio's client messages (one JSON object per WebSocket text message), independent of
// the transport so that tests and fuzzers call it directly. Every message may carry "req"
// (any JSON value up to 64 bytes), echoed in the reply so that a client matches replies.
//
//   {"cmd":"hello"} / {"cmd":"get_state"}   -> the state message (studio_session.hpp)
//   {"cmd":"ping"}                          -> {"type":"pong"}
//   a design edit (design_edit.hpp), {"cmd":"undo"}, {"cmd":"redo"}
//                                            -> {"type":"ack","cmd":..,"seq":N}, durable (journaled)
//   {"cmd":"save","file":"name.json"}       -> {"type":"saved","file":"name.json"}
//   {"cmd":"load","file":"name.json"}       -> an ack; the design is replaced (undo restores it)
//   {"cmd":"export","format":"vtu"|"ply"|"gltf","file":"name.vtu"} -> {"type":"exported","file":..}
// Anything else, a message over kMaxMessageBytes, invalid JSON or a failed validation gets
//   {"type":"error","req":..,"message":"<one line naming the field and what was expected>"}
// and leaves the session unchanged.
#include <filesystem>
#include <functional>
#include <nlohmann/json.hpp>
#include <string>
#include <string_view>

#include "studio/studio_session.hpp"

namespace cleave::studio {

enum class ExportFormat { vtu, ply, gltf };

/// Writes the current result in `format` to `file` (inside the session folder, checked).
using ExportFn = std::function<void(ExportFormat format, const std::filesystem::path& file)>;

struct MessageOutcome {
  nlohmann::json reply;         ///< to the client that sent the message
  bool design_changed = false;  ///< broadcast the state and recompute the fields
};

MessageOutcome handle_message(StudioSession& session, std::string_view text, const ExportFn& exporter);

}  // namespace cleave::studio
