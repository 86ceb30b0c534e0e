// Stage "measurements" of a batch run: what the released residual stress did to the cuts.
//   incisions  outer and inner margin ellipses (viz/incision_ellipses.hpp) -> summary["incisions"]
//              (one object per incision) and incisions.csv in the output folder; the reference
//              direction is the designed Langer direction (cell field "langer_direction") or, with
//              a direct stress, the major principal direction of the residual stress in the
//              tangent plane.
//   cuts       scalpel wound width (max, mean) and flap skin area / volume change (%) ->
//              summary["cuts"].
//   cut faces  cell fields "released_traction" (Pa, max ||sigma n|| over the cell's cut faces)
//              and "cut_face_depth" (0 at the skin .. 1 at the inner layer, mean over the cell's
//              cut faces); 0 for cells without cut faces.
// The cut geometry is planned again from the case (deterministic: same seed, same surface).
#include <fmt/format.h>

#include <algorithm>
#include <numbers>
#include <optional>

#include "cleave/core/units.hpp"
#include "cleave/io/atomic_file.hpp"
#include "cleave/io/case_cuts.hpp"
#include "cleave/pipeline/stages.hpp"
#include "cleave/viz/cut_face_colouring.hpp"
#include "cleave/viz/incision_ellipses.hpp"
#include "cleave/viz/wound_measures.hpp"

