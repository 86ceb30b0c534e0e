#pragma once
// A scalar 3-D image as read from a segmentation or intensity volume file (NRRD, NIfTI), before
// it is resampled onto cleave's axis-aligned grid. Plain data: sample values and the affine map
// from sample indices to world positions.
#include <cstdint>
#include <string>
#include <vector>

#include "cleave/core/types.hpp"

namespace cleave {

/// World frame of every image cleave reads: RAS+ as NIfTI (+x towards the patient's right,
/// +y anterior, +z superior), millimetres. NRRD files in LPS or LAS space are converted to it.
struct ImageVolume {
  std::string source;       ///< file the image came from (used in error messages)
  Vec3i dims{0, 0, 0};      ///< samples along the three index axes i, j, k
  /// World position (mm) of sample (i, j, k) = origin_mm + index_to_world * (i, j, k):
  /// the centre of that voxel. The columns of index_to_world are the voxel edge vectors (mm),
  /// so their lengths are the spacings; they may be rotated, permuted or flipped.
  Mat3 index_to_world = Mat3::Identity();
  Vec3 origin_mm{0, 0, 0};
  /// One value per sample, index (k * dims.y + j) * dims.x + i, after the file's value scaling.
  std::vector<double> values;
  /// True when the file stores integers (a label image is possible); false for float samples.
  bool integer_samples = true;

  std::int64_t sample_count() const { return std::int64_t{dims.x()} * dims.y() * dims.z(); }
  double value(const Vec3i& ijk) const {
    return values[static_cast<size_t>((std::int64_t{ijk.z()} * dims.y() + ijk.y()) * dims.x() + ijk.x())];
  }
  /// Voxel edge lengths along i, j, k (mm): the column norms of index_to_world.
  Vec3 spacing_mm() const { return index_to_world.colwise().norm().transpose(); }
};

/// Checks what every reader must guarantee: positive dimensions, finite invertible geometry with
/// positive spacings, finite values, values.size() == sample count. Throws InputError naming
/// `image.source` and the problem (e.g. "head.nrrd: spacing of axis 2 is 0 mm; expected a
/// positive spacing").
void check_image_volume(const ImageVolume& image);

/// Samples of an nx x ny x nz image (sizes as the file declares them), or InputError naming
/// `file` when the product does not fit in 64 bits: a header may declare sizes whose product
/// wraps around to a small number, which must never reach an allocation.
std::uint64_t checked_sample_count(std::uint64_t nx, std::uint64_t ny, std::uint64_t nz, const std::string& file);

}  // namespace cleave
