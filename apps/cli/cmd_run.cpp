// `cleave run CASE --out DIR`: a whole case in batch.
#include <fmt/format.h>

#include "cleave/io/case_file.hpp"
#include "cleave/pipeline/run_case.hpp"
#include "command_registry.hpp"
#include "progress_bar.hpp"

namespace cleave::cli {
namespace {

struct RunArguments {
  std::string case_file;
  std::string out_dir = "out";
  bool quiet = false;
};

int run_run(const RunArguments& args) {
  const CaseFile c = load_case_file(args.case_file);
  const RunResult result = run_case(c, args.out_dir, stderr_progress(args.quiet));
  fmt::print("wrote:\n");
  for (const auto& f : result.files) fmt::print("  {}\n", f.string());
  return 0;
}

const CommandRegistrar kRun{{"run", 20, [](CLI::App& app) -> std::function<int()> {
                               auto args = std::make_shared<RunArguments>();
                               auto* cmd = app.add_subcommand("run", "run a case file (docs/case-format.md) and write its results");
                               cmd->add_option("CASE", args->case_file, "case file (.json)")->required();
                               cmd->add_option("--out,-o", args->out_dir, "output folder (created if missing)")->capture_default_str();
                               cmd->add_flag("--quiet,-q", args->quiet, "no progress output");
                               return [args] { return run_run(*args); };
                             }}};

}  // namespace
}  // namespace cleave::cli
