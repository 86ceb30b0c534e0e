#pragma once
// Lumped (diagonal) mass of a tissue model on its current vertices.
#include "cleave/fem/element_table.hpp"
#include "cleave/solve/linear_solver.hpp"

namespace cleave {

/// Mass per dof (kg), 3 n_v entries: each cell gives rho h^3 / 8 to each of its 8 corner
/// vertices, the same for the x, y and z dof. Split vertices carry only the cells they serve, so
/// the total stays the body's mass after a cut. Recomputing is O(cells); no update is needed.
Vector lumped_mass(const TissueModel& model);
Vector lumped_mass(const TissueModel& model, const ElementTable& table);

}  // namespace cleave
