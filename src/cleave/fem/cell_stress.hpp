#pragma once
// Total Cauchy stress per cell after release: the residual stress plus the elastic stress of the
// displacement, both carried by the cell's corotational frame:
//   sigma = R (sigma_res + D eps) R^T,  eps = sym(R^T F) - I at the cell centre, F = R S.
// For small rotations this is sigma_res + D B(centre) u (linear elasticity).
#include <span>
#include <vector>

#include "cleave/model/tissue_model.hpp"

namespace cleave {

/// kPa per cell. `residual_stress_kPa` may be empty (stress free); `displacement_mm` may be empty
/// (at rest); otherwise one per cell / per vertex (InputError if not).
std::vector<Vec6> total_cell_stress_kPa(const TissueModel& model, std::span<const Vec6> residual_stress_kPa,
                                        std::span<const Vec3> displacement_mm);

}  // namespace cleave
