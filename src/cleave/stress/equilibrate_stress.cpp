#include "cleave/stress/equilibrate_stress.hpp"

#include <fmt/format.h>

#include "cleave/core/error.hpp"
#include "cleave/fem/element_table.hpp"
#include "cleave/fem/hex8_element.hpp"
#include "cleave/fem/residual_stress_forces.hpp"
#include "cleave/stress/sparse_cholesky.hpp"

namespace cleave {
namespace {

constexpr double kShiftOfMeanDiagonal = 1e-6;  ///< eps of Kc + eps I, relative to mean diag(Kc)
constexpr double kTargetReduction = 1e-12;     ///< stop when ||T sigma|| <= this * ||T sigma_d||
constexpr double kRequiredReduction = 1e-10;   ///< ComputeError above this after the last step
constexpr int kMaxRefinementSteps = 100;

}  // namespace

EquilibrationResult equilibrate_stress(const TissueModel& model, std::span<const Vec6> designed_kPa) {
  const LinkedVolume& volume = model.volume;
  if (designed_kPa.size() != static_cast<std::size_t>(volume.cell_count()))
    throw InputError(fmt::format("designed stress holds {} cell tensors; expected one per cell ({})", designed_kPa.size(),
                                 volume.cell_count()));
  for (std::size_t c = 0; c < designed_kPa.size(); ++c)
    if (!designed_kPa[c].allFinite()) throw InputError(fmt::format("designed stress of cell {} is not finite", c));

  EquilibrationResult result;
  result.stress_kPa.assign(designed_kPa.begin(), designed_kPa.end());
  const Vector load = residual_stress_forces(volume, designed_kPa);
  const double load_norm = load.norm();
  if (load_norm == 0.0) return result;

  const double h = volume.grid().cell_size_mm;
  const double cell_volume = h * h * h;
  const Mat6x24 bc = hex8_strain_matrix(Vec3::Constant(0.5), h);
  const ElementTable table = make_element_table(model);
  std::vector<Mat24> kc_per_material;
  for (const ElementMatrices& m : table.per_material)
    kc_per_material.push_back(cell_volume * bc.transpose() * m.elasticity_kPa * bc);

  const Eigen::Index dofs = 3 * static_cast<Eigen::Index>(volume.vertex_count());
  std::vector<Eigen::Triplet<double>> entries;
  entries.reserve(static_cast<std::size_t>(volume.cell_count()) * 24 * 24 + static_cast<std::size_t>(dofs));
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
  Eigen::SparseMatrix<double> kc(dofs, dofs);
  kc.setFromTriplets(entries.begin(), entries.end());
  const double shift = kShiftOfMeanDiagonal * kc.diagonal().mean();
  Eigen::SparseMatrix<double> shifted = kc;
  for (Eigen::Index d = 0; d < dofs; ++d) shifted.coeffRef(d, d) += shift;
  shifted.makeCompressed();
  SparseCholesky cholesky;
  cholesky.factorize(shifted);

  const Vector b = -load;
  Vector u = Vector::Zero(dofs);
  Vector r = b;
  double reduction = 1.0;
  while (result.refinement_steps < kMaxRefinementSteps && reduction > kTargetReduction) {
    u += cholesky.solve(r);
    r = b - kc * u;
    reduction = r.norm() / load_norm;
    ++result.refinement_steps;
  }
  for (CellId c = 0; c < volume.cell_count(); ++c) {
    Vec24 ue;
    const auto& corners = volume.cell_vertices(c);
    for (int a = 0; a < kCornerCount; ++a) ue.segment<3>(3 * a) = u.segment<3>(3 * corners[static_cast<std::size_t>(a)]);
    const Mat6& d = table.of_label(volume.cell_label(c)).elasticity_kPa;
    result.stress_kPa[static_cast<std::size_t>(c)] += d * (bc * ue);
  }
  result.force_reduction = residual_stress_forces(volume, result.stress_kPa).norm() / load_norm;
  if (!(result.force_reduction <= kRequiredReduction))
    throw ComputeError(fmt::format("stress equilibration reached only ||T sigma|| / ||T sigma_d|| = {:.3g} after {} steps "
                                   "(required {:.0e})",
                                   result.force_reduction, result.refinement_steps, kRequiredReduction));
  return result;
}

}  // namespace cleave
