#pragma once
// Per vertex, where it sits in each of its cells: the slots stride c + a (cell c, corner a) of
// the cells around it, in CSR form. Cell-by-cell operators compute per-cell corner values in one
// parallel pass and then sum them per vertex in a second one (no atomics, no colouring), reading a
// vertex's values through these slots. With 24 values per cell (8 x, 8 y, 8 z) a slot is where
// the vertex's x value sits, its y and z 8 and 16 further.
//
//   const VertexCornerSlots slots = vertex_corner_slots(volume, 24);
//   for (auto s = slots.start[v]; s < slots.start[v + 1]; ++s) sum_x += per_cell[slots.slot[s]];
#include <cstdint>
#include <vector>

#include "cleave/grid/linked_volume.hpp"

namespace cleave {

struct VertexCornerSlots {
  std::vector<std::int32_t> start{0};  ///< per vertex and one past the last: first entry in slot
  std::vector<std::int32_t> slot;      ///< stride c + a for each cell c around the vertex, a its corner there
};

/// The slots of the volume's current cells and vertices (rebuild after a cut) for `stride` values
/// per cell (at least kCornerCount).
VertexCornerSlots vertex_corner_slots(const LinkedVolume& volume, std::int32_t stride);

}  // namespace cleave
