#include "cleave/stress/stress_designer.hpp"

#include <chrono>
#include <cmath>
#include <fmt/format.h>

#include "cleave/core/error.hpp"
#include "cleave/stress/control_point_targets.hpp"
#include "cleave/stress/eigenvalue_interpolation.hpp"
#include "cleave/stress/equilibrate_stress.hpp"
#include "cleave/stress/equilibrium_operator.hpp"
#include "cleave/stress/line_field_interpolation.hpp"
#include "cleave/stress/stress_from_frames.hpp"
#include "cleave/stress/stroke_constraints.hpp"

namespace cleave {
namespace {

double seconds_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

void check_weights(const DesignWeights& w) {
  const auto check = [](double value, const char* name, bool positive) {
    if (!std::isfinite(value) || value < 0.0 || (positive && value == 0.0))
      throw InputError(fmt::format("design weight '{}' is {}; expected a finite number {}", name, value,
                                   positive ? "> 0" : ">= 0"));
  };
  check(w.laplacian, "laplacian", true);
  check(w.constraint, "constraint", true);
  check(w.equilibrium, "equilibrium", false);
}

bool same_control_points(const std::vector<DesignControlPoint>& a, const std::vector<DesignControlPoint>& b) {
  if (a.size() != b.size()) return false;
  for (std::size_t i = 0; i < a.size(); ++i)
    if (a[i].position_mm != b[i].position_mm || a[i].langer_kPa != b[i].langer_kPa || a[i].cross_kPa != b[i].cross_kPa)
      return false;
  return true;
}

}  // namespace

bool same_strokes(const std::vector<DesignStroke>& a, const std::vector<DesignStroke>& b) {
  if (a.size() != b.size()) return false;
  for (std::size_t i = 0; i < a.size(); ++i)
    if (a[i].placement != b[i].placement || a[i].points_mm != b[i].points_mm) return false;
  return true;
}

struct StressDesigner::Operators {
  Operators(const TissueModel& model, const DesignWeights& weights, const std::vector<VertexId>& held)
      : langer(model.volume, weights),
        eigenvalues(model.volume, weights, held),
        divergence(stress_divergence_matrix(model.volume)),
        held_vertices(held) {
    drop_held_vertex_rows(divergence, held);
    norm = equilibrium_norm(divergence);
    LineFieldInterpolator normal_interp(model.volume, weights);
    normals = normal_axes(normal_interp.interpolate(surface_normal_targets(model)));
  }
  LineFieldInterpolator langer;
  EigenvalueInterpolator eigenvalues;
  SparseMatrix divergence;  ///< T, rows of held vertices dropped
  EquilibriumNorm norm;
  std::vector<VertexId> held_vertices;
  std::vector<Vec3> normals;  ///< normal_axes of the interpolated normal field: the frames' normals never change
  std::unique_ptr<StressEquilibrator> equilibrator;  ///< built at the first equilibration (Kc factor)
};

StressDesigner::StressDesigner(const TissueModel& model, StressDesign design) : model_(model) {
  check_weights(design.weights);
  if (!std::isfinite(design.snap_tolerance_cells) || design.snap_tolerance_cells <= 0.0)
    throw InputError(fmt::format("design snap tolerance is {} cells; expected a positive number", design.snap_tolerance_cells));
  // Validate the inputs before building operators, so that a bad design fails fast.
  const double tolerance_mm = design.snap_tolerance_cells * model.volume.grid().cell_size_mm;
  stroke_line_targets(model, design.strokes, tolerance_mm);
  control_point_targets(model, design.control_points, tolerance_mm);
  ops_ = std::make_unique<Operators>(model, design.weights, design.held_vertices);
  DesignResult next;
  update_directions(design, next);
  update_eigenvalues(design, next);
  finish(design, next, EquilibrationPass::complete);
  result_ = std::move(next);
  design_ = std::move(design);
  recent_.remember(key_of(design_), result_);
}

StressDesigner::~StressDesigner() = default;

bool StressDesigner::DesignKey::operator==(const DesignKey& other) const {
  return same_strokes(strokes, other.strokes) && same_control_points(control_points, other.control_points) &&
         solver == other.solver && equilibration == other.equilibration;
}

StressDesigner::DesignKey StressDesigner::key_of(const StressDesign& design) {
  return {design.strokes, design.control_points, design.solver, design.equilibration};
}

void StressDesigner::update_directions(const StressDesign& design, DesignResult& out) {
  const auto start = std::chrono::steady_clock::now();
  const double tolerance_mm = design.snap_tolerance_cells * model_.volume.grid().cell_size_mm;
  const std::vector<LineTarget> targets = stroke_line_targets(model_, design.strokes, tolerance_mm);
  const std::vector<Mat3> langer = ops_->langer.interpolate(targets);
  out.frames = direction_frames(langer, ops_->normals);
  out.timings.directions_s = seconds_since(start);
}

void StressDesigner::update_eigenvalues(const StressDesign& design, DesignResult& out) {
  const auto start = std::chrono::steady_clock::now();
  const double tolerance_mm = design.snap_tolerance_cells * model_.volume.grid().cell_size_mm;
  const std::vector<EigenvalueTarget> targets = control_point_targets(model_, design.control_points, tolerance_mm);
  EigenvalueSolution s = ops_->eigenvalues.solve(out.frames, targets, design.solver, out.eigenvalues_kPa);
  out.eigenvalues_kPa = std::move(s.eigenvalues_kPa);
  out.eigenvalue_iterations = s.iterations;
  out.timings.eigenvalues_s = seconds_since(start);
}

void StressDesigner::take_equilibration(EquilibrationResult balanced, DesignResult& out) const {
  out.stress_kPa = std::move(balanced.stress_kPa);
  out.equilibration_iterations = balanced.refinement_steps;
  out.provisional = balanced.provisional;
  // The equilibration measured T sigma_d and T sigma at the free vertices (the rows the
  // designer's T keeps): no product with T for the two residuals.
  out.residual_designed = relative_equilibrium_residual(balanced.designed_force_mN, ops_->norm, out.designed_kPa);
  out.residual_final = relative_equilibrium_residual(balanced.remaining_force_mN, ops_->norm, out.stress_kPa);
}

void StressDesigner::finish(const StressDesign& design, DesignResult& out, EquilibrationPass pass) {
  out.designed_kPa = stress_from_frames(out.frames, out.eigenvalues_kPa);
  out.provisional = false;
  const auto start = std::chrono::steady_clock::now();
  if (design.equilibration == Equilibration::growth) {
    if (!ops_->equilibrator) ops_->equilibrator = std::make_unique<StressEquilibrator>(model_, ops_->held_vertices);
    take_equilibration(ops_->equilibrator->equilibrate(out.designed_kPa, pass), out);
    out.timings.equilibration_s = seconds_since(start);
    return;
  }
  out.stress_kPa = out.designed_kPa;
  out.equilibration_iterations = 0;
  out.timings.equilibration_s = 0;
  out.residual_designed = relative_equilibrium_residual(ops_->divergence, ops_->norm, out.designed_kPa);
  out.residual_final = out.residual_designed;
}

void StressDesigner::finish_equilibration() {
  if (!result_.provisional) return;
  const auto start = std::chrono::steady_clock::now();
  EquilibrationResult balanced;
  try {
    // The equilibrator dropped its pending solve when an edit after this one failed in its own
    // equilibration: then this design is equilibrated anew.
    StressEquilibrator& equilibrator = *ops_->equilibrator;
    balanced = equilibrator.has_provisional() ? equilibrator.finish() : equilibrator.equilibrate(result_.designed_kPa);
  } catch (const ComputeError&) {
    design_ = std::move(before_provisional_->design);
    result_ = std::move(before_provisional_->result);
    before_provisional_.reset();
    throw;
  }
  take_equilibration(std::move(balanced), result_);
  result_.timings.equilibration_s += seconds_since(start);
  before_provisional_.reset();
  recent_.remember(key_of(design_), result_);
}

void StressDesigner::set_design(StressDesign design, EquilibrationPass pass) {
  const DesignWeights& a = design.weights;
  const DesignWeights& b = design_.weights;
  if (a.laplacian != b.laplacian || a.constraint != b.constraint || a.equilibrium != b.equilibrium ||
      design.snap_tolerance_cells != design_.snap_tolerance_cells || design.held_vertices != design_.held_vertices)
    throw InputError("design weights, snap tolerance or held vertices changed; expected the same (build a new StressDesigner)");
  // renew: the recalled design becomes the newest again, so the last two are it and the next edit's.
  if (const DesignResult* known = recent_.renew(key_of(design))) {
    before_provisional_.reset();
    result_ = *known;
    result_.remembered = true;
    result_.timings = {};
    result_.eigenvalue_iterations = 0;
    result_.equilibration_iterations = 0;
    design_ = std::move(design);
    return;
  }
  // Work on a copy: a failing edit leaves the designer as it was.
  DesignResult next = result_;
  next.timings = {};
  next.remembered = false;
  const bool strokes_changed = !same_strokes(design.strokes, design_.strokes);
  if (strokes_changed) update_directions(design, next);
  // The eigenvalues depend on the frames only through the equilibrium rows (w_E > 0).
  const bool frames_matter = design.weights.equilibrium > 0.0;
  if (!same_control_points(design.control_points, design_.control_points) || design.solver != design_.solver ||
      (strokes_changed && frames_matter)) {
    update_eigenvalues(design, next);
  } else {
    next.eigenvalue_iterations = 0;
  }
  finish(design, next, pass);
  if (next.provisional) {
    // An edit after a provisional one keeps the first's "before": the last complete design.
    if (!before_provisional_) before_provisional_ = std::make_unique<Before>(Before{std::move(design_), std::move(result_)});
    result_ = std::move(next);
    design_ = std::move(design);
    return;
  }
  before_provisional_.reset();
  result_ = std::move(next);
  design_ = std::move(design);
  recent_.remember(key_of(design_), result_);
}

void StressDesigner::add_stroke(DesignStroke stroke) {
  StressDesign d = design_;
  d.strokes.push_back(std::move(stroke));
  set_design(std::move(d));
}

void StressDesigner::move_stroke(std::size_t index, DesignStroke stroke) {
  if (index >= design_.strokes.size())
    throw InputError(fmt::format("stroke {} does not exist; expected an index below {}", index, design_.strokes.size()));
  StressDesign d = design_;
  d.strokes[index] = std::move(stroke);
  set_design(std::move(d));
}

void StressDesigner::delete_stroke(std::size_t index) {
  if (index >= design_.strokes.size())
    throw InputError(fmt::format("stroke {} does not exist; expected an index below {}", index, design_.strokes.size()));
  StressDesign d = design_;
  d.strokes.erase(d.strokes.begin() + static_cast<std::ptrdiff_t>(index));
  set_design(std::move(d));
}

void StressDesigner::add_control_point(DesignControlPoint point) {
  StressDesign d = design_;
  d.control_points.push_back(point);
  set_design(std::move(d));
}

void StressDesigner::move_control_point(std::size_t index, DesignControlPoint point) {
  if (index >= design_.control_points.size())
    throw InputError(fmt::format("control point {} does not exist; expected an index below {}", index,
                                 design_.control_points.size()));
  StressDesign d = design_;
  d.control_points[index] = point;
  set_design(std::move(d));
}

void StressDesigner::delete_control_point(std::size_t index) {
  if (index >= design_.control_points.size())
    throw InputError(fmt::format("control point {} does not exist; expected an index below {}", index,
                                 design_.control_points.size()));
  StressDesign d = design_;
  d.control_points.erase(d.control_points.begin() + static_cast<std::ptrdiff_t>(index));
  set_design(std::move(d));
}

DesignResult design_residual_stress(const TissueModel& model, const StressDesign& design) {
  return StressDesigner(model, design).result();
}

}  // namespace cleave
