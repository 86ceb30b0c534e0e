// GCC 12 reports -Wnull-dereference inside Eigen (sparse products, vector dot products) after
// inlining: a false positive for possibly-empty vectors. Silenced for this file's headers.
#pragma GCC diagnostic ignored "-Wnull-dereference"
#include "cleave/stress/equilibrate_stress.hpp"

#include <cmath>
#include <fmt/format.h>

#include "cleave/core/error.hpp"
#include "cleave/fem/element_table.hpp"
#include "cleave/fem/hex8_element.hpp"
#include "cleave/fem/residual_stress_forces.hpp"
#include "cleave/stress/sparse_cholesky.hpp"

namespace cleave {
namespace {

/// eps of Kc + eps I, relative to mean diag(Kc). Small enough that only modes softer than this
/// are left to CG (thin-shell bending is ~1e-6), large enough that the factor stays accurate.
/// Measured on the bench's edits (iterations per equilibration): 1e-8 took 3-4 on the 44k tube and
/// 7-18 on the abdomen (5.7k and 45.8k cells); 1e-10 takes 2 and 3-5 (one first design of the
/// 5.7k abdomen 15); 1e-11 and 1e-12 are erratic (up to 18: the factor loses too many digits).
/// The price: the free abdomen's final residual ||T sigma|| / (||T|| ||sigma||) is 2e-12 instead
/// of below 1e-12 (tests/stress/equilibration_test.cpp).
constexpr double kShiftOfMeanDiagonal = 1e-10;
constexpr double kTargetReduction = 1e-12;    ///< stop when ||T sigma|| <= this * ||T sigma_d||
constexpr double kRequiredReduction = 1e-10;  ///< ComputeError above this at the end
constexpr int kMaxIterations = 200;

}  // namespace

struct StressEquilibrator::Impl {
  const TissueModel& model;
  Mat6x24 bc;
  ElementTable table;
  Eigen::SparseMatrix<double> kc;
  SparseCholesky cholesky;
  bool factorized = false;
  Vector u;  ///< displacement of the last solve (warm start)
  std::vector<std::uint8_t> held_dof;  ///< per dof: 1 = vertex held (Gamma_D)

  Impl(const TissueModel& m, std::span<const VertexId> held_vertices)
      : model(m), bc(hex8_strain_matrix(Vec3::Constant(0.5), m.volume.grid().cell_size_mm)), table(make_element_table(m)) {
    held_dof.assign(3 * static_cast<std::size_t>(m.volume.vertex_count()), 0);
    for (const VertexId v : held_vertices) {
      if (v < 0 || v >= m.volume.vertex_count())
        throw InputError(fmt::format("held vertex {} does not exist; expected 0 to {}", v, m.volume.vertex_count() - 1));
      for (int i = 0; i < 3; ++i) held_dof[3 * static_cast<std::size_t>(v) + static_cast<std::size_t>(i)] = 1;
    }
  }

  /// Zeroes the entries of held dofs (their forces are reactions).
  void mask(Vector& forces) const {
    for (Eigen::Index d = 0; d < forces.size(); ++d)
      if (held_dof[static_cast<std::size_t>(d)]) forces[d] = 0.0;
  }

  void factorize() {
    const LinkedVolume& volume = model.volume;
    const double h = volume.grid().cell_size_mm;
    std::vector<Mat24> kc_per_material;
    for (const ElementMatrices& m : table.per_material) kc_per_material.push_back(h * h * h * bc.transpose() * m.elasticity_kPa * bc);
    const Eigen::Index dofs = 3 * static_cast<Eigen::Index>(volume.vertex_count());
    std::vector<Eigen::Triplet<double>> entries;
    entries.reserve(static_cast<std::size_t>(volume.cell_count()) * 24 * 24);
    for (CellId c = 0; c < volume.cell_count(); ++c) {
      const Mat24& ke = kc_per_material[static_cast<std::size_t>(table.slot_of_label[volume.cell_label(c)])];
      const auto& corners = volume.cell_vertices(c);
      for (int a = 0; a < kCornerCount; ++a)
        for (int b = 0; b < kCornerCount; ++b)
          for (int i = 0; i < 3; ++i)
            for (int j = 0; j < 3; ++j)
              entries.emplace_back(3 * corners[static_cast<std::size_t>(a)] + i, 3 * corners[static_cast<std::size_t>(b)] + j,
                                   ke(3 * a + i, 3 * b + j));
    }
    // Held dofs: identity rows and columns (u = 0 there).
    std::erase_if(entries, [&](const Eigen::Triplet<double>& e) {
      return held_dof[static_cast<std::size_t>(e.row())] || held_dof[static_cast<std::size_t>(e.col())];
    });
    for (Eigen::Index d = 0; d < dofs; ++d)
      if (held_dof[static_cast<std::size_t>(d)]) entries.emplace_back(d, d, 1.0);
    kc.resize(dofs, dofs);
    kc.setFromTriplets(entries.begin(), entries.end());
    kc.makeCompressed();
    const double shift = kShiftOfMeanDiagonal * kc.diagonal().mean();
    Eigen::SparseMatrix<double> shifted = kc;
    shifted.diagonal().array() += shift;  // every diagonal entry exists (each vertex has a cell)
    cholesky.factorize(shifted);
    u = Vector::Zero(dofs);
    factorized = true;
  }

