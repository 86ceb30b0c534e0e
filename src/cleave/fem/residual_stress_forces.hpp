#pragma once
// The equilibrium operator T of the paper (section 6.1): it maps one constant stress per cell
// (Voigt xx, yy, zz, xy, xz, yz) to forces on the vertices, T = assembled T^e = integral of B^T.
// T depends only on geometry and topology, never on the material.
//
// Sign convention: (T sigma) at a vertex is the force the stressed cells exert on the
// surroundings through that vertex; the elastic equilibrium after release is K u = f - T sigma.
// A stress field is in equilibrium on a body when (T sigma)_v = 0 at every free vertex.
// For a uniform stress, interior vertices get 0 and a boundary vertex gets sigma n times its
// tributary area of the boundary faces around it (n the outward normal).
#include <span>
#include <vector>

#include "cleave/core/types.hpp"
#include "cleave/grid/linked_volume.hpp"
#include "cleave/solve/linear_solver.hpp"

namespace cleave {

/// T sigma: 3 n_v forces in mN for stresses in kPa (one per cell). Throws InputError when
/// `stress_kPa` does not hold one entry per cell.
Vector residual_stress_forces(const LinkedVolume& volume, std::span<const Vec6> stress_kPa);

/// T^T f: per cell, the 6 Voigt components T^e^T f_e (mm^2 times the unit of f), the adjoint used
/// by least-squares stress fits (minimizing |T sigma|^2 needs T^T T sigma).
std::vector<Vec6> stress_divergence_transpose(const LinkedVolume& volume, const Vector& vertex_values);

}  // namespace cleave
