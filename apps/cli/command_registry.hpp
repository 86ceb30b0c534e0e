#pragma once
// Subcommands register themselves here, each from its own file (cmd_info.cpp, cmd_run.cpp, ...),
// so that adding a command never touches main.cpp.
#include <CLI/CLI.hpp>
#include <functional>
#include <string>
#include <vector>

namespace cleave::cli {

struct Command {
  std::string name;
  int order;  ///< position in `cleave --help`
  /// Adds the subcommand to `app` and returns the function that runs it (exit code).
  std::function<std::function<int()>(CLI::App& app)> setup;
};

std::vector<Command>& command_registry();

struct CommandRegistrar {
  explicit CommandRegistrar(Command command) { command_registry().push_back(std::move(command)); }
};

}  // namespace cleave::cli
