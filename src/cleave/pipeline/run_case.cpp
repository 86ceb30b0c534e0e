#include "cleave/pipeline/run_case.hpp"

#include <chrono>
#include <fmt/format.h>

#include "cleave/io/atomic_file.hpp"
#include "cleave/pipeline/stages.hpp"

namespace cleave {
namespace {

template <typename Stage>
void timed(RunContext& ctx, const char* name, Stage&& stage) {
  const auto start = std::chrono::steady_clock::now();
  stage(ctx);
  ctx.record_time(name, std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
}

}  // namespace

RunResult run_case(const CaseFile& case_file, const std::filesystem::path& out_dir, const ProgressFn& progress) {
  RunContext ctx{case_file, out_dir, progress, {}, {}, {}, {}, {}, nlohmann::json::object(), nlohmann::json::object(), {}};
  timed(ctx, "model", [&](RunContext& c) {
    ModelSourceOptions options = case_file.model_options;
    options.progress = progress;
    c.model = make_tissue_model(case_file.model_source, load_model_source(case_file.model_source, options),
                                case_file.materials);
  });
  const LinkedVolume& volume = ctx.model.volume;
  ctx.summary["model"] = {{"source", ctx.model.source},
                          {"cells", volume.cell_count()},
                          {"vertices_uncut", volume.vertex_count()},
                          {"cell_size_mm", volume.grid().cell_size_mm}};

  report(progress, "residual stress", 0.0);
  timed(ctx, "residual_stress", stage_residual_stress);
  report(progress, "cuts", 0.0);
  timed(ctx, "cuts", stage_cuts);
  report(progress, "mechanics", 0.0);
  timed(ctx, "mechanics", stage_mechanics);
  report(progress, "measurements", 0.0);
  timed(ctx, "measure", stage_measure);
  report(progress, "render surface", 0.0);
  timed(ctx, "surface", stage_surface);

  ctx.summary["model"]["vertices"] = volume.vertex_count();
  ctx.summary["model"]["components"] = volume.component_count();
  RunResult result;
  if (case_file.output.vtu) {
    timed(ctx, "write_vtu", [&](RunContext& c) { write_vtu(out_dir / "result.vtu", c.model.volume, c.fields); });
    result.files.push_back(out_dir / "result.vtu");
  }
  if (!ctx.frames.empty()) {
    write_pvd(out_dir / "frames.pvd", ctx.frames);
    result.files.push_back(out_dir / "frames.pvd");
  }
  for (const auto& f : ctx.summary.value("files", nlohmann::json::array())) result.files.emplace_back(f.get<std::string>());
  result.summary_file = out_dir / "summary.json";
  write_file_atomically(result.summary_file, ctx.summary.dump(2) + "\n");
  result.files.push_back(result.summary_file);
  report(progress, "done", 1.0);
  return result;
}

}  // namespace cleave
