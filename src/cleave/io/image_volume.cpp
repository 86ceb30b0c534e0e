#include "cleave/io/image_volume.hpp"

#include <cmath>
#include <fmt/format.h>
#include <Eigen/LU>

#include "cleave/core/error.hpp"

namespace cleave {
namespace {

// A voxel whose edge vectors span less than this relative volume is degenerate (axes parallel).
constexpr double kMinRelativeVoxelVolume = 1e-9;

}  // namespace

void check_image_volume(const ImageVolume& image) {
  const std::string& f = image.source;
  if (image.dims.minCoeff() <= 0)
    throw InputError(fmt::format("{}: image size {}x{}x{}; expected at least one sample along each axis", f,
                                 image.dims.x(), image.dims.y(), image.dims.z()));
  if (!image.index_to_world.allFinite() || !image.origin_mm.allFinite())
    throw InputError(fmt::format("{}: voxel geometry (spacing, directions or origin) is not finite", f));
  const Vec3 spacing = image.spacing_mm();
  for (int a = 0; a < 3; ++a)
    if (!(spacing[a] > 0))
      throw InputError(fmt::format("{}: spacing of axis {} is {} mm; expected a positive spacing", f, a, spacing[a]));
  const double volume = std::abs(image.index_to_world.determinant());
  if (!(volume > kMinRelativeVoxelVolume * spacing.prod()))
    throw InputError(fmt::format("{}: the voxel axes are parallel (degenerate orientation); expected three "
                                 "independent axis directions", f));
  if (static_cast<std::int64_t>(image.values.size()) != image.sample_count())
    throw InputError(fmt::format("{}: holds {} samples; expected {} ({}x{}x{})", f, image.values.size(),
                                 image.sample_count(), image.dims.x(), image.dims.y(), image.dims.z()));
  for (size_t n = 0; n < image.values.size(); ++n)
    if (!std::isfinite(image.values[n]))
      throw InputError(fmt::format("{}: sample {} is {}; expected finite values", f, n, image.values[n]));
}

std::uint64_t checked_sample_count(std::uint64_t nx, std::uint64_t ny, std::uint64_t nz, const std::string& file) {
  std::uint64_t nxy = 0, samples = 0;
  if (__builtin_mul_overflow(nx, ny, &nxy) || __builtin_mul_overflow(nxy, nz, &samples))
    throw InputError(fmt::format("{}: image size {}x{}x{} has more than 2^64 samples; the header is corrupt", file, nx,
                                 ny, nz));
  return samples;
}

}  // namespace cleave
