#pragma once
// The equilibrium operator T of eq. 5 as an explicit sparse matrix, the eigenvalue form
// T (d sigma / d lambda) of eq. 6, and the relative equilibrium residual that the design reports.
//
//   SparseMatrix t = stress_divergence_matrix(volume);        // 3 n_v x 6 n_c, mm^2
//   EquilibriumNorm norm = equilibrium_norm(t);                // ||T||_2 estimate, once per topology
//   double r = relative_equilibrium_residual(t, norm, stress); // ||T sigma|| / (||T||_2 ||sigma||)
//
// Row 3 v + a is the force component a at vertex v; column 6 c + k is Voigt component k of cell
// c (xx, yy, zz, xy, xz, yz); T sigma equals fem/residual_stress_forces.hpp. ||T|| is the largest
// singular value (spectral norm), estimated by power iteration on T^T T, so the residual is 1
// for the worst possible field and 0 for a self-balanced one. "Free vertices" are all vertices:
// the design is made for the unsupported, uncut body.
#include <cstdint>
#include <span>
#include <vector>

#include "cleave/grid/linked_volume.hpp"
#include "cleave/solve/linear_solver.hpp"
#include "cleave/stress/direction_frames.hpp"

namespace cleave {

SparseMatrix stress_divergence_matrix(const LinkedVolume& volume);

/// T (d sigma / d lambda): 3 n_v x 3 n_c; column 3 c + i is T applied to the stress
/// n_i n_i^T (Voigt) of cell c's frame (i = Langer, cross, normal).
SparseMatrix eigenvalue_divergence_matrix(const LinkedVolume& volume, std::span<const DirectionFrame> frames);

struct EquilibriumNorm {
  double spectral_norm_mm2 = 0;  ///< estimate of the largest singular value of T
};

/// Per dof (3 per vertex): 1 where the vertex is held (Gamma_D). InputError "held vertex N does not
/// exist; ..." for ids out of range.
std::vector<std::uint8_t> held_dof_flags(VertexId vertex_count, std::span<const VertexId> held_vertices);

/// Zeroes the rows of `held_vertices` (rows 3 v + a) of a matrix with 3 n_v rows, so that the
/// operator only measures forces at free vertices (paper eq. 2 holds on Gamma_N only).
void drop_held_vertex_rows(SparseMatrix& t, std::span<const VertexId> held_vertices);

/// Power iteration (a fixed number of steps from a deterministic start) on T^T T.
EquilibriumNorm equilibrium_norm(const SparseMatrix& t);

/// ||T sigma||_2 / (||T||_2 ||sigma||_2); 0 for a zero field. Stress in kPa (the ratio has no unit).
double relative_equilibrium_residual(const SparseMatrix& t, const EquilibriumNorm& norm, std::span<const Vec6> stress_kPa);
/// The same from ||T sigma|| already known (the equilibration's forces at free vertices, mN = kPa mm^2).
double relative_equilibrium_residual(double force_norm_mN, const EquilibriumNorm& norm, std::span<const Vec6> stress_kPa);

/// Flattens per-cell Voigt tensors into one vector of 6 n_c values and back.
Vector flatten_stress(std::span<const Vec6> stress_kPa);
std::vector<Vec6> unflatten_stress(const Vector& flat);

}  // namespace cleave
