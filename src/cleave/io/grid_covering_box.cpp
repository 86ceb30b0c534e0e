#include "cleave/io/grid_covering_box.hpp"

#include <algorithm>
#include <cmath>
#include <fmt/format.h>
#include <limits>

#include "cleave/core/error.hpp"
#include "cleave/core/memory_budget.hpp"

namespace cleave {
namespace {

// A box extent within this fraction of a cell of a whole number of cells is that many cells.
constexpr double kWholeCellTolerance = 1e-6;
// Bytes a label volume needs per voxel, as make_empty_label_volume estimates them (labels,
// voxel-to-cell map, cell record) plus the float corner distance.
constexpr double kLabelVolumeBytesPerVoxel = 114.0;
// Largest grid dimension an int index can hold with room for the +1 corners and padding.
constexpr double kMaxCellsPerAxis = 1e9;

}  // namespace

GridSpec grid_covering_box(const Vec3& lo_mm, const Vec3& hi_mm, double cell_size_mm, int padding_cells,
                           const std::string& what) {
  if (!(cell_size_mm > 0) || !std::isfinite(cell_size_mm))
    throw InputError(fmt::format("{}: cell size {} mm; expected a positive finite number", what, cell_size_mm));
  if (!lo_mm.allFinite() || !hi_mm.allFinite())
    throw InputError(fmt::format("{}: the bounding box is not finite", what));
  Eigen::Vector3d cells;
  for (int a = 0; a < 3; ++a) {
    const double extent = std::max(0.0, hi_mm[a] - lo_mm[a]) / cell_size_mm;
    cells[a] = std::max(1.0, std::ceil(extent - kWholeCellTolerance)) + 2.0 * padding_cells;
  }
  const double voxels = cells.prod();
  const double bytes = voxels * kLabelVolumeBytesPerVoxel;
  const std::string grid_words = fmt::format("{} (a {:.0f}x{:.0f}x{:.0f} grid)", what, cells.x(), cells.y(), cells.z());
  if (cells.maxCoeff() > kMaxCellsPerAxis || bytes >= static_cast<double>(std::numeric_limits<std::uint64_t>::max()))
    throw InputError(fmt::format("{} would need {:.3g} GiB of memory; choose a larger cell size or a smaller region",
                                 grid_words, bytes / static_cast<double>(std::uint64_t{1} << 30)));
  require_memory(static_cast<std::uint64_t>(bytes), grid_words);

  GridSpec grid;
  grid.dims = cells.cast<int>();
  grid.cell_size_mm = cell_size_mm;
  grid.origin_mm = 0.5 * (lo_mm + hi_mm) - 0.5 * cell_size_mm * cells;
  return grid;
}

}  // namespace cleave
