#pragma once
// Running the studio: the session, the server and the computation wired together (what
// `cleave studio` calls). Prints the URL to stdout once it listens:
//   cleave studio: http://127.0.0.1:8765/  (model abdomen, 6048 cells; session cleave-session, 3 edits restored)
#include <cstdint>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>

#include "studio/bind_address.hpp"
#include "studio/studio_server.hpp"

namespace cleave::studio {

struct StudioMainOptions {
  std::uint16_t port = 8765;
  std::string host = kDefaultHost;
  HostOrigin host_origin = HostOrigin::default_loopback;
  std::filesystem::path session_folder = "cleave-session";
  std::filesystem::path web_root = CLEAVE_WEB_ROOT;
  double max_send_queue_mb = static_cast<double>(kDefaultMaxQueuedBytes >> 20);  ///< a client whose unsent messages pass this is disconnected
  std::optional<nlohmann::json> case_document;  ///< nullopt: the session folder's model or the default
};

/// The case document for the studio's MODEL argument: a case file (validated, model path made
/// absolute; its own design and simulation settings kept), or a model name / file with an
/// optional "NXxNYxNZ" resolution (bare_model_case: the demo's settings on the abdomen);
/// std::nullopt when both are empty. InputError for a bad case, model or resolution.
std::optional<nlohmann::json> case_for_model_argument(const std::string& model, const std::string& resolution);

/// Serves until SIGINT / SIGTERM; returns the exit code.
int run_studio(const StudioMainOptions& options);

}  // namespace cleave::studio
