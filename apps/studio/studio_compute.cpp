#include "studio/studio_compute.hpp"

#include <array>
#include <chrono>
#include <cmath>
#include <fmt/format.h>
#include <future>
#include <random>
#include <tbb/parallel_for.h>

#include "cleave/core/error.hpp"
#include "cleave/io/atomic_file.hpp"
#include "cleave/io/case_design.hpp"
#include "cleave/io/gltf_writer.hpp"
#include "cleave/io/ply_writer.hpp"
#include "cleave/io/vtu_writer.hpp"
#include "cleave/cut/place_incisions.hpp"
#include "cleave/fem/dynamics.hpp"
#include "cleave/pipeline/held_vertices.hpp"
#include "cleave/stress/equilibrium_operator.hpp"
#include "cleave/stress/stroke_constraints.hpp"
#include "cleave/viz/incision_ellipses.hpp"
#include "cleave/viz/streamlines.hpp"
#include "cleave/viz/wound_measures.hpp"
#include "studio/cut_face_values.hpp"
#include "studio/finite_message.hpp"
#include "studio/packed_array.hpp"
#include "studio/surface_residual.hpp"
#include "studio/wire_message.hpp"

namespace cleave::studio {
namespace {

using Clock = std::chrono::steady_clock;

// The round-incision preview (paper section 5, fig. 5), in cells of the model's grid.
constexpr double kPreviewRadiusCells = 2.5;   ///< incision radius
constexpr double kPreviewDepthCells = 2.0;    ///< incision depth
constexpr double kPreviewSpacingCells = 9.0;  ///< least distance between centres (> diameter + 1 cell)

// The wound opening after a cut: Newmark steps streamed to the page, one frame per step.
constexpr int kOpeningFrames = 8;
constexpr double kOpeningStep_s = 0.03;            ///< 8 steps: the first 0.24 s of the opening (Newmark is stable at any step)
constexpr double kOpeningDamping_per_s = 20.0;     ///< mass damping, as examples/plate_flap_dynamic.json
/// The opening's frames solve with a budget (DynamicsSettings::iterations_per_step): 5 multigrid CG
/// iterations of a cycle with a light fine smoother instead of the 8-15 a step needs to its
/// tolerance; the picture after the frames is the statics' equilibrium, solved exactly.
constexpr int kOpeningIterationsPerStep = kRealTimeIterationsPerStep;
/// Generalized-alpha with nothing left of what 30 ms steps cannot resolve: the opening's own
/// modes (in-plane waves cross a cut in about 3 ms). Under HHT (radius 0.67) the streamed width
/// alternated by +-20 % from frame to frame for all 8 frames.
constexpr double kOpeningHighFrequencyRadius = 0.0;

constexpr int kStreamlineSeedStride = 4;  ///< cells between seeds
constexpr int kStreamlineMaxSteps = 40;   ///< half cells per direction

double ms_since(Clock::time_point t0) { return std::chrono::duration<double, std::milli>(Clock::now() - t0).count(); }


/// The design settings of the session's case (weights, equilibration, equilibrium support,
/// solver, snap tolerance), without strokes or control points: the library's defaults when the
/// case has no "design" section. The studio edits the strokes and points itself.
StressDesign design_settings(const CaseFile& case_file) {
  const nlohmann::json* section = case_file.section("design");
  if (!section || !section->is_object()) return StressDesign{};
  return parse_design_settings_json(*section, case_file.at("design"));
}

/// Triangle indices of `surface` without the hidden plugs of the round incisions.
std::vector<std::uint32_t> visible_triangles(const RenderSurface& surface, const CutPlan& plan) {
  std::vector<std::uint8_t> hidden(surface.quad_of_face.size() / 6, 0);
  for (CellId c : plan.hidden_cells()) hidden[static_cast<std::size_t>(c)] = 1;
  std::vector<std::uint32_t> triangles;
  triangles.reserve(3 * surface.triangles.size());
  for (std::int32_t i = 0; i < surface.triangle_count(); ++i) {
    if (hidden[static_cast<std::size_t>(surface.triangle_cell(i))]) continue;
    for (SurfaceVertexId v : surface.triangles[static_cast<std::size_t>(i)]) triangles.push_back(static_cast<std::uint32_t>(v));
  }
  return triangles;
}

}  // namespace

StudioCompute::StudioCompute(const StudioSession& session, Send send, FieldWorker::JobThread jobs)
    : session_(session), send_(std::move(send)) {
  std::random_device entropy;
  server_token_ = fmt::format("{:08x}{:08x}", entropy(), entropy());
  worker_ = std::make_unique<FieldWorker>(
      [this](FieldWorker::Result r) {
        if (r.message.value("type", "") == "result") publish_result(std::move(r.message));
        else send_(wire_encoded(r.message), BroadcastKind::every);
      },
      [this](nlohmann::json progress) { send_(checked_outgoing(std::move(progress)).dump(), BroadcastKind::every); }, jobs);
}

void StudioCompute::publish_result(nlohmann::json message) {
  // How much work the edits caused: an edit that arrives while another's work runs replaces
  // the queued one, which then never starts (skipped); the page and its tests can see it.
  message["computations"] = {{"submitted", worker_->jobs_submitted()},
                             {"started", worker_->jobs_started()},
                             {"skipped", worker_->jobs_skipped()},
                             {"published", ++results_published_}};
  // The connected clients hold the parts of the surface they were last sent that are made with
  // it (every client gets every result or a newer one in its place, never a partial one in place
  // of a full one: broadcast_kind.hpp; one that connects later gets latest_result_ in full): a
  // result on that surface goes out without them.
  static const std::array<nlohmann::json::json_pointer, 2> kSurfaceParts = {nlohmann::json::json_pointer("/surface/triangles"),
                                                                            nlohmann::json::json_pointer("/fields/cut_depth")};
  std::vector<std::pair<const nlohmann::json::json_pointer*, nlohmann::json>> held;
  if (message["surface"].is_object()) {
    const std::string id = message["surface"].value("id", "");
    if (id == broadcast_surface_id_)
      for (const nlohmann::json::json_pointer& part : kSurfaceParts) {
        if (!message.contains(part)) continue;
        held.emplace_back(&part, std::move(message[part]));
        message[part.parent_pointer()].erase(part.back());
      }
    broadcast_surface_id_ = id;
  }
  std::string text = wire_encoded(message);
  const BroadcastKind kind = held.empty() ? BroadcastKind::full_result : BroadcastKind::partial_result;
  for (auto& [part, value] : held) message[*part] = std::move(value);
  {
    std::lock_guard lock(latest_mutex_);
    latest_result_ = std::move(message);
  }
  send_(std::move(text), kind);
}

StudioCompute::~StudioCompute() { worker_.reset(); }

void StudioCompute::design_changed(const DesignState& design, std::uint64_t seq) {
  worker_->submit([this, design, seq](const FieldWorker::Context& ctx) { return compute(design, seq, ctx); });
}

std::vector<std::string> StudioCompute::welcome_messages() const {
  std::lock_guard lock(latest_mutex_);
  if (latest_result_.is_null()) return {};
  return {wire_encoded(latest_result_)};
}

void StudioCompute::prepare(const FieldWorker::Context& ctx) {
  if (body_surface_) return;
  report(ctx.progress, "preparing the model", 0.0);
  const TissueModel& model = session_.model();
  design_settings_ = design_settings(session_.case_file());
  simulation_ = parse_simulation_settings(session_.case_file());
  if (design_settings_.support == EquilibriumSupport::simulation) design_settings_.held_vertices = held_vertices(model, simulation_);
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

const DesignResult* StudioCompute::design_fields(const DesignState& design, nlohmann::json& message,
                                                 nlohmann::json& timings) {
  const TissueModel& model = session_.model();
  StressDesign stress_design = design_settings_;
  for (const Stroke& s : design.strokes) stress_design.strokes.push_back({s.points_mm, StrokePlacement::surface});
  for (const ControlPoint& p : design.control_points)
    stress_design.control_points.push_back({p.position_mm, p.langer_kPa, p.cross_kPa});
  if (stress_design.strokes.empty() && stress_design.control_points.empty()) {
    designer_.reset();
    return nullptr;
  }
  if (!stress_design.control_points.empty()) {
    // Directions and magnitudes with the case's settings (on the bare abdomen the demo's: no
    // equilibrium term, exactly equilibrated at the free vertices; the residual display shows
    // what is left).
    try {
      // The picture may be drawn from the equilibration's provisional stress (1e-6 of the
      // designed forces: what the picture cannot tell apart); complete_design() finishes it
      // after the picture is sent.
      if (!designer_) designer_ = std::make_unique<StressDesigner>(model, stress_design);
      else designer_->set_design(stress_design, EquilibrationPass::picture);
      const DesignResult& r = designer_->result();
      timings["directions"] = 1000.0 * r.timings.directions_s;
      timings["eigenvalues"] = 1000.0 * r.timings.eigenvalues_s;
      if (stress_design.equilibration != Equilibration::none) timings["equilibration"] = 1000.0 * r.timings.equilibration_s;
      message["equilibrium_residual"] = {{"designed", r.residual_designed}, {"final", r.residual_final}};
      if (r.provisional) message["equilibrium_residual"]["provisional"] = true;
      stress_kPa_ = r.stress_kPa;
      return &r;
    } catch (const InputError& err) {
      // An edit that fails validation (a stroke or point dragged off the surface) leaves the
      // designer as it was (StressDesigner's contract): it is kept, with its factors, for the next
      // edit. With the strokes unchanged the error is in the control points: the last valid
      // design is shown; otherwise the new strokes' directions are, if they are valid.
      message["design_error"] = err.what();
      if (designer_ && same_strokes(stress_design.strokes, designer_->design().strokes)) return last_valid_design(message);
    } catch (const ComputeError& err) {
      message["design_error"] = err.what();
      designer_.reset();
    }
  } else {
    designer_.reset();
  }
  // Directions only (no control point yet, or the magnitudes failed): the direction step needs
  // no eigenvalues (paper section 6.3).
  const auto t = Clock::now();
  try {
    // The strokes are checked before the interpolator is built (a factorization: 1 s at 45k cells).
    const double tolerance_mm = stress_design.snap_tolerance_cells * model.volume.grid().cell_size_mm;
    const std::vector<LineTarget> targets = stroke_line_targets(model, stress_design.strokes, tolerance_mm);
    if (!langer_only_) {
      langer_only_ = std::make_unique<LineFieldInterpolator>(model.volume, stress_design.weights);
      LineFieldInterpolator normal_interp(model.volume, stress_design.weights);
      normal_axes_ = normal_axes(normal_interp.interpolate(surface_normal_targets(model)));
    }
    directions_only_ = DesignResult{};
    directions_only_.frames = direction_frames(langer_only_->interpolate(targets), normal_axes_);
  } catch (const InputError& err) {
    message["design_error"] = err.what();
    if (designer_) return last_valid_design(message);  // the strokes are invalid: nothing newer to show
    return nullptr;
  }
  timings["directions"] = ms_since(t);
  if (!message.contains("design_error") && stress_design.control_points.empty())
    message["eigenvalue_note"] = "directions only: place a control point (Magnitude tool) to set the eigenvalues";
  return &directions_only_;
}

const DesignResult* StudioCompute::last_valid_design(nlohmann::json& message) {
  const DesignResult& r = designer_->result();
  message["design_error"] = message["design_error"].get<std::string>() + "; the last valid design is shown";
  message["equilibrium_residual"] = {{"designed", r.residual_designed}, {"final", r.residual_final}};
  if (r.provisional) message["equilibrium_residual"]["provisional"] = true;
  stress_kPa_ = r.stress_kPa;
  return &r;
}

bool StudioCompute::cut_model(const CutRequests& requests, const std::string& key, nlohmann::json& message) {
  if (preview_model_ && key == cut_key_) return false;
  try {
    plan_ = plan_cuts(*body_surface_, requests);
  } catch (const InputError& e) {
    message["cut_error"] = e.what();
    CutRequests incisions_only;
    incisions_only.incisions = requests.incisions;
    plan_ = plan_cuts(*body_surface_, incisions_only);
  }
  // The statics refer to the model being replaced; a factorization still running keeps its own
  // reference to it and is dropped when done.
  preview_statics_.reset();
  preview_multigrid_.reset();
  factor_failed_.clear();
  if (pending_statics_.valid()) abandoned_statics_.push_back(std::move(pending_statics_));
  std::erase_if(abandoned_statics_, [](const auto& f) { return f.wait_for(std::chrono::seconds(0)) == std::future_status::ready; });
  preview_model_ = std::make_shared<TissueModel>(session_.model());
  apply_cut_plan(preview_model_->volume, plan_);
  preview_surface_ = std::make_unique<RenderSurface>(build_render_surface(*preview_model_));
  // Measurements sample the margins on the cut body's own surface (its split vertices).
  // Their sample points do not depend on the displacement: sampled once per cut body.
  incision_margins_.clear();
  surface_residuals_.clear();  // per vertex of the render surface being replaced
  if (!plan_.incisions.empty()) {
    const BodySurface cut_body_surface(*preview_model_);
    incision_margins_.resize(plan_.incisions.size());
    tbb::parallel_for(std::size_t{0}, plan_.incisions.size(), [&](std::size_t i) {
      incision_margins_[i] = sample_incision_margins(cut_body_surface, plan_.incisions[i]);
    });
  }
  // The case's supports on the cut body, and the removed plugs (hidden, touching nothing: free,
  // corotated plugs had made the multigrid need 55-77 iterations per step at 45k cells).
  held_cut_ = held_vertices(*preview_model_, simulation_, plan_.hidden_cells());
  cut_face_layout_ = cut_face_layout(*body_surface_, *preview_model_, *preview_surface_);
  cut_key_ = key;
  surface_id_ = fmt::format("{}-{}", server_token_, ++surfaces_built_);
  return true;
}

void StudioCompute::stream_opening(const DesignState& design, std::uint64_t generation, const FieldWorker::Context& ctx,
                                   nlohmann::json& timings) {
  const auto t0 = Clock::now();
  const RenderSurface& surface = *preview_surface_;
  DynamicsSettings settings;
  settings.mass_damping_per_s = kOpeningDamping_per_s;
  // Multigrid-preconditioned CG (the library's default): the corotated stiffness changes every
  // step, and refactoring it with CHOLMOD took 5 s per frame at 45k cells.
  settings.solver = SolverKind::multigrid_cg;
  settings.fixed_vertices = held_cut_;
  settings.iterations_per_step = kOpeningIterationsPerStep;
  settings.high_frequency_radius = kOpeningHighFrequencyRadius;
  Dynamics sim(*preview_model_, stress_kPa_, settings);
  std::vector<std::uint32_t> triangles = visible_triangles(surface, plan_);
  double step_ms = 0;
  for (int i = 0; i <= kOpeningFrames; ++i) {
    if (ctx.superseded()) return;
    report(ctx.progress, "opening the wound", 0.5 + 0.2 * i / kOpeningFrames);
    const auto ts = Clock::now();
    SolveReport step;
    if (i > 0) step = sim.step(kOpeningStep_s);
    const std::vector<Vec3> u = sim.displacement_mm();
    const std::vector<Vec3> x = deformed_positions(surface, preview_model_->volume, u);
    nlohmann::json frame = {{"type", "frame"}, {"generation", generation}, {"index", i}, {"frames", kOpeningFrames},
                            {"time_s", sim.time_s()}};
    std::vector<float> positions;
    positions.reserve(3 * x.size());
    for (const Vec3& p : x)
      for (int a = 0; a < 3; ++a) positions.push_back(static_cast<float>(p[a]));
    frame["positions_mm"] = packed_floats(positions);
    if (i == 0) frame["triangles"] = packed_indices(triangles);
    std::size_t scalpel = 0;
    for (const Cut& c : design.cuts) {
      if (c.kind != CutKind::scalpel || scalpel >= plan_.scalpel_paths.size()) continue;
      frame["width_mm"] = scalpel_wound_width(preview_model_->volume, u, plan_.scalpel_paths[scalpel++]).max_mm;
    }
    if (i > 0) step_ms += ms_since(ts);
    frame["step_ms"] = i > 0 ? step_ms / i : 0.0;
    // What the budget left of this step (kOpeningIterationsPerStep): its iterations and its
    // residual over the one it started from.
    frame["step_iterations"] = step.iterations;
    if (step.initial_relative_residual > 0) frame["step_residual"] = step.relative_residual / step.initial_relative_residual;
    frame = checked_outgoing(std::move(frame));
    send_(wire_encoded(frame), BroadcastKind::frame);
    if (frame["type"] == "error") return;  // the statics after it report the result (or its error)
  }
  timings["opening"] = ms_since(t0);
  timings["frame"] = step_ms / kOpeningFrames;
}

StaticResult StudioCompute::solve_preview_statics(nlohmann::json& message) {
  const StaticOptions options = preview_static_options(held_cut_);
  if (!preview_statics_ && pending_statics_.valid() &&
      pending_statics_.wait_for(std::chrono::seconds(0)) == std::future_status::ready) {
    try {
      preview_statics_ = pending_statics_.get();
      preview_multigrid_.reset();
    } catch (const std::exception& e) {
      // E.g. out of memory for the factor: this cut model stays with the multigrid.
      factor_failed_ = e.what();
    }
  }
  if (!factor_failed_.empty()) message["statics_note"] = "the direct factorization failed (" + factor_failed_ + "); solved by the multigrid";
  StaticSolver* statics = preview_statics_.get();
  if (!statics) {
    if (!preview_multigrid_) {
      StaticOptions multigrid = options;
      multigrid.solver = SolverKind::multigrid_cg;
      // To SolveSettings' 1e-8: the picture's 1e-4 is measured for the factor's float copy, whose
      // error is rounding; a CG stopped at 1e-4 leaves its smooth modes unbounded.
      multigrid.settings = SolveSettings{};
      preview_multigrid_ = std::make_unique<StaticSolver>(*preview_model_, multigrid);
    }
    statics = preview_multigrid_.get();
  }
  StaticResult r = statics->solve(stress_kPa_);
  message["statics_solver"] = r.solver_name;
  if (!preview_statics_ && !pending_statics_.valid() && factor_failed_.empty()) {
    // The lazy caches of the volume are filled here, so that the factorization's thread only reads.
    preview_model_->volume.vertex_cells();
    preview_model_->volume.component_count();
    pending_statics_ = std::async(std::launch::async, [model = preview_model_, options] {
      auto solver = std::make_unique<StaticSolver>(*model, options);
      solver->set_up_solver();
      return solver;
    });
  }
  return r;
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
  report(ctx.progress, "direction and eigenvalue fields", 0.1);
  stress_kPa_.clear();
  const DesignResult* fields = design_fields(design, message, timings);
  const bool has_stress = !stress_kPa_.empty();
  if (ctx.superseded()) return nullptr;

  // 2. The cuts: the round-incision preview and the user's cuts, on a copy of the model; the
  // cut model and its render surface are kept while the cuts do not change.
  auto t = Clock::now();
  report(ctx.progress, "incisions and cuts", 0.4);
  CutRequests requests;
  if (has_stress) requests.incisions = preview_incisions_;
  for (const Cut& c : design.cuts) {
    if (c.kind == CutKind::flap) requests.flaps.push_back({c.path_mm, c.depth_mm, FlapShape::u_shaped});
    else requests.scalpel_cuts.push_back({c.path_mm, c.depth_mm, 0.0});
  }
  nlohmann::json cuts_json = nlohmann::json::array();
  for (const Cut& c : design.cuts) cuts_json.push_back({to_string(c.kind), c.depth_mm, c.path_mm.size(), c.path_mm.front().x(),
                                                        c.path_mm.back().x(), c.path_mm.back().y(), c.path_mm.back().z()});
  const std::string previous_key = cut_key_;
  const std::string key = fmt::format("{}|{}", has_stress ? 1 : 0, cuts_json.dump());
  const bool recut = cut_model(requests, key, message);
  timings["cuts"] = ms_since(t);
  if (ctx.superseded()) return nullptr;
  const bool user_cuts_changed = recut && previous_key.substr(previous_key.find('|') + 1) != key.substr(key.find('|') + 1);

  // 3. The wounds open: the opening streamed frame by frame when the user's cuts changed, then
  // the equilibrium by statics with the residual stress on the cut body.
  displacement_mm_.clear();
  if (has_stress && !requests.empty()) {
    if (user_cuts_changed && !design.cuts.empty()) {
      // The opening takes seconds: it starts from the final design, not the provisional one.
      if (designer_ && designer_->result().provisional) {
        t = Clock::now();
        designer_->finish_equilibration();
        const DesignResult& r = designer_->result();
        stress_kPa_ = r.stress_kPa;
        message["equilibrium_residual"] = {{"designed", r.residual_designed}, {"final", r.residual_final}};
        timings["equilibration"] = 1000.0 * r.timings.equilibration_s;
      }
      stream_opening(design, ctx.generation, ctx, timings);
      if (ctx.superseded()) return nullptr;
    }
    t = Clock::now();
    report(ctx.progress, "opening the incisions", 0.7);
    const StaticResult r = solve_preview_statics(message);
    displacement_mm_ = r.displacement_mm;
    timings["incisions"] = ms_since(t);
  }
  if (ctx.superseded()) return nullptr;

  // 4. What the page shows, per surface vertex.
  t = Clock::now();
  report(ctx.progress, "surface", 0.9);
  const RenderSurface& surface = *preview_surface_;
  const std::vector<Vec3> x = deformed_positions(surface, preview_model_->volume, displacement_mm_);
  std::vector<float> positions, direction, langer, cross, moved;
  positions.reserve(3 * x.size());
  for (std::size_t v = 0; v < x.size(); ++v) {
    for (int a = 0; a < 3; ++a) positions.push_back(static_cast<float>(x[v][a]));
    moved.push_back(static_cast<float>((surface.reference_mm[v] - x[v]).norm()));
    if (!fields) continue;
    const auto c = static_cast<std::size_t>(surface.cell[v]);
    for (int a = 0; a < 3; ++a) direction.push_back(static_cast<float>(fields->frames[c].langer[a]));
    if (fields->eigenvalues_kPa.empty()) continue;
    langer.push_back(static_cast<float>(fields->eigenvalues_kPa[c][0]));
    cross.push_back(static_cast<float>(fields->eigenvalues_kPa[c][1]));
  }
  message["surface"] = {{"id", surface_id_},
                        {"positions_mm", packed_floats(positions)},
                        {"triangles", packed_indices(visible_triangles(surface, plan_))}};
  nlohmann::json f = nlohmann::json::object();
  if (fields) f["direction"] = packed_floats(direction);
  if (!langer.empty()) {
    f["langer_kPa"] = packed_floats(langer);
    f["cross_kPa"] = packed_floats(cross);
  }
  if (has_stress) f["residual_kPa"] = packed_floats(surface_residual());
  if (!displacement_mm_.empty()) f["displacement_mm"] = packed_floats(moved);
  // Cut faces coloured by depth (0 skin .. 1 inner layer) and by released traction (paper fig. 5).
  if (cut_face_layout_.any) {
    f["cut_depth"] = packed_floats(cut_face_layout_.depth);
    f["traction_kPa"] = packed_floats(cut_face_traction_kPa(cut_face_layout_, surface, stress_kPa_));
  }
  message["fields"] = f;
  timings["surface"] = ms_since(t);
  t = Clock::now();
  if (fields && !design.strokes.empty()) {
    StreamlineOptions so;
    so.seed_stride_cells = kStreamlineSeedStride;
    so.max_steps = kStreamlineMaxSteps;
    nlohmann::json lines = nlohmann::json::array();
    for (const std::vector<Vec3>& line : trace_streamlines(model.volume, fields->frames, so)) {
      std::vector<float> flat;
      for (const Vec3& p : line)
        for (int a = 0; a < 3; ++a) flat.push_back(static_cast<float>(p[a]));
      lines.push_back(packed_floats(flat));
    }
    message["streamlines_mm"] = lines;
  }

  if (message.contains("streamlines_mm")) timings["streamlines"] = ms_since(t);
  t = Clock::now();

  // 5. Measurements: incision openings and wound widths.
  nlohmann::json incisions = nlohmann::json::array();
  nlohmann::json wounds = nlohmann::json::array();
  nlohmann::json flaps = nlohmann::json::array();
  if (!displacement_mm_.empty()) {
    const double h = model.volume.grid().cell_size_mm;
    // Each incision is measured on its own (the surface and the displacement are only read).
    std::vector<nlohmann::json> measured(plan_.incisions.size());
    tbb::parallel_for(std::size_t{0}, plan_.incisions.size(), [&](std::size_t i) {
      const IncisionFrame& frame = plan_.incisions[i];
      // The designed Langer direction under the incision is the reference of the long axis.
      std::optional<TangentDirection> reference;
      CellId c = model.volume.cell_containing(frame.centre_mm - 0.5 * h * frame.normal);
      if (c == kNone) c = model.volume.cell_containing(frame.centre_mm - h * frame.normal);
      if (c != kNone && fields) reference = TangentDirection{fields->frames[static_cast<std::size_t>(c)].langer, 1.0};
      const auto m = measure_incision(preview_model_->volume, incision_margins_[i], displacement_mm_, frame, reference);
      if (!m) return;
      nlohmann::json j = {{"centre_mm", {frame.centre_mm.x(), frame.centre_mm.y(), frame.centre_mm.z()}},
                          {"opening_mm", m->opening_mm},
                          {"gap_mm", m->gap_mm},
                          {"semi_major_mm", m->outer.semi_major},
                          {"semi_minor_mm", m->outer.semi_minor},
                          {"axis_ratio", m->outer.axis_ratio()}};
      if (m->langer_angle_deg) j["langer_angle_deg"] = *m->langer_angle_deg;
      measured[i] = std::move(j);
    });
    for (nlohmann::json& j : measured)
      if (!j.is_null()) incisions.push_back(std::move(j));
    std::size_t scalpel = 0;
    for (const Cut& c : design.cuts) {
      if (c.kind != CutKind::scalpel || scalpel >= plan_.scalpel_paths.size()) continue;
      const WoundWidth w = scalpel_wound_width(preview_model_->volume, displacement_mm_, plan_.scalpel_paths[scalpel++]);
      wounds.push_back({{"cut", c.id}, {"width_mm", w.max_mm}, {"mean_width_mm", w.mean_mm}});
    }
    std::size_t flap = 0;
    for (const Cut& c : design.cuts) {
      if (c.kind != CutKind::flap || flap >= plan_.flaps.size()) continue;
      const FlapChange change = flap_change(preview_model_->volume, displacement_mm_, plan_.flaps[flap++]);
      flaps.push_back({{"cut", c.id},
                       {"skin_area_mm2", change.skin_area_before_mm2},
                       {"skin_area_change_percent", change.skin_area_change_percent},
                       {"volume_change_percent", change.volume_change_percent}});
    }
  }
  message["incisions"] = incisions;
  message["wounds"] = wounds;
  message["flaps"] = flaps;
  const auto [lo, hi] = model.bounding_box_mm();
  message["bounding_box_mm"] = {{lo.x(), lo.y(), lo.z()}, {hi.x(), hi.y(), hi.z()}};
  message["cell_size_mm"] = model.volume.grid().cell_size_mm;
  message["cells"] = model.volume.cell_count();
  timings["measurements"] = ms_since(t);
  timings["total"] = ms_since(t0);
  message["timings_ms"] = timings;
  // Nothing non-finite leaves the server: a NaN anywhere turns the result into an error naming
  // its stage, and the exports keep the last good result.
  message = checked_outgoing(std::move(message));
  if (message["type"] == "result") {
    ExportSnapshot snapshot{preview_model_, displacement_mm_, stress_kPa_, make_surface_mesh(surface, x)};
    std::lock_guard lock(latest_mutex_);
    latest_export_ = std::move(snapshot);
  }
  if (message["type"] == "result" && designer_ && designer_->result().provisional) {
    if (ctx.superseded()) return nullptr;  // as the worker drops a superseded result
    publish_result(std::move(message));   // the picture now; the design's last digits follow
    return complete_design(seq, ctx);
  }
  return message;
}

const std::vector<float>& StudioCompute::surface_residual() {
  if (divergence_.size() == 0) {
    SparseMatrix divergence = stress_divergence_matrix(session_.model().volume);
    divergence_.swap(divergence);
  }
  // An edit back to a recent design gives the same stress on the same surface: the same values.
  if (const std::vector<float>* known = surface_residuals_.find(stress_kPa_)) return *known;
  surface_residuals_.remember(stress_kPa_, residual_per_surface_vertex(session_.model().volume, divergence_, stress_kPa_,
                                                                       *preview_surface_, design_settings_.held_vertices));
  return *surface_residuals_.find(stress_kPa_);
}

nlohmann::json StudioCompute::complete_design(std::uint64_t seq, const FieldWorker::Context& ctx) {
  report(ctx.progress, "completing the equilibration", 0.95);
  if (ctx.superseded()) return nullptr;  // the next edit drops the provisional stress
  const auto t = Clock::now();
  try {
    designer_->finish_equilibration();
  } catch (const ComputeError& e) {
    designer_.reset();
    return {{"type", "error"},
            {"stage", "equilibration"},
            {"message", fmt::format("computation failed: {}; the picture shows the provisional stress", e.what())}};
  }
  const DesignResult& r = designer_->result();
  stress_kPa_ = r.stress_kPa;
  nlohmann::json fields = {{"residual_kPa", packed_floats(surface_residual())}};
  if (cut_face_layout_.any) fields["traction_kPa"] = packed_floats(cut_face_traction_kPa(cut_face_layout_, *preview_surface_, stress_kPa_));
  nlohmann::json message = {{"type", "design_final"},
                            {"generation", ctx.generation},
                            {"seq", seq},
                            {"equilibrium_residual", {{"designed", r.residual_designed}, {"final", r.residual_final}}},
                            {"equilibration_iterations", r.equilibration_iterations},
                            {"fields", std::move(fields)},
                            {"timings_ms", {{"equilibration_completion", ms_since(t)}}}};
  message = checked_outgoing(std::move(message));
  if (message["type"] != "design_final") return message;
  // What a client that connects later gets, and what the exports write: the final design.
  std::lock_guard lock(latest_mutex_);
  latest_export_.stress_kPa = stress_kPa_;
  if (latest_result_.value("generation", std::uint64_t{0}) == ctx.generation) {
    for (const auto& [key, value] : message["fields"].items()) latest_result_["fields"][key] = value;
    latest_result_["equilibrium_residual"] = message["equilibrium_residual"];
    latest_result_["timings_ms"]["equilibration_completion"] = message["timings_ms"]["equilibration_completion"];
  }
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
