#pragma once
// The residual stress tensor of every cell from its eigenvector frame and eigenvalues (eq. 4):
//   sigma = lambda_1 n_1 n_1^T + lambda_2 n_2 n_2^T + lambda_3 n_3 n_3^T   (Voigt, kPa).
//
//   std::vector<Vec6> s = stress_from_frames(frames, eigenvalues_kPa);   // InputError on size mismatch
#include <vector>

#include "cleave/stress/direction_frames.hpp"

namespace cleave {

std::vector<Vec6> stress_from_frames(const std::vector<DirectionFrame>& frames, const std::vector<Vec3>& eigenvalues_kPa);

}  // namespace cleave
