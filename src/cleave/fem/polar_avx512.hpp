#pragma once
// The polar factor's Newton iteration (fem/corotation.hpp: rotation_from_deformation_gradient)
// on 8 deformation gradients at once, one per lane of an AVX-512 register of doubles: the same
// operations in the same order as the 4-lane AVX2 version, so the same rotations bit for bit.
//
// Compiled with -mavx512f -mavx512dq (src/cleave/CMakeLists.txt); like
// fem/corotated_cells_avx512.cpp it includes no Eigen and no inline code it could share with the
// rest of the library. Call it only where avx512_cell_pass_supported() is true.
//
//   const unsigned settled = polar_rotations_avx512(f, r, count);   // the rest: the SVD
#include <cstdint>

namespace cleave {

/// Newton steps after which a lane that has not settled goes to the SVD, and the settling rule
/// (no entry moved by more than `settled_change` in the last step): corotation.cpp's constants.
struct PolarIteration {
  int max_iterations = 16;
  double settled_change = 3e-8;
};

/// The Newton iteration on `count` (1 to 8) gradients `f` (9 doubles each, column-major, as
/// Eigen's Matrix3d), their rotations into `rotations` (likewise). Returns the mask of the lanes
/// that settled (bit i: gradient i); a lane that did not (its determinant not positive and
/// finite, or unsettled after the iterations) is left for the SVD and its rotation unwritten.
unsigned polar_rotations_avx512(const double* f, double* rotations, int count, const PolarIteration& iteration);

}  // namespace cleave
