#pragma once
// The vertices a case's "simulation" section holds: its fixed boxes and fixed surfaces (the
// body's inner side or all of it), on the model as it is. Used by the mechanics stage for the
// supports and by the design stage when equilibrium is asked only at the free vertices.
#include <vector>

#include "cleave/io/case_mechanics.hpp"
#include "cleave/model/tissue_model.hpp"

namespace cleave {

/// Sorted, without duplicates.
std::vector<VertexId> held_vertices(const TissueModel& model, const SimulationSettings& settings);

}  // namespace cleave
