#pragma once
// Small models and stress fields for the cut tests.
#include <cmath>
#include <vector>

#include "cleave/model/tissue_model.hpp"

namespace cleave::test {

/// A solid box of `cells` cubic cells of edge h (mm), corner at the origin, label 1, E (kPa), nu.
inline TissueModel make_box(const Vec3i& cells, double h_mm, double youngs_modulus_kPa = 80.0,
                            double poisson_ratio = 0.4) {
  LabelVolume labels;
  labels.grid.dims = cells;
  labels.grid.cell_size_mm = h_mm;
  labels.grid.origin_mm = Vec3::Zero();
  labels.labels.assign(static_cast<std::size_t>(labels.grid.voxel_count()), Label{1});
  Material m;
  m.youngs_modulus_kPa = youngs_modulus_kPa;
  m.poisson_ratio = poisson_ratio;
  return make_tissue_model("box", std::move(labels), {{Label{1}, m}});
}

/// The same (uniform) Voigt stress in every cell.
inline std::vector<Vec6> uniform_stress(const TissueModel& model, const Vec6& s_kPa) {
  return std::vector<Vec6>(static_cast<std::size_t>(model.volume.cell_count()), s_kPa);
}

/// lambda_a a a^T + lambda_b b b^T in Voigt form.
inline Vec6 biaxial(const Vec3& a, double lambda_a_kPa, const Vec3& b, double lambda_b_kPa) {
  return to_voigt(lambda_a_kPa * a * a.transpose() + lambda_b_kPa * b * b.transpose());
}

}  // namespace cleave::test
