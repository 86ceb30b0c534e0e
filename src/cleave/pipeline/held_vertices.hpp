#pragma once
// The vertices a case's "simulation" section holds: its fixed boxes and fixed surfaces (the
// body's inner side or all of it), on the model as it is. Used by the mechanics stage for the
// supports and by the design stage when equilibrium is asked only at the free vertices.
// After cuts, the removed plugs of round incisions (hidden, cut-free pieces that touch nothing)
// are held too, by the batch run and the studio alike: as free bodies they change nothing the
// user sees but were the solvers' slowest case (rigid supports, free corotated pieces).
#include <span>
#include <vector>

#include "cleave/io/case_mechanics.hpp"
#include "cleave/model/tissue_model.hpp"

namespace cleave {

/// Sorted, without duplicates.
std::vector<VertexId> held_vertices(const TissueModel& model, const SimulationSettings& settings);
/// The same plus the vertices that only `removed_cells` use (grid/vertices_only_of.hpp).
std::vector<VertexId> held_vertices(const TissueModel& model, const SimulationSettings& settings,
                                    std::span<const CellId> removed_cells);

}  // namespace cleave
