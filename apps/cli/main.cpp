// `cleave`: the command-line front end. Thin: parses arguments and calls the library.
#include <CLI/CLI.hpp>
#include <algorithm>
#include <cstdio>
#include <exception>

#include "cleave/core/allocator_tuning.hpp"
#include "cleave/core/error.hpp"
#include "command_registry.hpp"

namespace cleave::cli {

std::vector<Command>& command_registry() {
  static std::vector<Command> commands;
  return commands;
}

}  // namespace cleave::cli

int main(int argc, char** argv) {
  cleave::restart_with_huge_pages(argv);   // the heap in 2 MB pages: far fewer page faults
  cleave::keep_freed_memory_for_reuse();  // before any thread: solvers reallocate the same large arrays
  using namespace cleave::cli;
  CLI::App app{"cleave " CLEAVE_VERSION
               ": interactive residual-stress modelling and cut simulation of soft tissue\n"
               "(Wu, Buerger, Westermann, Dick 2012). Units: mm, kPa, s.",
               "cleave"};
  app.set_version_flag("--version", std::string("cleave ") + CLEAVE_VERSION);
  app.require_subcommand(1);
  app.footer("Run `cleave <command> --help` for the options of one command.");

  auto& commands = command_registry();
  std::sort(commands.begin(), commands.end(), [](const Command& a, const Command& b) { return a.order < b.order; });
  std::vector<std::pair<CLI::App*, std::function<int()>>> runners;
  for (const Command& command : commands) {
    const std::size_t before = app.get_subcommands({}).size();
    auto run = command.setup(app);
    auto subs = app.get_subcommands({});
    if (subs.size() > before) runners.emplace_back(subs.back(), std::move(run));
  }

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e);
  }
  try {
    for (auto& [sub, run] : runners)
      if (sub->parsed()) return run();
  } catch (const cleave::InputError& e) {
    std::fprintf(stderr, "cleave: error: %s\n", e.what());
    return 2;
  } catch (const cleave::ComputeError& e) {
    std::fprintf(stderr, "cleave: computation failed: %s\n", e.what());
    return 3;
  } catch (const std::bad_alloc&) {
    std::fprintf(stderr, "cleave: error: out of memory\n");
    return 4;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "cleave: internal error: %s\n", e.what());
    return 5;
  }
  return 1;
}
