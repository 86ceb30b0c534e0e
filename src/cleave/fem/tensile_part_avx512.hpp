#pragma once
// The tensile part of 8 symmetric stresses at once (fem/stress_stiffness.hpp: tensile_part), one
// per lane of an AVX-512 register of doubles: cyclic Jacobi rotations diagonalize each 3x3 tensor
// (no trigonometry: a square root and two divisions per rotation), then the eigenvalues below zero
// are dropped, T = V max(Lambda, 0) V^T. The dynamic step needs it for every cell whose stress is
// mixed in sign (most cells of tissue whose normal stress is near zero): Eigen's closed form costs
// an atan2, a sincos and a cos per cell.
//
// Compiled with -mavx512f -mavx512dq (src/cleave/CMakeLists.txt); like fem/polar_avx512.cpp it
// includes no Eigen and no inline code it could share with the rest of the library. Call it only
// where avx512_cell_pass_supported() is true.
//
//   tensile_parts_avx512(stress, tension, count);   // 6 doubles per tensor, Voigt (xx yy zz xy xz yz)

namespace cleave {

/// Rotations sweep over the pairs (0,1), (0,2), (1,2) until every lane's off-diagonal sum is below
/// `settled_ratio` times its diagonal's (or zero), at most `max_sweeps` times (3x3 Jacobi
/// converges quadratically: 3 to 5 sweeps from tissue stresses).
struct JacobiSweeps {
  int max_sweeps = 12;
  double settled_ratio = 1e-15;
};

/// The tensile parts of `count` (1 to 8) Voigt stresses `stress` (6 doubles each) into `tension`
/// (likewise).
void tensile_parts_avx512(const double* stress, double* tension, int count, const JacobiSweeps& sweeps);

}  // namespace cleave
