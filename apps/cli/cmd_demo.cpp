// `cleave demo [--out DIR]`: the paper's story on the built-in abdomen in one command.
// A Langer design (strokes running horizontally around the body, 20 kPa along / 10 kPa across at
// control points), round incisions placed evenly over the upper part of the skin, one 5 cm
// scalpel cut across the lines and one along them and a U-shaped flap in the lower part (apart,
// so that one wound does not disturb the measurement of another). The wall is held at its rim
// and on its inner surface, which lies on the body beneath: that support, not the wall alone,
// balances the tension, so the design is used as drawn (no equilibrium term, no equilibration;
// docs/VALIDATION.md, "The demo"). 3.6 mm cells put three cells through the 10.8 mm wall, which
// bends and shears well enough for the openings (two cells lock; docs/VALIDATION.md). Writes result.vtu,
// surface.ply/.gltf, streamlines.vtp, summary.json and incisions.csv, and prints where they are
// and the key numbers. If the design step fails, the demo says so and runs again with a direct
// uniform stress (20 kPa along x, 10 kPa along z) so that the rest can still be seen.
#include <fmt/format.h>

#include <fstream>
#include <nlohmann/json.hpp>

#include "cleave/core/error.hpp"
#include "cleave/io/case_file.hpp"
#include "cleave/pipeline/run_case.hpp"
#include "cleave/shapes/builtin_shapes.hpp"
#include "cleave/model/tissue_model.hpp"
#include "command_registry.hpp"
#include "progress_bar.hpp"

