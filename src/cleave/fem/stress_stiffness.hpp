#pragma once
// The initial-stress (geometric) stiffness of corotated cells. A cell's force R (K^e d + T^e s)
// turns with the cell: for an increment that rotates it rigidly by dtheta, the force changes by
// dtheta x f. The frozen-rotation step of corotational dynamics misses that change; under tissue
// tension of the order of E it then grows rotations of loose pieces from step to step (a free
// shell under 20 kPa of unbalanced tension diverged within 0.2-0.5 s at dt = 1/60 s). The standard
// geometric stiffness of the stress the cell carries, sum_k s_k G_k (x) I_3 per block (hex8_element:
// hex8_stress_stiffness_basis), gives exactly dtheta x f for rigid rotations. Only the tensile part
// of the stress is taken, so that the step's system stays positive definite (compression would
// soften it; its buckling is left to the exact forces).
//
//   cell_rotations_and_tension(volume, table, residual_kPa, u, rotations, tension);  // per cell
//   block(a, b) += stress_stiffness_coefficient(table, tension[c], a, b) * I_3;  // mN/mm
#include <span>
#include <vector>

#include "cleave/fem/cell_ranges.hpp"
#include "cleave/fem/element_table.hpp"
#include "cleave/grid/linked_volume.hpp"
#include "cleave/solve/linear_solver.hpp"

namespace cleave {

/// The tensile part of a symmetric stress (Voigt, kPa): its negative eigenvalues set to zero.
Vec6 tensile_part(const Vec6& stress_kPa);

/// Per cell, in one pass: the rotation R of F = R S at the cell centre (as cell_rotations) and the
/// tensile part of the stress the cell carries in its corotated frame, the residual stress (empty:
/// none) plus D (S - I), F from `displacement_mm` (3 n_v). In parallel; both outputs are resized.
void cell_rotations_and_tension(const LinkedVolume& volume, const ElementTable& table, std::span<const Vec6> residual_stress_kPa,
                                const Vector& displacement_mm, std::vector<Mat3>& rotations, std::vector<Vec6>& tension_kPa);
/// The same for the cells of `cell_ranges` ([begin, end) pairs) only, in parallel over the
/// ranges; the other cells' entries stay as they were (both outputs must already hold one per
/// cell: InputError otherwise). The dynamic step leaves out the cells held at every corner.
void cell_rotations_and_tension(const LinkedVolume& volume, const ElementTable& table, std::span<const Vec6> residual_stress_kPa,
                                const Vector& displacement_mm, std::span<const CellRange> cell_ranges,
                                std::vector<Mat3>& rotations, std::vector<Vec6>& tension_kPa);

/// The coefficient of I_3 in block (a, b) of the initial-stress stiffness of a cell that carries
/// `stress_kPa` (mN/mm): sum over the Voigt components k of stress_k G_k(a, b).
inline double stress_stiffness_coefficient(const ElementTable& table, const Vec6& stress_kPa, int a, int b) {
  double sum = 0;
  for (std::size_t k = 0; k < 6; ++k) sum += stress_kPa[static_cast<Eigen::Index>(k)] * table.stress_stiffness[k](a, b);
  return sum;
}

}  // namespace cleave
