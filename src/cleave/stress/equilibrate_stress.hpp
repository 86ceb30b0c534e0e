#pragma once
// Makes a designed residual stress exactly self-balanced on the uncut body (issue 4, item 5),
// in the kinematic-growth view of paper section 3.2: the design sigma_d is read as the stress of
// an incompatible eigenstrain; its compatible part is removed by one elastic solve.
//
// With the one-point (cell-centre) strain matrix Bc of each cube, T^e = V Bc^T exactly (the
// trilinear B averages to its centre value). Solving
//   Kc u = -T sigma_d,   Kc = sum over cells of V Bc^T D Bc    (D of the cell's material)
// and setting sigma = sigma_d + D Bc u gives T sigma = T sigma_d + Kc u = 0. Kc is singular
// (rigid and hourglass modes) but the right-hand side lies in its range, and those modes do not
// change D Bc u. The solve is sparse Cholesky of Kc + eps I (eps = 1e-6 of the mean diagonal)
// used in iterative refinement until ||T sigma|| <= 1e-12 ||T sigma_d|| (or 100 steps).
// Consequences: the uncut, unsupported body does not move under sigma, and the volume average of
// sigma is exactly zero (Hoger's theorem, section 3.1), since T sigma = 0 for a field on cubes
// implies sum_c V sigma_c = 0.
//
//   EquilibrationResult r = equilibrate_stress(model, designed_kPa);
//   r.stress_kPa  // per cell, Voigt
#include <span>
#include <vector>

#include "cleave/model/tissue_model.hpp"

namespace cleave {

struct EquilibrationResult {
  std::vector<Vec6> stress_kPa;         ///< self-balanced field, one per cell
  double force_reduction = 0;           ///< ||T sigma|| / ||T sigma_d|| reached (0 when sigma_d was balanced)
  int refinement_steps = 0;
};

/// Throws InputError when `designed_kPa` has the wrong size or non-finite values; ComputeError
/// when the refinement does not reach 1e-10 (never returns NaN).
EquilibrationResult equilibrate_stress(const TissueModel& model, std::span<const Vec6> designed_kPa);

}  // namespace cleave