namespace cleave {
namespace {

constexpr double kDegPerRad = 180.0 / std::numbers::pi;

const DataArray* find_cell_array(const VolumeFields& fields, const std::string& name) {
  for (const DataArray& a : fields.cell_data)
    if (a.name == name) return &a;
  return nullptr;
}

CellId cell_under(const LinkedVolume& volume, const IncisionFrame& f) {
  const CellId c = volume.cell_containing(f.centre_mm - 0.5 * volume.grid().cell_size_mm * f.normal);
  return c != kNone ? c : volume.cell_containing(f.centre_mm - volume.grid().cell_size_mm * f.normal);
}

nlohmann::json ellipse_json(const Ellipse2& e) {
  return {{"semi_major_mm", e.semi_major},
          {"semi_minor_mm", e.semi_minor},
          {"axis_ratio", e.axis_ratio()},
          {"angle_deg", e.angle_rad * kDegPerRad}};
}

void measure_incisions(RunContext& ctx, const BodySurface& surface, const CutPlan& plan) {
  const LinkedVolume& volume = ctx.model.volume;
  const DataArray* langer = find_cell_array(ctx.fields, "langer_direction");
  nlohmann::json list = nlohmann::json::array();
  std::string csv =
      "index,centre_x_mm,centre_y_mm,centre_z_mm,radius_mm,depth_mm,outer_semi_major_mm,outer_semi_minor_mm,"
      "outer_axis_ratio,outer_angle_deg,inner_semi_major_mm,inner_semi_minor_mm,inner_axis_ratio,gap_mm,opening_mm,"
      "langer_angle_deg,eigenvalue_ratio\n";
  double ratio_sum = 0;
  int measured = 0;
  for (std::size_t i = 0; i < plan.incisions.size(); ++i) {
    const IncisionFrame& f = plan.incisions[i];
    std::optional<TangentDirection> reference;
    const CellId c = cell_under(volume, f);
    if (c != kNone && !ctx.residual_stress_kPa.empty()) {
      reference = principal_tangent_direction(ctx.residual_stress_kPa[static_cast<std::size_t>(c)], f.normal);
      if (langer) reference->direction = Vec3(&langer->values[3 * static_cast<std::size_t>(c)]);
    }
    const auto m = measure_incision(surface, ctx.displacement_mm, f, reference);
    if (!m) continue;
    ++measured;
    ratio_sum += m->outer.axis_ratio();
    nlohmann::json j = {{"index", i},
                        {"centre_mm", {f.centre_mm.x(), f.centre_mm.y(), f.centre_mm.z()}},
                        {"normal", {f.normal.x(), f.normal.y(), f.normal.z()}},
                        {"radius_mm", f.radius_mm},
                        {"depth_mm", f.depth_mm},
                        {"outer", ellipse_json(m->outer)},
                        {"inner", ellipse_json(m->inner)},
                        {"outer_long_axis", {m->outer_major.x(), m->outer_major.y(), m->outer_major.z()}},
                        {"gap_mm", m->gap_mm},
                        {"opening_mm", m->opening_mm}};
    const bool finite_ratio = m->reference_eigenvalue_ratio && std::isfinite(*m->reference_eigenvalue_ratio);
    if (m->langer_angle_deg) j["langer_angle_deg"] = *m->langer_angle_deg;
    if (finite_ratio) j["eigenvalue_ratio"] = *m->reference_eigenvalue_ratio;
    list.push_back(std::move(j));
    csv += fmt::format("{},{:.6g},{:.6g},{:.6g},{:.6g},{:.6g},{:.6g},{:.6g},{:.6g},{:.6g},{:.6g},{:.6g},{:.6g},{:.6g},{:.6g},{},{}\n",
                       i, f.centre_mm.x(), f.centre_mm.y(), f.centre_mm.z(), f.radius_mm, f.depth_mm,
                       m->outer.semi_major, m->outer.semi_minor, m->outer.axis_ratio(), m->outer.angle_rad * kDegPerRad,
                       m->inner.semi_major, m->inner.semi_minor, m->inner.axis_ratio(), m->gap_mm, m->opening_mm,
                       m->langer_angle_deg ? fmt::format("{:.6g}", *m->langer_angle_deg) : "",
                       finite_ratio ? fmt::format("{:.6g}", *m->reference_eigenvalue_ratio) : "");
  }
  ctx.summary["incisions"] = std::move(list);
  ctx.summary["incisions_overview"] = {{"placed", plan.incisions.size()},
                                       {"measured", measured},
                                       {"mean_outer_axis_ratio", measured > 0 ? ratio_sum / measured : 0.0}};
  const std::filesystem::path file = ctx.out_dir / "incisions.csv";
  write_file_atomically(file, csv);
  if (!ctx.summary.contains("files")) ctx.summary["files"] = nlohmann::json::array();
  ctx.summary["files"].push_back(file.string());
}

void measure_cuts(RunContext& ctx, const CaseCuts& cuts, const CutPlan& plan) {
  const LinkedVolume& volume = ctx.model.volume;
  nlohmann::json list = nlohmann::json::array();
  for (std::size_t i = 0; i < plan.scalpel_paths.size(); ++i) {
    const WoundWidth w = scalpel_wound_width(volume, ctx.displacement_mm, plan.scalpel_paths[i]);
    list.push_back({{"index", cuts.scalpel_index[i]},
                    {"type", "scalpel"},
                    {"length_mm", plan.scalpel_paths[i].length_mm},
                    {"max_width_mm", w.max_mm},
                    {"mean_width_mm", w.mean_mm},
                    {"samples", w.samples}});
  }
  for (std::size_t i = 0; i < plan.flaps.size(); ++i) {
    const FlapChange f = flap_change(volume, ctx.displacement_mm, plan.flaps[i]);
    list.push_back({{"index", cuts.flap_index[i]},
                    {"type", "flap"},
                    {"cells", plan.flaps[i].cells.size()},
                    {"skin_area_before_mm2", f.skin_area_before_mm2},
                    {"skin_area_after_mm2", f.skin_area_after_mm2},
                    {"skin_area_change_percent", f.skin_area_change_percent},
                    {"volume_before_mm3", f.volume_before_mm3},
                    {"volume_after_mm3", f.volume_after_mm3},
                    {"volume_change_percent", f.volume_change_percent}});
  }
  ctx.summary["cuts"] = std::move(list);
}

void colour_cut_cells(RunContext& ctx, const BodySurface& surface) {
  const LinkedVolume& volume = ctx.model.volume;
  const std::vector<CellFace> faces = cut_faces(volume);
  const CutFaceColours colours = colour_cut_faces(surface, faces, ctx.residual_stress_kPa);
  const std::size_t n = static_cast<std::size_t>(volume.cell_count());
  DataArray traction{"released_traction", 1, std::vector<double>(n, 0.0)};
  DataArray depth{"cut_face_depth", 1, std::vector<double>(n, 0.0)};
  std::vector<int> count(n, 0);
  for (std::size_t i = 0; i < faces.size(); ++i) {
    const std::size_t c = static_cast<std::size_t>(faces[i].cell);
    traction.values[c] = std::max(traction.values[c], colours.released_traction_kPa[i] * units::Pa_per_kPa);
    depth.values[c] += colours.depth[i];
    ++count[c];
  }
  for (std::size_t c = 0; c < n; ++c)
    if (count[c] > 0) depth.values[c] /= count[c];
  ctx.fields.cell_data.push_back(std::move(traction));
  ctx.fields.cell_data.push_back(std::move(depth));
  if (!faces.empty()) {
    const auto [lo, hi] = std::minmax_element(colours.released_traction_kPa.begin(), colours.released_traction_kPa.end());
    ctx.summary["cut_faces"] = {{"faces", faces.size()}, {"released_traction_min_kPa", *lo}, {"released_traction_max_kPa", *hi}};
  }
}

}  // namespace

void stage_measure(RunContext& ctx) {
  const CaseCuts cuts = parse_case_cuts(ctx.case_file);
  if (cuts.empty()) return;
  if (ctx.displacement_mm.size() != static_cast<std::size_t>(ctx.model.volume.vertex_count()))
    ctx.displacement_mm.assign(static_cast<std::size_t>(ctx.model.volume.vertex_count()), Vec3::Zero());
  const BodySurface surface(ctx.model);
  const CutRequests requests = resolve_case_cuts(ctx.case_file, cuts, surface);
  const CutPlan plan = plan_case_cuts(ctx.case_file, cuts, requests, surface);
  if (!plan.incisions.empty()) measure_incisions(ctx, surface, plan);
  report(ctx.progress, "measurements", 0.5);
  if (!plan.scalpel_paths.empty() || !plan.flaps.empty()) measure_cuts(ctx, cuts, plan);
  colour_cut_cells(ctx, surface);
}

}  // namespace cleave
