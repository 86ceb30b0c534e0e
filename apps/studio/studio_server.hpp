#pragma once
// The studio's network front: HTTP for the web client's static files and a small JSON API, a
// WebSocket (/ws) for edits, results and streamed frames. One I/O thread; the computation runs
// in the field worker (field_worker.hpp), so the I/O thread only parses, journals and sends.
//
//   GET /                      web/index.html
//   GET /<file>                a file under web/ (no traversal: path_safety.hpp)
//   GET /vendor/three.module.js, /vendor/OrbitControls.js   three.js from web/node_modules
//   GET /session/<file>        a saved case or export from the session folder (.json .vtu .ply .gltf)
//   GET /api/state             the session state message
//   WS  /ws                    message_handler.hpp messages; the server also pushes
//                              "state" (after every edit, to every client), "mesh", "result",
//                              "progress" and "frame" messages (docs/studio.md)
// Limits: request headers 8 KiB, bodies kMaxHttpBodyBytes, WebSocket messages kMaxMessageBytes;
// a client whose send queue exceeds kMaxQueuedMessages messages or, with more than one message,
// ServerOptions::max_queued_bytes (a client that stopped reading: results at 45k cells are ~2.5 MB
// each) is disconnected; the
// others go on. A broadcast state still unsent to a client is replaced by a newer one (only the
// newest design matters), and so is a result (broadcast_kind.hpp), so a burst of edits does not
// fill a slow reader's queue.
#include <cstdint>
#include <filesystem>
#include <functional>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>

#include "studio/broadcast_kind.hpp"
#include "studio/message_handler.hpp"
#include "studio/studio_session.hpp"

namespace cleave::studio {

inline constexpr std::size_t kMaxQueuedMessages = 512;
inline constexpr std::size_t kDefaultMaxQueuedBytes = std::size_t{128} << 20;

struct ServerOptions {
  std::string bind_address = "127.0.0.1";  ///< numeric, checked by checked_bind_address
  std::uint16_t port = 8765;                ///< 0: any free port (see StudioServer::port)
  std::filesystem::path web_root;           ///< folder with index.html and node_modules/three
  std::size_t max_queued_bytes = kDefaultMaxQueuedBytes;  ///< per client, messages not yet sent included
};

/// What the server asks of the computation side (studio_compute.hpp implements it).
struct ServerHooks {
  /// Messages a newly connected client needs besides the state: the latest result with its whole
  /// surface (queued as BroadcastKind::full_result, so it replaces an older result still unsent).
  std::function<std::vector<std::string>()> welcome_messages;
  /// Called on the I/O thread after every acknowledged edit with the new design.
  std::function<void(const StudioSession&)> design_changed;
  /// Called for {"cmd":"run_cut", ...}-style requests the message handler does not know:
  /// returns a reply or nullopt for "unknown".
  std::function<std::optional<nlohmann::json>(const nlohmann::json& message)> extra_command;
  ExportFn exporter;
};

class StudioServer {
 public:
  /// Binds and listens. Throws InputError "port N is already in use on ADDR; ..." when taken.
  StudioServer(StudioSession& session, ServerOptions options, ServerHooks hooks);
  ~StudioServer();
  StudioServer(const StudioServer&) = delete;
  StudioServer& operator=(const StudioServer&) = delete;

  /// The port actually bound.
  std::uint16_t port() const;
  /// Serves until stop() or SIGINT / SIGTERM.
  void run();
  /// Thread safe: ends run().
  void stop();
  /// Thread safe: sends `text` to every connected WebSocket client; `kind` says which of a
  /// client's unsent messages it replaces.
  void broadcast(std::string text, BroadcastKind kind = BroadcastKind::every);

  struct Impl;  ///< the connections and the I/O loop (studio_server.cpp)

 private:
  std::unique_ptr<Impl> impl_;
};

}  // namespace cleave::studio
