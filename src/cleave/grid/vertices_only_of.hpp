#pragma once
// The vertices that belong to a set of cells alone: corners no cell outside the set uses.
// Holding these vertices fixes the set's cells without touching anything else (the studio and
// the batch run hold the removed plugs of round incisions this way: hidden, cut-free pieces that
// would otherwise float as free bodies and slow every solve down).
#include <span>
#include <vector>

#include "cleave/grid/linked_volume.hpp"

namespace cleave {

/// Sorted, without duplicates. InputError for a cell id outside the volume.
std::vector<VertexId> vertices_only_of(const LinkedVolume& volume, std::span<const CellId> cells);

}  // namespace cleave
