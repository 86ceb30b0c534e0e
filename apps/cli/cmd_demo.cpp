// `cleave demo [--out DIR]`: the paper's story on the built-in abdomen in one command: a Langer
// design, round incisions opening into ellipses along the lines, a 5 cm cut across the lines
// gaping wider than one along them, a shrinking flap (the case: pipeline/demo_case.hpp). Prints
// progress, the key numbers and where the results are (result.vtu, surface.ply/.gltf,
// streamlines.vtp, summary.json, incisions.csv, demo_case.json). If the design step fails, the
// demo says so and runs again with a direct uniform stress so that the rest can still be seen.
#include <fmt/format.h>

#include <algorithm>
#include <fstream>
#include <nlohmann/json.hpp>

#include "cleave/core/error.hpp"
#include "cleave/io/case_file.hpp"
#include "cleave/pipeline/demo_case.hpp"
#include "cleave/pipeline/run_case.hpp"
#include "cleave/shapes/builtin_shapes.hpp"
#include "cleave/model/tissue_model.hpp"
#include "command_registry.hpp"
#include "progress_bar.hpp"

namespace cleave::cli {
namespace {

using nlohmann::json;

constexpr double kLangerKPa = 20.0;  // as in pipeline/demo_case.cpp
constexpr double kCrossKPa = 10.0;
constexpr double kYoungKPa = 80.0;
constexpr double kPoisson = 0.4;

struct DemoArguments {
  std::string out_dir = "cleave-demo";
  bool quiet = false;
};

void print_key_numbers(const std::filesystem::path& summary_file) {
  std::ifstream in(summary_file);
  const json s = json::parse(in, nullptr, /*allow_exceptions=*/false);
  if (s.is_discarded()) return;
  if (s.contains("incisions_overview")) {
    const json& o = s["incisions_overview"];
    fmt::print("round incisions: {} placed, {} measured, mean outer axis ratio {:.3f}\n", o.value("placed", 0),
               o.value("measured", 0), o.value("mean_outer_axis_ratio", 0.0));
    double lo = 1e300, hi = 0, worst_angle = 0;
    for (const json& i : s.value("incisions", json::array())) {
      lo = std::min(lo, i["outer"].value("axis_ratio", 0.0));
      hi = std::max(hi, i["outer"].value("axis_ratio", 0.0));
      worst_angle = std::max(worst_angle, i.value("langer_angle_deg", 0.0));
    }
    if (hi > 0)
      fmt::print("  they open into ellipses: axis ratio {:.3f} to {:.3f}, long axis at most {:.1f} deg off Langer's lines\n",
                 lo, hi, worst_angle);
    for (const json& i : s.value("incisions", json::array())) {
      fmt::print("  incision {:2}: outer {:.1f} x {:.1f} mm (ratio {:.3f}), gap {:.2f} mm", i.value("index", 0),
                 2 * i["outer"].value("semi_major_mm", 0.0), 2 * i["outer"].value("semi_minor_mm", 0.0),
                 i["outer"].value("axis_ratio", 0.0), i.value("gap_mm", 0.0));
      if (i.contains("langer_angle_deg")) fmt::print(", long axis {:.1f} deg off Langer", i["langer_angle_deg"].get<double>());
      fmt::print("\n");
    }
  }
  const char* names[] = {"5 cm cut across Langer's lines", "5 cm cut along Langer's lines"};
  double widths[2] = {0, 0};
  for (const json& c : s.value("cuts", json::array())) {
    if (c.value("type", "") == "scalpel") {
      const std::size_t k = c.value("index", std::size_t{0});
      fmt::print("{}: wound opens {:.2f} mm at most, {:.2f} mm on average\n", k < 2 ? names[k] : "cut",
                 c.value("max_width_mm", 0.0), c.value("mean_width_mm", 0.0));
      if (k < 2) widths[k] = c.value("max_width_mm", 0.0);
      if (k == 1 && widths[1] > 0) fmt::print("  across / along: {:.2f} (paper: 5 to 20 mm across)\n", widths[0] / widths[1]);
    } else {
      fmt::print("flap: skin area {:+.1f} %, volume {:+.1f} %\n", c.value("skin_area_change_percent", 0.0),
                 c.value("volume_change_percent", 0.0));
    }
  }
}

int run_demo(const DemoArguments& args) {
  const ProgressFn progress = stderr_progress(args.quiet);
  ShapeResolution resolution;
  resolution.cell_size_mm = kDemoCellSizeMm;
  const TissueModel model = make_tissue_model("abdomen", make_builtin_shape("abdomen", resolution));
  std::filesystem::create_directories(args.out_dir);
  RunResult result;
  bool done = false;
  for (const bool with_design : {true, false}) {
    const json c = abdomen_demo_case(model, with_design ? DemoStress::designed : DemoStress::direct);
    const std::filesystem::path case_path = std::filesystem::path(args.out_dir) / "demo_case.json";
    std::ofstream(case_path) << c.dump(2) << "\n";
    try {
      const CaseFile case_file = parse_case_text(c.dump(), "demo_case.json", args.out_dir);
      result = run_case(case_file, args.out_dir, progress);
      done = true;
      break;
    } catch (const std::exception& e) {
      if (!with_design) throw;
      fmt::print(stderr, "demo: the Langer design step failed ({}); running again with a direct uniform stress\n", e.what());
    }
  }
  if (!done) return 1;
  fmt::print("cleave demo: the built-in abdomen (E = {} kPa, nu = {}), Langer's lines around the body, {} / {} kPa\n",
             kYoungKPa, kPoisson, kLangerKPa, kCrossKPa);
  print_key_numbers(result.summary_file);
  fmt::print("wrote (open result.vtu and surface.ply in ParaView; the case is demo_case.json):\n");
  for (const auto& f : result.files) fmt::print("  {}\n", f.string());
  return 0;
}

const CommandRegistrar kDemo{{"demo", 5, [](CLI::App& app) -> std::function<int()> {
                                auto args = std::make_shared<DemoArguments>();
                                auto* cmd = app.add_subcommand(
                                    "demo", "Langer design, round incisions, cuts and a flap on the built-in abdomen");
                                cmd->add_option("--out,-o", args->out_dir, "output folder (created if missing)")
                                    ->capture_default_str();
                                cmd->add_flag("--quiet,-q", args->quiet, "no progress output");
                                return [args] { return run_demo(*args); };
                              }}};

}  // namespace
}  // namespace cleave::cli
