#pragma once
// The axis-aligned grid of cubic cells that covers a world-space box: how model sources choose
// cleave's grid for a resampled volume or a voxelized mesh.
#include <string>

#include "cleave/grid/grid_spec.hpp"

namespace cleave {

/// Smallest grid of cells of edge `cell_size_mm` covering the box [lo_mm, hi_mm], centred on the
/// box, plus `padding_cells` empty cells on every side. A box whose extent is an exact multiple
/// of the cell size (within 1e-6 cells) gets exactly that many cells, so a grid read back from a
/// file it was written to is the same grid. A flat box still gets one cell along that axis.
/// Throws InputError when the cell size is not positive and finite, when the box is not finite,
/// and -- before anything is allocated -- when a label volume on that grid would not fit in
/// memory (naming `what`, e.g. "man.off at cell size 0.001 mm", and the bytes it would need).
GridSpec grid_covering_box(const Vec3& lo_mm, const Vec3& hi_mm, double cell_size_mm, int padding_cells,
                           const std::string& what);

}  // namespace cleave
