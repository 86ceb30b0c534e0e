#include "studio/studio_compute.hpp"

#include <chrono>
#include <cmath>
#include <fmt/format.h>

#include "cleave/core/error.hpp"
#include "cleave/io/atomic_file.hpp"
#include "cleave/io/gltf_writer.hpp"
#include "cleave/io/ply_writer.hpp"
#include "cleave/io/vtu_writer.hpp"
#include "cleave/cut/place_incisions.hpp"
#include "cleave/fem/solve_static.hpp"
#include "cleave/viz/incision_ellipses.hpp"
#include "cleave/viz/wound_measures.hpp"

namespace cleave::studio {
namespace {

using Clock = std::chrono::steady_clock;

// The round-incision preview (paper section 5, fig. 5), in cells of the model's grid.
constexpr double kPreviewRadiusCells = 2.5;   ///< incision radius
constexpr double kPreviewDepthCells = 2.0;    ///< incision depth
constexpr double kPreviewSpacingCells = 9.0;  ///< least distance between centres (> diameter + 1 cell)

double ms_since(Clock::time_point t0) { return std::chrono::duration<double, std::milli>(Clock::now() - t0).count(); }

/// Rounds to 1e-3 mm / kPa: the page does not need more and the messages stay small.
double rounded(double v) { return std::round(v * 1000.0) / 1000.0; }

nlohmann::json float_array(const std::vector<float>& values) {
  nlohmann::json a = nlohmann::json::array();
  a.get_ref<nlohmann::json::array_t&>().reserve(values.size());
  for (float v : values) a.push_back(rounded(static_cast<double>(v)));
  return a;
}

}  // namespace

StudioCompute::StudioCompute(const StudioSession& session, std::function<void(std::string)> send)
    : session_(session), send_(std::move(send)) {
  worker_ = std::make_unique<FieldWorker>(
      [this](FieldWorker::Result r) {
        std::string text = r.message.dump();
        {
          std::lock_guard lock(latest_mutex_);
          if (r.message.value("type", "") == "result") latest_result_ = text;
        }
        send_(std::move(text));
      },
      [this](nlohmann::json progress) { send_(progress.dump()); });
}

StudioCompute::~StudioCompute() { worker_.reset(); }

void StudioCompute::design_changed(const DesignState& design, std::uint64_t seq) {
  worker_->submit([this, design, seq](const FieldWorker::Context& ctx) { return compute(design, seq, ctx); });
}

std::vector<std::string> StudioCompute::welcome_messages() const {
  std::lock_guard lock(latest_mutex_);
  if (latest_result_.empty()) return {};
  return {latest_result_};
}

void StudioCompute::prepare(const FieldWorker::Context& ctx) {
  if (body_surface_) return;
  report(ctx.progress, "preparing the model", 0.0);
  const TissueModel& model = session_.model();
  body_surface_ = std::make_unique<BodySurface>(model);
  const double h = model.volume.grid().cell_size_mm;
  IncisionPattern pattern;
  pattern.radius_mm = kPreviewRadiusCells * h;
  pattern.depth_mm = kPreviewDepthCells * h;
  pattern.spacing_mm = kPreviewSpacingCells * h;
  try {
    preview_incisions_ = place_incisions(*body_surface_, pattern);
  } catch (const InputError&) {
    preview_incisions_.clear();  // a body too small for the preview: show the fields only
  }
}

nlohmann::json StudioCompute::compute(const DesignState& design, std::uint64_t seq, const FieldWorker::Context& ctx) {
  const auto t0 = Clock::now();
  nlohmann::json timings = nlohmann::json::object();
  const TissueModel& model = session_.model();
  prepare(ctx);
  if (ctx.superseded()) return nullptr;
  nlohmann::json message = {{"type", "result"},
                            {"generation", ctx.generation},
                            {"seq", seq},
                            {"design_items", design.strokes.size() + design.control_points.size() + design.cuts.size()}};

  // 1. The residual stress design (stress/stress_designer.hpp), incremental between edits.
  StressDesign stress_design;
  for (const Stroke& s : design.strokes) stress_design.strokes.push_back({s.points_mm, StrokePlacement::surface});
  for (const ControlPoint& p : design.control_points)
    stress_design.control_points.push_back({p.position_mm, p.langer_kPa, p.cross_kPa});
  const bool has_design = !stress_design.strokes.empty() && !stress_design.control_points.empty();
  const DesignResult* fields = nullptr;
  stress_kPa_.clear();
  if (!stress_design.strokes.empty() || !stress_design.control_points.empty()) {
    report(ctx.progress, "direction and eigenvalue fields", 0.1);
    try {
      if (!designer_) designer_ = std::make_unique<StressDesigner>(model, stress_design);
      else designer_->set_design(stress_design);
      fields = &designer_->result();
      timings["directions"] = 1000.0 * fields->timings.directions_s;
      timings["eigenvalues"] = 1000.0 * fields->timings.eigenvalues_s;
      timings["equilibration"] = 1000.0 * fields->timings.equilibration_s;
      if (has_design) stress_kPa_ = fields->stress_kPa;
      message["equilibrium_residual"] = {{"designed", fields->residual_designed}, {"final", fields->residual_final}};
    } catch (const InputError& e) {
      message["design_error"] = e.what();
      designer_.reset();
    }
  }
  if (ctx.superseded()) return nullptr;

  // 2. The cuts: the round-incision preview and the user's cuts, on a copy of the model.
  auto t = Clock::now();
  report(ctx.progress, "incisions and cuts", 0.4);
  CutRequests requests;
  if (has_design) requests.incisions = preview_incisions_;
  for (const Cut& c : design.cuts) {
    if (c.kind == CutKind::flap) requests.flaps.push_back({c.path_mm, c.depth_mm, FlapShape::u_shaped});
    else requests.scalpel_cuts.push_back({c.path_mm, c.depth_mm, 0.0});
  }
  CutPlan plan;
  try {
    plan = plan_cuts(*body_surface_, requests);
  } catch (const InputError& e) {
    message["cut_error"] = e.what();
    requests.scalpel_cuts.clear();
    requests.flaps.clear();
    plan = plan_cuts(*body_surface_, requests);
  }
  preview_model_ = std::make_shared<TissueModel>(model);
  apply_cut_plan(preview_model_->volume, plan);
  preview_surface_ = std::make_unique<RenderSurface>(build_render_surface(*preview_model_));
  timings["cuts"] = ms_since(t);
  if (ctx.superseded()) return nullptr;

  // 3. The wounds open: statics with the residual stress on the cut body.
  displacement_mm_.clear();
  if (!stress_kPa_.empty() && !requests.empty()) {
    t = Clock::now();
    report(ctx.progress, "opening the incisions", 0.6);
    StaticOptions options;
    options.solver = SolverKind::cholmod;
    const StaticResult r = solve_static(*preview_model_, stress_kPa_, options);
    displacement_mm_ = r.displacement_mm;
    timings["incisions"] = ms_since(t);
  }
  if (ctx.superseded()) return nullptr;

  // 4. What the page shows, per surface vertex.
  t = Clock::now();
  const RenderSurface& surface = *preview_surface_;
  const std::vector<Vec3> x = deformed_positions(surface, preview_model_->volume, displacement_mm_);
  const std::vector<CellId> hidden = plan.hidden_cells();
  std::vector<std::uint8_t> is_hidden(static_cast<std::size_t>(model.volume.cell_count()), 0);
  for (CellId c : hidden) is_hidden[static_cast<std::size_t>(c)] = 1;
  std::vector<float> positions, direction, langer, cross, depth;
  positions.reserve(3 * x.size());
  for (std::size_t v = 0; v < x.size(); ++v) {
    for (int a = 0; a < 3; ++a) positions.push_back(static_cast<float>(x[v][a]));
    if (fields) {
      const CellId c = surface.cell[v];
      const DirectionFrame& f = fields->frames[static_cast<std::size_t>(c)];
      for (int a = 0; a < 3; ++a) direction.push_back(static_cast<float>(f.langer[a]));
      langer.push_back(static_cast<float>(fields->eigenvalues_kPa[static_cast<std::size_t>(c)][0]));
      cross.push_back(static_cast<float>(fields->eigenvalues_kPa[static_cast<std::size_t>(c)][1]));
    }
    depth.push_back(static_cast<float>((surface.reference_mm[v] - x[v]).norm()));
  }
  std::vector<std::uint32_t> triangles;
  triangles.reserve(3 * surface.triangles.size());
  for (std::int32_t i = 0; i < surface.triangle_count(); ++i) {
    if (is_hidden[static_cast<std::size_t>(surface.triangle_cell(i))]) continue;
    for (SurfaceVertexId v : surface.triangles[static_cast<std::size_t>(i)]) triangles.push_back(static_cast<std::uint32_t>(v));
  }
  message["surface"] = {{"positions_mm", float_array(positions)}, {"triangles", triangles}};
  {
    ExportSnapshot snapshot{preview_model_, displacement_mm_, stress_kPa_, make_surface_mesh(surface, x)};
    std::lock_guard lock(latest_mutex_);
    latest_export_ = std::move(snapshot);
  }
  nlohmann::json f = nlohmann::json::object();
  if (fields) {
    f["direction"] = float_array(direction);
    f["langer_kPa"] = float_array(langer);
    f["cross_kPa"] = float_array(cross);
  }
  if (!displacement_mm_.empty()) f["depth"] = float_array(depth);  // displacement magnitude (mm)
  message["fields"] = f;

  // 5. Measurements: incision openings and wound widths.
  nlohmann::json incisions = nlohmann::json::array();
  nlohmann::json wounds = nlohmann::json::array();
  if (!displacement_mm_.empty()) {
    for (const IncisionFrame& frame : plan.incisions) {
      const auto m = measure_incision(*body_surface_, displacement_mm_, frame, std::nullopt);
      if (m) incisions.push_back({{"centre_mm", {frame.centre_mm.x(), frame.centre_mm.y(), frame.centre_mm.z()}},
                                  {"opening_mm", m->opening_mm},
                                  {"gap_mm", m->gap_mm}});
    }
    std::size_t scalpel = 0;
    for (const Cut& c : design.cuts) {
      if (c.kind != CutKind::scalpel || scalpel >= plan.scalpel_paths.size()) continue;
      const WoundWidth w = scalpel_wound_width(preview_model_->volume, displacement_mm_, plan.scalpel_paths[scalpel++]);
      wounds.push_back({{"cut", c.id}, {"width_mm", w.max_mm}, {"mean_width_mm", w.mean_mm}});
    }
  }
  message["incisions"] = incisions;
  message["wounds"] = wounds;
  const auto [lo, hi] = model.bounding_box_mm();
  message["bounding_box_mm"] = {{lo.x(), lo.y(), lo.z()}, {hi.x(), hi.y(), hi.z()}};
  message["cell_size_mm"] = model.volume.grid().cell_size_mm;
  message["cells"] = model.volume.cell_count();
  timings["surface"] = ms_since(t);
  timings["total"] = ms_since(t0);
  message["timings_ms"] = timings;
  return message;
}

void StudioCompute::export_result(ExportFormat format, const std::filesystem::path& file) const {
  std::lock_guard lock(latest_mutex_);
  const ExportSnapshot& e = latest_export_;
  if (!e.model) throw InputError("export: no result yet; wait for the first result");
  if (format == ExportFormat::vtu) {
    VolumeFields fields;
    if (!e.displacement_mm.empty()) {
      DataArray d{"displacement", 3, {}};
      for (const Vec3& u : e.displacement_mm) d.values.insert(d.values.end(), {u.x(), u.y(), u.z()});
      fields.point_data.push_back(std::move(d));
    }
    if (!e.stress_kPa.empty()) {
      DataArray s{"residual_stress_kPa", 6, {}};
      for (const Vec6& v : e.stress_kPa) s.values.insert(s.values.end(), v.data(), v.data() + 6);
      fields.cell_data.push_back(std::move(s));
    }
    write_vtu(file, e.model->volume, fields);
  } else if (format == ExportFormat::ply) {
    write_ply(file, e.mesh);
  } else {
    write_gltf(file, e.mesh);
  }
}

}  // namespace cleave::studio