namespace cleave::cli {
namespace {

using nlohmann::json;

constexpr double kLangerKPa = 20.0;      // paper section 7
constexpr double kCrossKPa = 10.0;
constexpr double kYoungKPa = 80.0;
constexpr double kPoisson = 0.4;
constexpr double kCellSizeMm = 3.6;      // three cells through the wall
constexpr double kIncisionRadiusMm = 8.0;
constexpr double kIncisionDepthMm = 5.0;  // through the skin and the fat, about half the wall
constexpr double kIncisionSpacingMm = 35.0;
constexpr double kCutLengthMm = 50.0;    // "a 5 cm incision"
constexpr double kCutDepthMm = 8.0;
constexpr double kFlapDepthMm = 5.0;
constexpr double kRimMm = 5.0;           // held band along the wall's edges

struct DemoArguments {
  std::string out_dir = "cleave-demo";
  bool quiet = false;
};

/// Point on the skin above (x, z): the top of the body found by a vertical ray from above.
json skin_point(const TissueModel& model, double x, double z) {
  const LinkedVolume& v = model.volume;
  const double step = 0.1 * v.grid().cell_size_mm;
  double y = v.grid().origin_mm.y() + v.grid().extent_mm().y();
  while (y > v.grid().origin_mm.y() && v.cell_containing(Vec3(x, y, z)) == kNone) y -= step;
  return json::array({x, y + 0.5 * step, z});
}

json demo_case(const TissueModel& model, bool with_design) {
  const Vec3 extent = model.volume.grid().extent_mm();
  const double w = extent.x(), l = extent.z();
  json strokes = json::array();
  for (const double z : {0.2 * l, 0.5 * l, 0.8 * l}) {
    json pts = json::array();
    for (double x = 0.1 * w; x <= 0.9 * w + 1e-9; x += 0.1 * w) pts.push_back(skin_point(model, x, z));
    strokes.push_back({{"points", pts}});
  }
  json controls = json::array();
  for (const double x : {0.3 * w, 0.7 * w})
    for (const double z : {0.3 * l, 0.7 * l})
      controls.push_back({{"position", skin_point(model, x, z)}, {"langer_kPa", kLangerKPa}, {"cross_kPa", kCrossKPa}});
  const double xa = 0.32 * w, xb = 0.72 * w, zc = 0.3 * l;
  json c = json::object();
  c["cleave_case"] = 1;
  c["description"] = "cleave demo: Langer design on the abdomen, round incisions, cuts across and along, a flap";
  c["model"] = {{"source", "abdomen"}, {"cell_size_mm", kCellSizeMm}};
  json material = {{"E_kPa", kYoungKPa}, {"nu", kPoisson}};
  c["materials"] = {{"1", material}, {"2", material}, {"3", material}};
  json place = json::object();
  place["spacing_mm"] = kIncisionSpacingMm;
  place["region"] = {{"box_mm", json::array({json::array({0.1 * w, 0.0, 0.55 * l}), json::array({0.9 * w, extent.y(), 0.9 * l})})}};
  place["seed"] = 7;
  c["incisions"] = {{"radius_mm", kIncisionRadiusMm}, {"depth_mm", kIncisionDepthMm}, {"plug", "remove"}, {"place", place}};
  json across = {{"type", "scalpel"}, {"depth_mm", kCutDepthMm}};  // Langer's lines run along x: this path runs along z
  across["path_mm"] = json::array({skin_point(model, xa, zc - 0.5 * kCutLengthMm), skin_point(model, xa, zc + 0.5 * kCutLengthMm)});
  json along = {{"type", "scalpel"}, {"depth_mm", kCutDepthMm}};
  along["path_mm"] = json::array({skin_point(model, xb - 0.5 * kCutLengthMm, zc), skin_point(model, xb + 0.5 * kCutLengthMm, zc)});
  json flap = {{"type", "flap"}, {"shape", "u"}, {"depth_mm", kFlapDepthMm}};
  flap["path_mm"] = json::array({skin_point(model, 0.45 * w, 0.12 * l), skin_point(model, 0.45 * w, 0.27 * l),
                                 skin_point(model, 0.55 * w, 0.27 * l), skin_point(model, 0.55 * w, 0.12 * l)});
  c["cuts"] = json::array({across, along, flap});
  const auto box = [](double x0, double y0, double z0, double x1, double y1, double z1) {
    return json{{"box_mm", json::array({json::array({x0, y0, z0}), json::array({x1, y1, z1})})}};
  };
  const double top = extent.y() + 1;
  c["simulation"] = {{"mode", "static"},
                     {"fixed", json::array({box(-1, -1, -1, kRimMm, top, l + 1), box(w - kRimMm, -1, -1, w + 1, top, l + 1),
                                            box(-1, -1, -1, w + 1, top, kRimMm), box(-1, -1, l - kRimMm, w + 1, top, l + 1),
                                            {{"surface", "inner"}}})}};
  if (with_design)
    c["design"] = {{"strokes", strokes}, {"control_points", controls}, {"weights", {{"equilibrium", 0.0}}}, {"equilibrate", false}};
  else
    c["residual_stress"] = {{"uniform_kPa", json::array({kLangerKPa, 0.0, kCrossKPa, 0.0, 0.0, 0.0})}};
  return c;
}

void print_key_numbers(const std::filesystem::path& summary_file) {
  std::ifstream in(summary_file);
  const json s = json::parse(in, nullptr, /*allow_exceptions=*/false);
  if (s.is_discarded()) return;
  if (s.contains("incisions_overview")) {
    const json& o = s["incisions_overview"];
    fmt::print("round incisions: {} placed, {} measured, mean outer axis ratio {:.3f}\n", o.value("placed", 0),
               o.value("measured", 0), o.value("mean_outer_axis_ratio", 0.0));
    for (const json& i : s.value("incisions", json::array())) {
      fmt::print("  incision {:2}: outer {:.1f} x {:.1f} mm (ratio {:.3f}), gap {:.2f} mm", i.value("index", 0),
                 2 * i["outer"].value("semi_major_mm", 0.0), 2 * i["outer"].value("semi_minor_mm", 0.0),
                 i["outer"].value("axis_ratio", 0.0), i.value("gap_mm", 0.0));
      if (i.contains("langer_angle_deg")) fmt::print(", long axis {:.1f} deg off Langer", i["langer_angle_deg"].get<double>());
      fmt::print("\n");
    }
  }
  const char* names[] = {"5 cm cut across Langer's lines", "5 cm cut along Langer's lines"};
  for (const json& c : s.value("cuts", json::array())) {
    if (c.value("type", "") == "scalpel") {
      const std::size_t k = c.value("index", std::size_t{0});
      fmt::print("{}: wound opens {:.2f} mm at most, {:.2f} mm on average\n", k < 2 ? names[k] : "cut",
                 c.value("max_width_mm", 0.0), c.value("mean_width_mm", 0.0));
    } else {
      fmt::print("flap: skin area {:+.1f} %, volume {:+.1f} %\n", c.value("skin_area_change_percent", 0.0),
                 c.value("volume_change_percent", 0.0));
    }
  }
}

int run_demo(const DemoArguments& args) {
  const ProgressFn progress = stderr_progress(args.quiet);
  ShapeResolution resolution;
  resolution.cell_size_mm = kCellSizeMm;
  const TissueModel model = make_tissue_model("abdomen", make_builtin_shape("abdomen", resolution));
  std::filesystem::create_directories(args.out_dir);
  RunResult result;
  bool done = false;
  for (const bool with_design : {true, false}) {
    const json c = demo_case(model, with_design);
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
