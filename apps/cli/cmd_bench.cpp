// `cleave bench`: the paper's Table 1 re-measured on this machine, with the peers (the paper's
// algorithms on one thread, Eigen CG + incomplete Cholesky, CHOLMOD) run on the same systems.
//
//   cleave bench                     the four Table 1 models, 5 repetitions, tables on stdout
//   cleave bench --json              one JSON object per model per line (see bench/bench_report.hpp)
//   cleave bench --large             also the tube at ~350k and >1M cells (design stages skipped
//                                    above --design-max-cells; preview and step on a prescribed stress)
//   cleave bench --quick --json      tiny models, one repetition (smoke test; seconds)
//   cleave bench --models scaling --peers none --scaling docs/performance-scaling.tsv
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <optional>
#include <sstream>

#include "bench_models.hpp"
#include "bench_report.hpp"
#include "cleave/core/allocator_tuning.hpp"
#include "cleave/core/error.hpp"
#include "command_registry.hpp"
#include "measure_model.hpp"
#include "progress_bar.hpp"

namespace cleave::cli {
namespace {

constexpr std::size_t kQuickBandwidthElements = std::size_t{1} << 21;  // 16 MiB per array

struct BenchArguments {
  std::string models;        ///< comma-separated keys or groups; empty = Table 1
  std::string peers = "paper,eigen_cg,cholmod";
  std::string scaling_file;  ///< per-cell times of every measured model, tab separated
  int repeat = 5;
  int peer_max_cells = 400'000;
  int design_max_cells = 60'000;
  std::optional<double> design_equilibrium;  ///< w_E of the design stages; unset = the default design's
  bool large = false;
  bool quick = false;
  bool json = false;
  bool quiet = false;
};

std::vector<std::string> split_list(const std::string& list) {
  std::vector<std::string> items;
  std::stringstream in(list);
  std::string item;
  while (std::getline(in, item, ','))
    if (!item.empty()) items.push_back(item);
  return items;
}

std::vector<bench::BenchModel> selected_models(const BenchArguments& args) {
  std::vector<bench::BenchModel> models;
  const auto append = [&models](std::vector<bench::BenchModel> more) {
    for (auto& m : more) models.push_back(std::move(m));
  };
  if (args.models.empty()) append(args.quick ? bench::quick_models() : bench::table1_models());
  for (const std::string& key : split_list(args.models)) {
    if (key == "table1") append(bench::table1_models());
    else if (key == "large") append(bench::large_models());
    else if (key == "scaling") append(bench::scaling_models());
    else if (key == "quick") append(bench::quick_models());
    else models.push_back(bench::bench_model_by_key(key));
  }
  if (args.large)
    for (bench::BenchModel& m : bench::large_models())  // --models scaling --large: each tube once
      if (std::none_of(models.begin(), models.end(), [&](const bench::BenchModel& known) { return known.key == m.key; }))
        models.push_back(std::move(m));
  return models;
}

std::vector<bench::Implementation> selected_peers(const std::string& list) {
  std::vector<bench::Implementation> peers;
  if (list == "none") return peers;
  for (const std::string& key : split_list(list)) {
    const bench::Implementation peer = bench::implementation_from_key(key, "--peers");
    if (peer == bench::Implementation::cleave)
      throw InputError("--peers: 'cleave' is always measured; expected paper, eigen_cg, cholmod or none");
    peers.push_back(peer);
  }
  return peers;
}

/// One row per measured model: time per cell of every stage (us), then the medians (ms), the
/// preview's and the step's iterations, the peak memory (MB) and where the stress came from.
/// Rewritten after every model, so a long run leaves the models measured so far.
void write_scaling_table(const std::string& path, const std::vector<bench::ModelFigures>& figures) {
  std::ofstream out(path);
  if (!out) throw InputError(fmt::format("--scaling {}: cannot write the file", path));
  out << "# model\tcells\tvertices";
  for (bench::Stage s : bench::kAllStages) out << "\tus_per_cell_" << bench::stage_key(s);
  for (bench::Stage s : bench::kAllStages) out << "\tms_" << bench::stage_key(s);
  out << "\titerations_preview\titerations_step\tpeak_mb\tresidual_stress\n";
  for (const bench::ModelFigures& m : figures) {
    out << m.model.key << '\t' << m.cells << '\t' << m.vertices;
    for (bench::Stage s : bench::kAllStages) {
      const bench::StageFigures& st = m.cleave.stage(s);
      if (st.time.count == 0) out << "\t-";  // gnuplot reads "-" as missing
      else out << '\t' << fmt::format("{:.4g}", 1000.0 * st.time.median_ms / m.cells);
    }
    for (bench::Stage s : bench::kAllStages) {
      const bench::StageFigures& st = m.cleave.stage(s);
      if (st.time.count == 0) out << "\t-";
      else out << '\t' << fmt::format("{:.4g}", st.time.median_ms);
    }
    out << '\t' << m.cleave.preview.iterations << '\t' << m.cleave.step.iterations << '\t'
        << fmt::format("{:.0f}", m.cleave.peak_mb) << '\t' << m.residual_stress << "\n";
  }
}

int run_bench(const BenchArguments& args) {
  if (args.repeat < 1) throw InputError(fmt::format("--repeat {}: expected at least 1", args.repeat));
  const std::vector<bench::BenchModel> models = selected_models(args);
  bench::BenchOptions options;
  options.repeat = args.repeat;
  options.peers = selected_peers(args.peers);
  options.peer_max_cells = args.peer_max_cells;
  if (args.design_max_cells < 0) throw InputError(fmt::format("--design-max-cells {}: expected at least 0", args.design_max_cells));
  options.design_max_cells = args.design_max_cells;
  if (args.design_equilibrium && !(*args.design_equilibrium >= 0.0 && std::isfinite(*args.design_equilibrium)))
    throw InputError(fmt::format("--design-equilibrium {}: expected a finite weight >= 0", *args.design_equilibrium));
  options.design_equilibrium_weight = args.design_equilibrium;
  const ProgressFn progress = stderr_progress(args.quiet);

  report(progress, "memory bandwidth", 0.0);
  bench::MachineFigures machine;
  machine.cpu = bench::cpu_model_name();
  machine.malloc_huge_pages = malloc_uses_huge_pages();
  bench::BandwidthOptions bandwidth_options;
  if (args.quick) bandwidth_options.elements_per_array = kQuickBandwidthElements;
  machine.bandwidth = bench::measure_memory_bandwidth(bandwidth_options);
  machine.threads = machine.bandwidth.threads;
  report(progress, "memory bandwidth", 1.0);

  std::vector<bench::ModelFigures> figures;
  for (const bench::BenchModel& m : models) {
    figures.push_back(bench::measure_model(m, options, progress));
    if (args.json) {
      std::puts(bench::model_figures_json(figures.back(), machine).dump().c_str());
      std::fflush(stdout);
    }
    if (!args.scaling_file.empty()) write_scaling_table(args.scaling_file, figures);
  }
  if (args.json) return 0;
  fmt::print("machine: {}, {} threads, memory bandwidth (triad) {:.1f} GB/s all threads, {:.1f} GB/s one thread\n\n",
             machine.cpu, machine.threads, machine.bandwidth.all_threads_GB_per_s, machine.bandwidth.one_thread_GB_per_s);
  fmt::print("Median times (ms) over {} runs\n{}\n", args.repeat, bench::stage_table(figures));
  if (!options.peers.empty()) fmt::print("cleave time / peer time (relative difference of the results)\n{}\n", bench::ratio_table(figures));
  const std::string paper = bench::paper_table(figures);
  if (paper.find('\n') != paper.rfind('\n')) fmt::print("Paper (2008 CPU, one core) vs cleave (ms)\n{}", paper);
  return 0;
}

const CommandRegistrar kBench{{"bench", 90, [](CLI::App& app) -> std::function<int()> {
                                 auto args = std::make_shared<BenchArguments>();
                                 auto* cmd = app.add_subcommand("bench", "time every stage on the paper's Table 1 models, with peers");
                                 cmd->add_option("--models", args->models,
                                                 "comma-separated models: table1, large, scaling, quick, or keys like cylinder-42, abdomen-126, tube-84");
                                 cmd->add_flag("--large", args->large,
                                               "also the tube at 84x84x102 (~350k cells) and 120x120x146 (>1M cells); "
                                               "design stages skipped there (see --design-max-cells)");
                                 cmd->add_flag("--quick", args->quick, "tiny models, one repetition: a smoke run of seconds");
                                 cmd->add_option("--repeat", args->repeat, "timed runs per stage (medians reported)")->capture_default_str();
                                 cmd->add_option("--peers", args->peers, "peers to run: paper, eigen_cg, cholmod (comma-separated) or none")
                                     ->capture_default_str();
                                 cmd->add_option("--peer-max-cells", args->peer_max_cells, "skip peers on larger models")->capture_default_str();
                                 cmd->add_option("--design-max-cells", args->design_max_cells,
                                                 "skip the design stages on larger models (their sparse Cholesky factors outgrow memory); "
                                                 "preview and step then run on a prescribed 20/10 kPa biaxial stress")
                                     ->capture_default_str();
                                 cmd->add_option("--design-equilibrium", args->design_equilibrium,
                                                 "w_E of the design stages (default: the design default, 0)");
                                 cmd->add_option("--scaling", args->scaling_file, "write per-cell times of every model to this tab-separated file");
                                 cmd->add_flag("--json", args->json, "print one JSON object per model per line");
                                 cmd->add_flag("--quiet,-q", args->quiet, "no progress output");
                                 return [args, cmd] {
                                   BenchArguments a = *args;
                                   if (a.quick && cmd->count("--repeat") == 0) a.repeat = 1;
                                   return run_bench(a);
                                 };
                               }}};

}  // namespace
}  // namespace cleave::cli
