#include "cleave/io/volume_resample.hpp"

#include <algorithm>
#include <cmath>
#include <Eigen/LU>
#include <fmt/format.h>

#include "cleave/core/error.hpp"
#include "cleave/io/grid_covering_box.hpp"

namespace cleave {
namespace {

constexpr int kMinOccupancySamplesPerAxis = 2;  // at least the 8 cells around a corner
constexpr int kMaxOccupancySamplesPerAxis = 4;  // 64 lookups per corner at most

/// Nearest-neighbour lookup of the labelled image at a continuous index position.
struct LabelLookup {
  const ImageVolume& image;
  const std::vector<Label>& labels;
  Label at(const Vec3& index) const {
    const Vec3i ijk(static_cast<int>(std::lround(index.x())), static_cast<int>(std::lround(index.y())),
                    static_cast<int>(std::lround(index.z())));
    if ((ijk.array() < 0).any() || (ijk.array() >= image.dims.array()).any()) return 0;
    return labels[static_cast<size_t>((std::int64_t{ijk.z()} * image.dims.y() + ijk.y()) * image.dims.x() + ijk.x())];
  }
};

/// World bounding box of the labelled samples, each taken as its voxel (index +- 0.5).
std::pair<Vec3, Vec3> labelled_world_box(const ImageVolume& image, const std::vector<Label>& labels) {
  Vec3i lo = image.dims, hi = Vec3i::Constant(-1);
  size_t n = 0;
  for (int k = 0; k < image.dims.z(); ++k)
    for (int j = 0; j < image.dims.y(); ++j)
      for (int i = 0; i < image.dims.x(); ++i, ++n)
        if (labels[n] != 0) {
          lo = lo.cwiseMin(Vec3i(i, j, k));
          hi = hi.cwiseMax(Vec3i(i, j, k));
        }
  if (hi.x() < 0) throw InputError(fmt::format("{}: the mask is empty: no sample is selected", image.source));
  Vec3 world_lo = Vec3::Constant(std::numeric_limits<double>::infinity());
  Vec3 world_hi = -world_lo;
  for (int c = 0; c < 8; ++c) {
    const Vec3 index((c & 1 ? hi.x() + 0.5 : lo.x() - 0.5), (c & 2 ? hi.y() + 0.5 : lo.y() - 0.5),
                     (c & 4 ? hi.z() + 0.5 : lo.z() - 0.5));
    const Vec3 p = image.origin_mm + image.index_to_world * index;
    world_lo = world_lo.cwiseMin(p);
    world_hi = world_hi.cwiseMax(p);
  }
  return {world_lo, world_hi};
}

}  // namespace

LabelVolume resample_image_labels(const ImageVolume& image, const std::vector<Label>& sample_labels,
                                  const VolumeResampleOptions& options) {
  check_image_volume(image);
  if (static_cast<std::int64_t>(sample_labels.size()) != image.sample_count())
    throw InputError(fmt::format("{}: {} sample labels for {} samples", image.source, sample_labels.size(),
                                 image.sample_count()));
  const Vec3 spacing = image.spacing_mm();
  const double h = options.cell_size_mm.value_or(spacing.maxCoeff());
  const auto [lo, hi] = labelled_world_box(image, sample_labels);
  const GridSpec grid = grid_covering_box(lo, hi, h, 0, fmt::format("{} at cell size {} mm", image.source, h));
  LabelVolume volume = make_empty_label_volume(grid, /*with_distance=*/true);

  // index(p) = A^-1 (p - origin): affine in the grid coordinates, stepped incrementally.
  const Mat3 world_to_index = image.index_to_world.inverse();
  const Mat3 step = world_to_index * h;  // index change per grid step along x, y, z (columns)
  const LabelLookup lookup{image, sample_labels};
  const auto index_at = [&](const Vec3& p_mm) -> Vec3 { return world_to_index * (p_mm - image.origin_mm); };

  std::int64_t inside = 0;
  for (int z = 0; z < grid.dims.z(); ++z) {
    report(options.progress, "resampling volume", 0.5 * z / grid.dims.z());
    for (int y = 0; y < grid.dims.y(); ++y) {
      Vec3 index = index_at(grid.voxel_center_mm({0, y, z}));
      std::int64_t n = grid.voxel_index({0, y, z});
      for (int x = 0; x < grid.dims.x(); ++x, ++n, index += step.col(0)) {
        const Label label = lookup.at(index);
        volume.labels[static_cast<size_t>(n)] = label;
        inside += label != 0;
      }
    }
  }
  if (inside == 0)
    throw InputError(fmt::format("{}: the mask is empty at cell size {} mm: no cell centre falls on a selected "
                                 "sample; choose a smaller cell size", image.source, h));

  const int per_axis = std::clamp(static_cast<int>(std::ceil(h / spacing.minCoeff())), kMinOccupancySamplesPerAxis,
                                  kMaxOccupancySamplesPerAxis);
  std::vector<Vec3> offsets;  // sub-sample offsets (index space) inside the cube around a corner
  for (int c = 0; c < per_axis; ++c)
    for (int b = 0; b < per_axis; ++b)
      for (int a = 0; a < per_axis; ++a) {
        const Vec3 fraction = (Vec3(a, b, c) + Vec3::Constant(0.5)) / per_axis - Vec3::Constant(0.5);
        offsets.push_back(step * fraction);
      }
  const double weight = 1.0 / static_cast<double>(offsets.size());
  for (int z = 0; z <= grid.dims.z(); ++z) {
    report(options.progress, "surface distances", 0.5 + 0.5 * z / (grid.dims.z() + 1));
    for (int y = 0; y <= grid.dims.y(); ++y) {
      Vec3 index = index_at(grid.corner_position_mm({0, y, z}));
      std::int64_t n = grid.corner_index({0, y, z});
      for (int x = 0; x <= grid.dims.x(); ++x, ++n, index += step.col(0)) {
        double occupancy = 0;
        for (const Vec3& o : offsets) occupancy += lookup.at(index + o) != 0 ? weight : 0.0;
        volume.corner_distance_mm[static_cast<size_t>(n)] = static_cast<float>((0.5 - occupancy) * h);
      }
    }
  }
  report(options.progress, "surface distances", 1.0);
  return volume;
}

}  // namespace cleave