  /// Kc u = b by CG preconditioned with (Kc + eps I)^-1 from the current u; keeps the best iterate.
  int solve(const Vector& b) {
    const double b_norm = b.norm();
    Vector r = b - kc * u;
    Vector best = u;
    double best_norm = r.norm();
    int iterations = 0;
    if (best_norm <= kTargetReduction * b_norm) return 0;
    Vector z = cholesky.solve(r);
    Vector p = z;
    double rz = r.dot(z);
    while (iterations < kMaxIterations) {
      const Vector kp = kc * p;
      const double curvature = p.dot(kp);
      if (!(curvature > 0.0) || !(rz > 0.0)) break;
      const double alpha = rz / curvature;
      u += alpha * p;
      r -= alpha * kp;
      ++iterations;
      const double r_norm = r.norm();
      if (r_norm < best_norm) {
        best_norm = r_norm;
        best = u;
      }
      if (r_norm <= kTargetReduction * b_norm) break;
      z = cholesky.solve(r);
      const double rz_next = r.dot(z);
      p = z + (rz_next / rz) * p;
      rz = rz_next;
    }
    u = best;
    return iterations;
  }
};

StressEquilibrator::StressEquilibrator(const TissueModel& model, std::span<const VertexId> held_vertices)
    : impl_(std::make_unique<Impl>(model, held_vertices)) {}
StressEquilibrator::~StressEquilibrator() = default;
StressEquilibrator::StressEquilibrator(StressEquilibrator&&) noexcept = default;
StressEquilibrator& StressEquilibrator::operator=(StressEquilibrator&&) noexcept = default;

EquilibrationResult StressEquilibrator::equilibrate(std::span<const Vec6> designed_kPa) {
  const LinkedVolume& volume = impl_->model.volume;
  if (designed_kPa.size() != static_cast<std::size_t>(volume.cell_count()))
    throw InputError(fmt::format("designed stress holds {} cell tensors; expected one per cell ({})", designed_kPa.size(),
                                 volume.cell_count()));
  for (std::size_t c = 0; c < designed_kPa.size(); ++c)
    if (!designed_kPa[c].allFinite()) throw InputError(fmt::format("designed stress of cell {} is not finite", c));

  EquilibrationResult result;
  result.stress_kPa.assign(designed_kPa.begin(), designed_kPa.end());
  Vector load = residual_stress_forces(volume, designed_kPa);
  impl_->mask(load);
  const double load_norm = load.norm();
  if (load_norm == 0.0) return result;
  if (!std::isfinite(load_norm))
    throw ComputeError(fmt::format("stress equilibration: the forces T sigma_d of the designed stress are not finite "
                                   "(norm {}); expected stresses of finite magnitude in kPa",
                                   load_norm));
  if (!impl_->factorized) impl_->factorize();
  result.refinement_steps = impl_->solve(-load);

  const Vector& u = impl_->u;
  for (CellId c = 0; c < volume.cell_count(); ++c) {
    Vec24 ue;
    const auto& corners = volume.cell_vertices(c);
    for (int a = 0; a < kCornerCount; ++a) ue.segment<3>(3 * a) = u.segment<3>(3 * corners[static_cast<std::size_t>(a)]);
    const Mat6& d = impl_->table.of_label(volume.cell_label(c)).elasticity_kPa;
    result.stress_kPa[static_cast<std::size_t>(c)] += d * (impl_->bc * ue);
    if (!result.stress_kPa[static_cast<std::size_t>(c)].allFinite()) {
      impl_->u.setZero();  // do not warm-start the next call from a failed solve
      throw ComputeError(fmt::format("stress equilibration: the stress of cell {} is not finite after {} preconditioned CG "
                                     "iterations; expected a finite self-balanced field",
                                     c, result.refinement_steps));
    }
  }
  Vector remaining = residual_stress_forces(volume, result.stress_kPa);
  impl_->mask(remaining);
  result.force_reduction = remaining.norm() / load_norm;
  if (!(result.force_reduction <= kRequiredReduction)) {
    impl_->u.setZero();  // do not warm-start the next call from a failed solve
    throw ComputeError(fmt::format("stress equilibration reached only ||T sigma|| / ||T sigma_d|| = {:.3g} after {} "
                                   "preconditioned CG iterations (required {:.0e})",
                                   result.force_reduction, result.refinement_steps, kRequiredReduction));
  }
  return result;
}

EquilibrationResult equilibrate_stress(const TissueModel& model, std::span<const Vec6> designed_kPa,
                                       std::span<const VertexId> held_vertices) {
  return StressEquilibrator(model, held_vertices).equilibrate(designed_kPa);
}

}  // namespace cleave
