#pragma once
// Streamlines of the Langer direction field (paper fig. 6): polylines traced through the cells
// along each cell's Langer eigenvector, seeded on a regular subset of boundary cells.
//
//   StreamlineOptions o;                                   // defaults suit a few thousand cells
//   std::vector<std::vector<Vec3>> lines = trace_streamlines(volume, frames, o);
//
// The field is a line field (no sign): at every step the direction is flipped to continue the
// previous one. Integration is the midpoint rule with a step of `step_cells` cell sizes, in both
// directions from the seed, and stops on leaving the body, after `max_steps` per direction, or
// where the line would turn by more than `max_turn_deg` in one step (a singularity of the field).
// Seeds: boundary cells whose voxel coordinates are all multiples of `seed_stride_cells`.
// Lines shorter than 2 points are dropped. Deterministic (seed order = cell order).
#include <span>
#include <vector>

#include "cleave/grid/linked_volume.hpp"
#include "cleave/stress/direction_frames.hpp"

namespace cleave {

struct StreamlineOptions {
  int seed_stride_cells = 3;     ///< seed every n-th boundary cell along each axis (>= 1)
  double step_cells = 0.5;       ///< integration step in cell sizes (> 0)
  int max_steps = 200;           ///< per direction from the seed (>= 1)
  double max_turn_deg = 60.0;    ///< stop where one step turns by more than this
};

/// InputError for options out of range or a frame count that does not match the cells.
std::vector<std::vector<Vec3>> trace_streamlines(const LinkedVolume& volume, std::span<const DirectionFrame> frames,
                                                 const StreamlineOptions& options = {});

}  // namespace cleave
