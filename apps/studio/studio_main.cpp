#include "studio/studio_main.hpp"

#include <cstdio>
#include <fmt/format.h>
#include <exception>
#include <regex>
#include <thread>

#include "cleave/core/error.hpp"
#include "cleave/io/case_file.hpp"
#include "studio/studio_compute.hpp"
#include "studio/studio_server.hpp"
#include "studio/studio_session.hpp"

namespace cleave::studio {

std::optional<nlohmann::json> case_for_model_argument(const std::string& model, const std::string& resolution) {
  if (model.empty() && resolution.empty()) return std::nullopt;
  const bool case_file = !model.empty() && classify_model_source(model) == ModelSourceKind::case_file;
  nlohmann::json doc;
  if (case_file) {
    const CaseFile c = load_case_file(model);
    doc = c.document;
    doc["model"]["source"] = c.model_source;  // resolved against the case's folder
  } else {
    std::string source = model.empty() ? "abdomen" : model;
    if (classify_model_source(source) != ModelSourceKind::builtin)
      source = std::filesystem::absolute(source).lexically_normal().string();
    doc = {{"cleave_case", 1}, {"model", {{"source", source}}}};
  }
  if (!resolution.empty()) {
    static const std::regex kRes(R"((\d{1,6})[xX](\d{1,6})[xX](\d{1,6}))");
    std::smatch m;
    if (!std::regex_match(resolution, m, kRes))
      throw InputError(fmt::format("--res '{}': expected NXxNYxNZ with three positive integers, e.g. 63x21x42", resolution));
    doc["model"].erase("cell_size_mm");
    doc["model"]["resolution"] = {std::stoi(m[1]), std::stoi(m[2]), std::stoi(m[3])};
  }
  parse_case_text(doc.dump(), model.empty() ? "--res" : model, std::filesystem::current_path());  // validates
  // A case file keeps its own settings; a bare model gets the studio's (the demo's on the abdomen).
  return case_file ? doc : bare_model_case(doc["model"]);
}

int run_studio(const StudioMainOptions& options) {
  ServerOptions server_options;
  server_options.bind_address = checked_bind_address(options.host, options.host_origin);
  server_options.port = options.port;
  server_options.max_queued_bytes = static_cast<std::size_t>(options.max_send_queue_mb * (1 << 20));
  server_options.web_root = std::filesystem::absolute(options.web_root);
  if (!std::filesystem::is_regular_file(server_options.web_root / "index.html"))
    throw InputError(fmt::format("--web-root '{}' has no index.html", options.web_root.string()));
  if (!std::filesystem::is_regular_file(server_options.web_root / "node_modules/three/build/three.module.js"))
    std::fprintf(stderr, "cleave studio: warning: three.js is missing in %s/node_modules; run scripts/install-web.sh\n",
                 server_options.web_root.c_str());

  StudioSession session(options.session_folder, options.case_document);
  std::unique_ptr<StudioServer> server;
  // The computations run on this (the main) thread, the server on a second one: see
  // FieldWorker::JobThread for why.
  StudioCompute compute(
      session,
      [&server](std::string text, BroadcastKind kind) {
        if (server) server->broadcast(std::move(text), kind);
      },
      FieldWorker::JobThread::caller);
  ServerHooks hooks;
  hooks.welcome_messages = [&compute] { return compute.welcome_messages(); };
  hooks.design_changed = [&compute](const StudioSession& s) { compute.design_changed(s.design(), s.seq()); };
  hooks.exporter = [&compute](ExportFormat format, const std::filesystem::path& file) { compute.export_result(format, file); };
  server = std::make_unique<StudioServer>(session, server_options, hooks);

  const bool ipv6 = server_options.bind_address.find(':') != std::string::npos;
  const std::string url = fmt::format("http://{}{}{}:{}/", ipv6 ? "[" : "", server_options.bind_address, ipv6 ? "]" : "",
                                      server->port());
  if (options.host_origin == HostOrigin::explicit_flag && !is_loopback_address(server_options.bind_address))
    std::fprintf(stderr, "cleave studio: warning: listening on %s: other machines can reach this session\n",
                 server_options.bind_address.c_str());
  std::printf("cleave studio: %s  (model %s, %d cells; session %s, %llu edits restored%s)\n", url.c_str(),
              session.model().source.c_str(), session.model().volume.cell_count(), session.folder().c_str(),
              static_cast<unsigned long long>(session.seq()),
              session.torn_bytes_dropped() > 0 ? ", a torn last journal line dropped" : "");
  std::fflush(stdout);
  compute.design_changed(session.design(), session.seq());
  std::exception_ptr server_failure;
  std::thread io([&server, &compute, &server_failure] {
    try {
      server->run();  // until SIGINT or SIGTERM
    } catch (...) {
      server_failure = std::current_exception();  // rethrown on the main thread, as before
    }
    compute.stop_jobs();
  });
  try {
    compute.run_jobs();
  } catch (...) {
    server->stop();
    io.join();
    throw;
  }
  io.join();
  if (server_failure) std::rethrow_exception(server_failure);
  std::printf("cleave studio: stopped\n");
  return 0;
}

}  // namespace cleave::studio
