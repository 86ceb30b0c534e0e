#include "cleave/fem/dynamics.hpp"

#include <algorithm>
#include <cmath>
#include <fmt/format.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "cleave/core/error.hpp"
#include "cleave/fem/corotation.hpp"
#include "cleave/fem/fixed_dofs.hpp"
#include "cleave/fem/lumped_mass.hpp"
#include "cleave/fem/solve_static.hpp"
#include "cleave/fem/stress_stiffness.hpp"
#include "cleave/fem/vertex_block_matrix.hpp"
#include "cleave/solve/multigrid_cg_solver.hpp"
#include "cleave/solve/parallel_ranges.hpp"

namespace cleave {
namespace {

/// The multigrid of a step with an iteration budget (DynamicsSettings::iterations_per_step): the
/// fine level smoothed by one damped block-Jacobi step on each side of the coarse correction
/// (Chebyshev degree 1 over [lambda_max / 4, lambda_max]: D^-1 / (0.625 lambda_max)); the coarse
/// levels as in every solve. On the 44k tube's budgeted steps a range of 8 left the motion 1.3
/// times further off the solved one than 4 (16: 7 times; 2: 1.5 times; 3: as 4).
/// After a cut the fine bound continues its power iteration for 2 products instead of 4 (it is
/// never lowered, and includes the 15 % safety factor; one damped Jacobi step amplifies only modes
/// above 1.25 times it): the 44k tube's step after each cut 38.0-39.3 -> 35.3-37.3 ms (harness,
/// alternating, 3 pairs). Over the accuracy harness's 14 cuts (DISABLED_BudgetAccuracy) the bounds
/// came out 2-3 % lower and the motion as close to the solved one (medians: tube 1.18e-2 against
/// 1.17e-2, abdomen 3.46e-2 against 3.44e-2).
MultigridOptions real_time_multigrid_options() {
  MultigridOptions options;
  options.smoother.degree = 1;
  options.smoother.smoothing_range = 4.0;
  options.smoother.warm_power_iterations = 2;
  return options;
}

}  // namespace

Dynamics::Dynamics(const TissueModel& model, std::vector<Vec6> residual_stress_kPa, DynamicsSettings settings)
    : model_(model), stress_kPa_(std::move(residual_stress_kPa)), settings_(std::move(settings)) {
  const LinkedVolume& volume = model_.volume;
  if (!stress_kPa_.empty() && stress_kPa_.size() != static_cast<std::size_t>(volume.cell_count()))
    throw InputError(fmt::format("residual stress holds {} cell tensors; expected one per cell ({})", stress_kPa_.size(),
                                 volume.cell_count()));
  if (!(settings_.mass_damping_per_s >= 0) || !(settings_.stiffness_damping_s >= 0))
    throw InputError(fmt::format("damping is alpha {} 1/s, beta {} s; expected non-negative numbers",
                                 settings_.mass_damping_per_s, settings_.stiffness_damping_s));
  if (!(settings_.numerical_damping >= 0 && settings_.numerical_damping <= 1.0 / 3.0))
    throw InputError(fmt::format("numerical damping is {}; expected a number from 0 to 1/3", settings_.numerical_damping));
  if (settings_.high_frequency_radius && !(*settings_.high_frequency_radius >= 0 && *settings_.high_frequency_radius <= 1))
    throw InputError(fmt::format("high-frequency spectral radius is {}; expected a number from 0 to 1 (generalized-alpha)",
                                 *settings_.high_frequency_radius));
  const auto dofs = 3 * static_cast<Eigen::Index>(volume.vertex_count());
  if (settings_.external_force_mN.size() != 0 && settings_.external_force_mN.size() != dofs)
    throw InputError(fmt::format("external force holds {} values; expected {} (3 per vertex)", settings_.external_force_mN.size(), dofs));
  table_ = make_element_table(model_);
  if (!(settings_.step_tolerance >= 0 && settings_.step_tolerance < 1))
    throw InputError(fmt::format("step tolerance is {}; expected a number from 0 to below 1", settings_.step_tolerance));
  if (settings_.iterations_per_step < 0)
    throw InputError(fmt::format("iterations per step is {}; expected 0 (solve every step to its tolerance) or a positive count",
                                 settings_.iterations_per_step));
  SolveSettings step_solve = settings_.solve;
  if (settings_.iterations_per_step > 0)
    step_solve.max_iterations = std::min(step_solve.max_iterations, settings_.iterations_per_step);
  step_solve.initial_residual_tolerance = settings_.step_tolerance;
  step_solve.zero_start_when_better = true;
  solver_ = settings_.solver == SolverKind::multigrid_cg && settings_.iterations_per_step > 0
                ? make_multigrid_cg_solver(step_solve, real_time_multigrid_options())
                : make_linear_solver(settings_.solver, step_solve);
  const FixedDofs held = fix_vertices(volume.vertex_count(), settings_.fixed_vertices);
  fixed_ = held.fixed;
  u_ = Vector::Zero(dofs);
  v_ = Vector::Zero(dofs);
  a_ = Vector::Zero(dofs);
  rebuild_topology();
  compute_acceleration();
}

Dynamics::~Dynamics() = default;

std::string_view Dynamics::solver_name() const { return solver_->name(); }

void Dynamics::rebuild_topology(const CutReport* cut) {
  mass_ = lumped_mass(model_, table_);
  if (cut != nullptr && system_blocks_.block_rows() > 0) {
    // After a cut only the rows of the vertices it touched are patterned afresh, and only when an
    // assembly needs them (steps with the operator do not): the touched rows of all cuts since.
    const std::vector<std::uint8_t> touched = vertices_affected_by_cut(model_.volume, *cut);
    rows_to_pattern_.resize(touched.size(), 0);
    for (std::size_t v = 0; v < touched.size(); ++v) rows_to_pattern_[v] |= touched[v];
    pattern_current_ = false;
    if (!settings_.matrix_free) ensure_pattern();
  } else {
    system_blocks_ = make_vertex_block_csr(model_.volume);
    rows_to_pattern_.clear();
    pattern_current_ = false;
    ensure_pattern();
  }
  any_fixed_ = std::any_of(fixed_.begin(), fixed_.end(), [](std::uint8_t f) { return f != 0; });
  every_cell_next_step_ = true;
  system_operator_.set_topology(model_.volume, table_);
  force_pass_.set_topology(model_.volume, table_);
  update_rotations();
}

void Dynamics::ensure_pattern() {
  if (pattern_current_) return;
  if (!rows_to_pattern_.empty()) repattern_vertex_block_csr(model_.volume, system_blocks_, rows_to_pattern_);
  rows_to_pattern_.clear();
  scalar_current_ = false;
  gather_ = make_vertex_block_gather(model_.volume, system_blocks_);
  diagonal_block_.assign(static_cast<std::size_t>(system_blocks_.block_rows()), 0);
  for (Eigen::Index v = 0; v < system_blocks_.block_rows(); ++v) {
    const auto begin = system_blocks_.column.begin() + system_blocks_.row_start[static_cast<std::size_t>(v)];
    const auto end = system_blocks_.column.begin() + system_blocks_.row_start[static_cast<std::size_t>(v) + 1];
    diagonal_block_[static_cast<std::size_t>(v)] =
        static_cast<std::int32_t>(std::lower_bound(begin, end, static_cast<std::int32_t>(v)) - system_blocks_.column.begin());
  }
  pattern_current_ = true;
}

void Dynamics::update_rotations() { cell_rotations(model_.volume, u_, rotations_); }

void Dynamics::topology_changed(const CutReport& report) {
  // Cut links without divided vertices leave K, M and the pattern as they are (cells still share
  // those vertices); the solver keeps its structure (the multigrid's levels, built with the old
  // links, stay a valid preconditioner and are rebuilt when iterations grow).
  if (report.splits.empty()) return;
  const LinkedVolume& volume = model_.volume;
  const auto dofs = 3 * static_cast<Eigen::Index>(volume.vertex_count());
  const Eigen::Index old = u_.size();
  u_.conservativeResize(dofs);
  v_.conservativeResize(dofs);
  a_.conservativeResize(dofs);
  fixed_.resize(static_cast<std::size_t>(dofs), 0);
  if (settings_.external_force_mN.size() != 0) {
    settings_.external_force_mN.conservativeResize(dofs);
    settings_.external_force_mN.tail(dofs - old).setZero();
  }
  note_vertex_origins(report);
  for (const VertexSplit& split : report.splits)
    for (const VertexId v : split.created) {
      u_.segment<3>(3 * v) = u_.segment<3>(3 * split.original);
      v_.segment<3>(3 * v) = v_.segment<3>(3 * split.original);
      a_.segment<3>(3 * v) = a_.segment<3>(3 * split.original);
      for (int i = 0; i < 3; ++i)
        fixed_[static_cast<std::size_t>(3 * v + i)] = fixed_[static_cast<std::size_t>(3 * split.original + i)];
    }
  rebuild_topology(&report);
  // Positions and velocities are continuous across a cut, forces are not: the cut faces lose
  // their tractions at once. Newmark needs the acceleration that satisfies the equation of
  // motion of the new topology; the old one (copied onto split vertices) would inject momentum
  // (a cell cut loose under 20 kPa left at 5 m/s instead of staying in place).
  compute_acceleration();
}

void Dynamics::note_vertex_origins(const CutReport& report) {
  const VertexId count = model_.volume.vertex_count();
  origin_of_new_.resize(static_cast<std::size_t>(std::max<VertexId>(count - solver_vertices_, 0)), kNone);
  for (const VertexSplit& split : report.splits)
    for (const VertexId v : split.created)
      if (v >= solver_vertices_ && v < count) origin_of_new_[static_cast<std::size_t>(v - solver_vertices_)] = split.original;
  // A copy of a copy (two cuts through one corner before a step) goes back to the first origin.
  for (VertexId& origin : origin_of_new_)
    for (int hops = 0; origin >= solver_vertices_ && hops < static_cast<int>(origin_of_new_.size()); ++hops)
      origin = origin_of_new_[static_cast<std::size_t>(origin - solver_vertices_)];
}

void Dynamics::set_state(const Vector& displacement_mm, const Vector& velocity_mm_per_s) {
  if (displacement_mm.size() != u_.size() || velocity_mm_per_s.size() != u_.size())
    throw InputError(fmt::format("state holds {} and {} values; expected {} (3 per vertex)", displacement_mm.size(),
                                 velocity_mm_per_s.size(), u_.size()));
  u_ = displacement_mm;
  v_ = velocity_mm_per_s;
  update_rotations();
  compute_acceleration();
}

std::vector<Vec3> Dynamics::displacement_mm() const {
  std::vector<Vec3> out(static_cast<std::size_t>(u_.size() / 3));
  for (std::size_t v = 0; v < out.size(); ++v) out[v] = u_.segment<3>(3 * static_cast<Eigen::Index>(v));
  return out;
}

Vector Dynamics::internal_forces(const Vector* velocity, const std::vector<CellRange>* cell_ranges) const {
  const LinkedVolume& volume = model_.volume;
  const double beta_k = velocity != nullptr ? settings_.stiffness_damping_s : 0.0;
  // Per cell its 24 corner forces by component (8 x, 8 y, 8 z), the layout of the operator's
  // corner slots; the buffer is kept across steps (8.8 MB at 45k cells: fresh pages each step
  // cost more than the pass). With stiffness damping, K_R v on the cell = R K^e R^T v_e shares
  // K^e and R with the elastic force: the pass takes u + beta_k v.
  const Vector* x = &u_;
  if (beta_k > 0) {
    damped_displacement_.resize(u_.size());
    for_each_range(u_.size(), [&](Eigen::Index begin, Eigen::Index end) {
      for (Eigen::Index i = begin; i < end; ++i) damped_displacement_[i] = u_[i] + beta_k * (*velocity)[i];
    });
    x = &damped_displacement_;
  }
  if (cell_ranges != nullptr && force_per_cell_.size() == 24 * static_cast<std::size_t>(volume.cell_count()))
    force_pass_.per_cell(rotations_, stress_kPa_, *x, *cell_ranges, force_per_cell_);
  else
    force_pass_.per_cell(rotations_, stress_kPa_, *x, force_per_cell_);
  // Summed per vertex over its corners (in parallel, without write conflicts).
  const VertexCornerSlots& slots = system_operator_.corner_slots();
  Vector f(u_.size());
  tbb::parallel_for(tbb::blocked_range<VertexId>(0, volume.vertex_count()), [&](const tbb::blocked_range<VertexId>& r) {
    for (VertexId v = r.begin(); v != r.end(); ++v) {
      const auto vi = static_cast<std::size_t>(v);
      Vec3 sum = Vec3::Zero();
      for (std::int32_t s = slots.start[vi]; s < slots.start[vi + 1]; ++s) {
        const double* slot = force_per_cell_.data() + slots.slot[static_cast<std::size_t>(s)];
        sum += Vec3(slot[0], slot[8], slot[16]);
      }
      f.segment<3>(3 * v) = sum;
    }
  });
  return f;
}

Vector Dynamics::external_forces() const {
  Vector f = Vector::Zero(u_.size());
  if (settings_.external_force_mN.size() != 0) f += settings_.external_force_mN;
  if (!settings_.gravity_mm_per_s2.isZero())
    for (Eigen::Index i = 0; i < f.size(); ++i) f[i] += mass_[i] * settings_.gravity_mm_per_s2[i % 3];
  return f;
}

void Dynamics::assemble_system(double c_stiff, double c_stress, double c_mass) {
  const LinkedVolume& volume = model_.volume;
  volume.vertex_cells();
  const bool with_tension = !tension_kPa_.empty();
  const auto block = [&](CellId c, int a, int b) -> Mat3 {
    const auto ci = static_cast<std::size_t>(c);
    const Mat3& r = rotations_[ci];
    Mat3 m = (c_stiff * r) * table_.of_label(volume.cell_label(c)).stiffness.block<3, 3>(3 * a, 3 * b) * r.transpose();
    // R (s I) R^T = s I: the initial-stress stiffness is the same in the rotated frame.
    if (with_tension) m.diagonal().array() += c_stress * stress_stiffness_coefficient(table_, tension_kPa_[ci], a, b);
    return m;
  };
  double* values = system_blocks_.values.data();
  tbb::parallel_for(tbb::blocked_range<VertexId>(0, volume.vertex_count()), [&](const tbb::blocked_range<VertexId>& r) {
    for (VertexId v = r.begin(); v != r.end(); ++v) {
      gather_vertex_block_row(volume, v, gather_, block, system_blocks_);
      double* diagonal = values + 9 * static_cast<std::size_t>(diagonal_block_[static_cast<std::size_t>(v)]);
      for (int i = 0; i < 3; ++i) diagonal[4 * i] += c_mass * mass_[3 * static_cast<Eigen::Index>(v) + i];
    }
  });
}

void Dynamics::hand_system_to_solver(double c_mass) {
  // Same pattern and mass term: the solver keeps its structure. A changed time step changes the
  // mass term c_m M, which stale multigrid levels would miss (many more iterations): set up.
  // After a cut, the multigrid keeps its coarse levels (exactly Galerkin for the new matrix:
  // LinearSolver::update_topology) unless a divided vertex's origin is unknown.
  const VertexId vertices = model_.volume.vertex_count();
  const bool keep = solver_ready_ && solver_mass_factor_ == c_mass && origins_known();
  const bool taken_as_blocks = keep && origin_of_new_.empty() && solver_->update_block_values(system_blocks_, model_.volume);
  bool set_up_with_operator = false;
  if (!taken_as_blocks && settings_.matrix_free)  // step() set the operator's state
    set_up_with_operator = solver_->setup_operator(system_operator_, system_blocks_, model_.volume);
  if (set_up_with_operator) {
    solver_ready_ = true;
    solver_mass_factor_ = c_mass;
    ++matrix_free_steps_;
  } else if (!taken_as_blocks) {
    if (scalar_current_) {
      copy_block_values(system_blocks_, system_);
    } else {
      SparseMatrix scalar = to_scalar_sparse(system_blocks_);
      system_.swap(scalar);  // Eigen 3.4's SparseMatrix has no move: assigning the temporary would copy it
      scalar_current_ = true;
    }
    if (keep && origin_of_new_.empty()) {
      solver_->update_values(system_, model_.volume);
    } else if (keep) {
      solver_->update_topology_with_blocks(system_, system_blocks_, model_.volume, origin_of_new_);
    } else {
      solver_->setup(system_, model_.volume);
      solver_ready_ = true;
      solver_mass_factor_ = c_mass;
    }
  }
  solver_vertices_ = vertices;
  origin_of_new_.clear();
}

bool Dynamics::origins_known() const {
  const VertexId vertices = model_.volume.vertex_count();
  return std::none_of(origin_of_new_.begin(), origin_of_new_.end(), [&](VertexId o) { return o < 0 || o >= solver_vertices_; }) &&
         static_cast<VertexId>(origin_of_new_.size()) == vertices - solver_vertices_;
}

bool Dynamics::hand_operator_to_solver(double c_mass) {
  if (!solver_ready_ || solver_mass_factor_ != c_mass) return false;
  const VertexId vertices = model_.volume.vertex_count();
  const bool cut_since = vertices != solver_vertices_ || !origin_of_new_.empty();
  if (cut_since && !origins_known()) return false;
  const bool taken = cut_since ? solver_->update_topology_operator(system_operator_, model_.volume, origin_of_new_)
                               : solver_->update_operator(system_operator_, model_.volume);
  if (!taken) return false;
  solver_vertices_ = vertices;
  origin_of_new_.clear();
  ++matrix_free_steps_;
  return true;
}

void Dynamics::compute_acceleration() {
  Vector net = external_forces() - internal_forces(&v_);
  if (settings_.mass_damping_per_s > 0) net -= settings_.mass_damping_per_s * mass_.cwiseProduct(v_);
  a_ = net.cwiseQuotient(mass_);
  for (std::size_t i = 0; i < fixed_.size(); ++i)
    if (fixed_[i] != 0) a_[static_cast<Eigen::Index>(i)] = 0.0;
}

double Dynamics::kinetic_energy_uJ() const { return 0.5 * v_.dot(mass_.cwiseProduct(v_)); }

double Dynamics::elastic_energy_uJ() const {
  const LinkedVolume& volume = model_.volume;
  std::vector<Mat3> rotations;
  cell_rotations(volume, u_, rotations);
  double energy = 0;
  for (CellId c = 0; c < volume.cell_count(); ++c) {
    const auto ci = static_cast<std::size_t>(c);
    const Vec24 d = corotated_displacement(cell_displacement(volume, c, u_), rotations[ci], table_.cell_size_mm);
    energy += 0.5 * d.dot(table_.of_label(volume.cell_label(c)).stiffness * d);
    if (!stress_kPa_.empty()) energy += d.dot(table_.stress_divergence * stress_kPa_[ci]);
  }
  return energy;
}

SolveReport Dynamics::step(double dt) {
  if (!(dt > 0) || !std::isfinite(dt)) throw InputError(fmt::format("time step is {} s; expected a positive time step in s", dt));
  // The inertia at n + 1 - alpha_inertia, the damping and elastic forces at n + 1 - alpha_forces:
  // HHT (alpha_inertia = 0, alpha_forces = numerical_damping) or generalized-alpha with the
  // high-frequency radius r (Chung & Hulbert 1993).
  double alpha_inertia = 0.0;
  double alpha_forces = settings_.numerical_damping;
  if (settings_.high_frequency_radius) {
    const double r = *settings_.high_frequency_radius;
    alpha_inertia = (2.0 * r - 1.0) / (r + 1.0);
    alpha_forces = r / (r + 1.0);
  }
  const double gamma = kNewmarkGamma - alpha_inertia + alpha_forces;
  const double beta = 0.25 * (1.0 - alpha_inertia + alpha_forces) * (1.0 - alpha_inertia + alpha_forces);
  const double alpha_m = settings_.mass_damping_per_s;
  const double beta_k = settings_.stiffness_damping_s;

  // A stress-free body keeps the classic corotational step: its stresses come from its own
  // deformation, and the tensile part alone would make bending oscillations drift in energy
  // (5.9 % over 1000 undamped steps of the cantilever instead of < 1 %).
  // Cells held at every corner (the operator's list, the same fixed flags and topology as its
  // last state) keep their rotation, tension and forces: only held dofs' rows read them.
  const auto cells = static_cast<std::size_t>(model_.volume.cell_count());
  const std::vector<CellRange>* computed =
      settings_.matrix_free && !every_cell_next_step_ && rotations_.size() == cells && tension_kPa_.size() == cells
          ? &system_operator_.computed_cell_ranges()
          : nullptr;
  if (settings_.stress_stiffness && !stress_kPa_.empty()) {
    if (computed != nullptr)
      cell_rotations_and_tension(model_.volume, table_, stress_kPa_, u_, *computed, rotations_, tension_kPa_);
    else
      cell_rotations_and_tension(model_.volume, table_, stress_kPa_, u_, rotations_, tension_kPa_);
  } else {
    computed = nullptr;
    update_rotations();
  }
  cells_in_last_step_ = computed != nullptr ? system_operator_.computed_cells() : cells;
  // M [(1 - alpha_inertia) a(n+1) + alpha_inertia a(n)] + w [D v(n+1) + f_int(n+1)]
  //   + (1 - w) [D v(n) + f_int(n)] = f_ext, w = 1 - alpha_forces,
  // with f_int(n+1) ~ f_int(n) + (K_R + K_sigma) du (R frozen over the step; K_sigma: how the
  // stress forces turn with the cells) and v(n+1) = gamma du / (beta dt) + damping_part.
  const double w = 1.0 - alpha_forces;
  const double c_mass = (1.0 - alpha_inertia) / (beta * dt * dt) + w * alpha_m * gamma / (beta * dt);
  const double c_stiff = w * (1.0 + beta_k * gamma / (beta * dt));

  // Velocity-like combinations of the old state that enter the increment equation: the damped
  // velocity w damping_part + (1 - w) v (damping_part = (1 - gamma / beta) v + dt (1 - gamma /
  // (2 beta)) a), and the inertia part v / (beta dt) + (1 / (2 beta) - 1) a; entry by entry, in
  // parallel passes (156k dofs at 44k cells: a serial Eigen expression per vector cost 1-2 ms).
  const Eigen::Index dofs = u_.size();
  Vector damped_velocity(dofs);
  for_each_range(dofs, [&](Eigen::Index begin, Eigen::Index end) {
    for (Eigen::Index i = begin; i < end; ++i) {
      const double damping_part = (1.0 - gamma / beta) * v_[i] + dt * (1.0 - 0.5 * gamma / beta) * a_[i];
      damped_velocity[i] = w * damping_part + (1.0 - w) * v_[i];
    }
  });
  // f_int + beta_k K_R v_damped in one pass over the cells.
  Vector rhs = internal_forces(&damped_velocity, computed);
  // rhs = f_ext - f_int + M inertia - alpha_m M v_damped; the Newmark predictor du, or no
  // increment where that is closer (the solver's zero_start_when_better). Fixed dofs are held at
  // zero: their rows are identity rows with a zero right-hand side.
  Vector du(dofs);
  const bool external = settings_.external_force_mN.size() != 0;
  const bool gravity = !settings_.gravity_mm_per_s2.isZero();
  for_each_range(dofs, [&](Eigen::Index begin, Eigen::Index end) {
    for (Eigen::Index i = begin; i < end; ++i) {
      if (fixed_[static_cast<std::size_t>(i)] != 0) {
        rhs[i] = 0.0;
        du[i] = 0.0;
        continue;
      }
      // M [(1 - alpha_inertia) a(n+1) + alpha_inertia a(n)], a(n+1) = du / (beta dt^2) - inertia_part.
      const double inertia_part = v_[i] / (beta * dt) + (0.5 / beta - 1.0) * a_[i];
      const double inertia = (1.0 - alpha_inertia) * inertia_part - alpha_inertia * a_[i];
      double value = mass_[i] * (inertia - alpha_m * damped_velocity[i]) - rhs[i];
      if (external) value += settings_.external_force_mN[i];
      if (gravity) value += mass_[i] * settings_.gravity_mm_per_s2[i % 3];
      rhs[i] = value;
      du[i] = dt * v_[i] + 0.5 * dt * dt * a_[i];
    }
  });
  SolveReport report;
  if (rhs.lpNorm<Eigen::Infinity>() == 0.0) {
    du.setZero();
    report.converged = true;
  } else {
    // The system applied cell by cell: its state once per step, for the operator's update or a
    // rebuild from the assembled blocks alike.
    if (settings_.matrix_free) {
      system_operator_.set_state(rotations_, tension_kPa_, c_stiff, w, c_mass, mass_, fixed_);
      every_cell_next_step_ = false;
    }
    if (!(settings_.matrix_free && hand_operator_to_solver(c_mass))) {
      ensure_pattern();
      assemble_system(c_stiff, w, c_mass);
      if (any_fixed_) {
        FixedDofs held;
        held.fixed = fixed_;
        held.value_mm = Vector::Zero(u_.size());
        eliminate_fixed_dofs(system_blocks_, rhs, held);
      }
      hand_system_to_solver(c_mass);
    }
    report = solver_->solve(rhs, du);
    const bool within_budget = settings_.iterations_per_step > 0 && report.iterations >= settings_.iterations_per_step &&
                               std::isfinite(report.relative_residual);
    if (!within_budget) require_converged(report, solver_->name(), settings_.solve, fmt::format("dynamic step at t = {:.6g} s", time_s_));
  }
  if (!du.allFinite()) throw ComputeError(fmt::format("dynamic step with {} produced a non-finite displacement", solver_->name()));
  const double size_mm = model_.volume.grid().cell_size_mm * model_.volume.grid().dims.cast<double>().norm();
  const double largest_mm = (u_ + du).lpNorm<Eigen::Infinity>();
  if (largest_mm > kDivergedSizes * size_mm)
    throw ComputeError(fmt::format("dynamic step at t = {:.6g} s diverged: a vertex moved {:.3g} mm, more than {:g} times the "
                                   "model's size ({:.3g} mm); add damping (simulation.damping) or use a smaller time step",
                                   time_s_, largest_mm, kDivergedSizes, size_mm));

  for_each_range(dofs, [&](Eigen::Index begin, Eigen::Index end) {
    for (Eigen::Index i = begin; i < end; ++i) {
      u_[i] += du[i];
      if (fixed_[static_cast<std::size_t>(i)] != 0) {
        v_[i] = 0.0;
        a_[i] = 0.0;
        continue;
      }
      const double a_new = du[i] / (beta * dt * dt) - v_[i] / (beta * dt) - (0.5 / beta - 1.0) * a_[i];
      v_[i] += dt * ((1.0 - gamma) * a_[i] + gamma * a_new);
      a_[i] = a_new;
    }
  });
  time_s_ += dt;
  return report;
}

}  // namespace cleave
