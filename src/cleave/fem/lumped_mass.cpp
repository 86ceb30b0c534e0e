#include "cleave/fem/lumped_mass.hpp"

namespace cleave {

Vector lumped_mass(const TissueModel& model, const ElementTable& table) {
  const LinkedVolume& volume = model.volume;
  Vector mass = Vector::Zero(3 * static_cast<Eigen::Index>(volume.vertex_count()));
  for (CellId c = 0; c < volume.cell_count(); ++c) {
    const double m = table.of_label(volume.cell_label(c)).node_mass_kg;
    for (const VertexId v : volume.cell_vertices(c)) mass.segment<3>(3 * v).array() += m;
  }
  return mass;
}

Vector lumped_mass(const TissueModel& model) { return lumped_mass(model, make_element_table(model)); }

}  // namespace cleave
