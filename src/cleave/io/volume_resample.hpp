#pragma once
// Resampling a labelled image (any orientation, any spacing) onto cleave's axis-aligned grid of
// cubic cells, with corner signed distances so that the render surface is smooth.
#include <optional>
#include <vector>

#include "cleave/core/progress.hpp"
#include "cleave/grid/label_volume.hpp"
#include "cleave/io/image_volume.hpp"

namespace cleave {

struct VolumeResampleOptions {
  /// Cell edge (mm); default: the largest voxel spacing of the image (no finer than the data).
  std::optional<double> cell_size_mm;
  ProgressFn progress;
};

/// Resamples `sample_labels` (one Label per sample of `image`, 0 = outside; e.g. from
/// select_image_labels) onto the axis-aligned grid that covers the world bounding box of the
/// non-zero samples (each sample taken as its voxel box), centred on it. Every cell takes the
/// label of the sample nearest to its centre (nearest neighbour: labels are never blended).
/// corner_distance_mm is filled from the box-filtered occupancy of the mask around each grid
/// corner (a cube of one cell, supersampled 2 to 4 times per axis): d = (0.5 - occupancy) * h,
/// which is the exact signed distance (negative inside) for a locally planar surface within
/// half a cell, and +-h/2 farther away.
/// Throws InputError (naming image.source) when no sample is labelled, the cell size is not
/// positive, no cell centre falls on a labelled sample, or the grid would not fit in memory.
LabelVolume resample_image_labels(const ImageVolume& image, const std::vector<Label>& sample_labels,
                                  const VolumeResampleOptions& options);

}  // namespace cleave
