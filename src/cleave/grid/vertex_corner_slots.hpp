#pragma once
// Per vertex, where it sits in each of its cells: the slots 8 c + a (cell c, corner a) of the
// cells around it, in CSR form. Cell-by-cell operators compute per-cell corner values in one
// parallel pass and then sum them per vertex in a second one (no atomics, no colouring), reading a
// vertex's values through these slots.
//
//   const VertexCornerSlots slots = vertex_corner_slots(volume);
//   for (auto s = slots.start[v]; s < slots.start[v + 1]; ++s) sum += per_corner[slots.slot[s]];
#include <cstdint>
#include <vector>

#include "cleave/grid/linked_volume.hpp"

namespace cleave {

struct VertexCornerSlots {
  std::vector<std::int32_t> start{0};  ///< per vertex and one past the last: first entry in slot
  std::vector<std::int32_t> slot;      ///< 8 c + a for each cell c around the vertex, a its corner there
};

/// The slots of the volume's current cells and vertices (rebuild after a cut).
VertexCornerSlots vertex_corner_slots(const LinkedVolume& volume);

}  // namespace cleave
