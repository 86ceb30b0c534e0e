#include "cleave/fem/element_table.hpp"

#include "cleave/core/units.hpp"

namespace cleave {

ElementTable make_element_table(const TissueModel& model) {
  ElementTable table;
  const LinkedVolume& volume = model.volume;
  table.cell_size_mm = volume.grid().cell_size_mm;
  table.stress_divergence = hex8_stress_divergence(table.cell_size_mm);
  table.stress_stiffness = hex8_stress_stiffness_basis(table.cell_size_mm);
  table.slot_of_label.fill(-1);
  for (CellId c = 0; c < volume.cell_count(); ++c) {
    const Label label = volume.cell_label(c);
    if (table.slot_of_label[label] >= 0) continue;
    const Material& m = model.material_of_cell(c);
    validate_material(m, "materials/" + std::to_string(label));
    ElementMatrices e;
    e.elasticity_kPa = isotropic_elasticity(m.youngs_modulus_kPa, m.poisson_ratio);
    e.stiffness = hex8_stiffness(table.cell_size_mm, e.elasticity_kPa);
    e.node_mass_kg = hex8_lumped_node_mass(table.cell_size_mm, units::density_kg_per_mm3(m.density_kg_per_m3));
    table.slot_of_label[label] = static_cast<int>(table.per_material.size());
    table.per_material.push_back(e);
  }
  return table;
}

std::vector<std::uint8_t> material_slot_per_cell(const ElementTable& table, const LinkedVolume& volume) {
  std::vector<std::uint8_t> slots(static_cast<std::size_t>(volume.cell_count()));
  for (std::size_t c = 0; c < slots.size(); ++c)
    slots[c] = static_cast<std::uint8_t>(table.slot_of_label[volume.cell_label(static_cast<CellId>(c))]);
  return slots;
}

}  // namespace cleave
