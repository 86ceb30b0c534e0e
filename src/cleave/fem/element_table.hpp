#pragma once
// Element matrices shared by all cells of one material. On the uniform grid every cell is the
// same cube, so K^e depends only on the cell's material and T^e only on the cell size: they are
// computed once per label instead of once per cell.
//
//   ElementTable table = make_element_table(model);
//   const Mat24& ke = table.of_label(model.volume.cell_label(c)).stiffness;
//
// Units: K^e in mN/mm, T^e in mm^2, node mass in kg (lumped: rho h^3 / 8 per corner).
#include <array>
#include <cstdint>
#include <vector>

#include "cleave/fem/hex8_element.hpp"
#include "cleave/model/tissue_model.hpp"

namespace cleave {

struct ElementMatrices {
  Mat6 elasticity_kPa;   ///< isotropic D (Voigt, engineering shear)
  Mat24 stiffness;       ///< K^e, mN/mm
  double node_mass_kg;   ///< lumped mass of each of the 8 nodes
};

struct ElementTable {
  double cell_size_mm = 1.0;
  Mat24x6 stress_divergence;  ///< T^e = integral of B^T (mm^2); material independent
  std::array<Mat8, 6> stress_stiffness;  ///< G_k (mm): initial-stress stiffness per Voigt component
  std::array<int, 256> slot_of_label{};  ///< label -> index into per_material (-1 = label absent)
  std::vector<ElementMatrices> per_material;

  const ElementMatrices& of_label(Label label) const {
    return per_material[static_cast<std::size_t>(slot_of_label[label])];
  }
};

/// Per cell of `volume`: its material's slot in table.per_material (the cell passes' lookup).
std::vector<std::uint8_t> material_slot_per_cell(const ElementTable& table, const LinkedVolume& volume);

/// Element matrices for every label used by a cell of `model`. Materials are validated
/// (InputError naming "materials/<label>" for E <= 0, nu outside (-1, 0.5), density <= 0).
ElementTable make_element_table(const TissueModel& model);

}  // namespace cleave
