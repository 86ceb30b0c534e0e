// `cleave studio [CASE | MODEL] [--port N] [--host ADDR] [--session DIR]`: the interactive
// modelling tool in the browser. Thin: builds the session and runs the server (apps/studio).
#include <cstdio>
#include <fmt/format.h>

#include "cleave/core/error.hpp"
#include "cleave/io/atomic_file.hpp"
#include "cleave/io/case_file.hpp"
#include "command_registry.hpp"
#include "studio/studio_main.hpp"

namespace cleave::cli {
namespace {

struct StudioArguments {
  studio::StudioMainOptions options;
  std::string model;
  std::string resolution;
  std::string host;
};

int run_studio(StudioArguments& args) {
  args.options.host_origin = args.host.empty() ? studio::HostOrigin::default_loopback : studio::HostOrigin::explicit_flag;
  if (!args.host.empty()) args.options.host = args.host;
  args.options.case_document = studio::case_for_model_argument(args.model, args.resolution);
  return studio::run_studio(args.options);
}

const CommandRegistrar kStudio{
    {"studio", 30, [](CLI::App& app) -> std::function<int()> {
       auto args = std::make_shared<StudioArguments>();
       auto* cmd = app.add_subcommand("studio", "serve the interactive modelling tool in the browser (http://127.0.0.1:8765/)");
       cmd->add_option("MODEL", args->model,
                       "a case file (.json) or a model (built-in cylinder, abdomen, plate; volume; mesh); "
                       "default: the session folder's model, else the abdomen at 63x21x42");
       cmd->add_option("--res", args->resolution, "grid resolution NXxNYxNZ for a built-in model, e.g. 126x41x84");
       cmd->add_option("--port", args->options.port, "TCP port (0: any free port)")->capture_default_str()->check(CLI::Range(0, 65535));
       cmd->add_option("--host", args->host, "address to listen on (default 127.0.0.1; other addresses open the studio to the network)");
       cmd->add_option("--session", args->options.session_folder, "session folder: journal, saved cases, exports")
           ->capture_default_str();
       cmd->add_option("--web-root", args->options.web_root, "folder with the web client (index.html)")->capture_default_str();
       cmd->add_option("--max-send-queue-mb", args->options.max_send_queue_mb,
                       "disconnect a client whose unsent messages pass this many MB (one that stopped reading)")
           ->capture_default_str()
           ->check(CLI::Range(0.01, 65536.0));
       return [args] { return run_studio(*args); };
     }}};

}  // namespace
}  // namespace cleave::cli
