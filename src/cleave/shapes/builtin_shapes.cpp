#include "cleave/shapes/builtin_shapes.hpp"

#include <algorithm>
#include <cmath>
#include <fmt/format.h>
#include <functional>

#include "cleave/core/error.hpp"

namespace cleave {
namespace {

struct ShapeDefinition {
  std::string name;
  Vec3i default_cells;
  double default_cell_size_mm;
  /// Signed distance (mm, negative inside) and tissue label at a point, given the grid extent.
  std::function<float(const Vec3& p, const Vec3& extent)> distance_mm;
  std::function<Label(const Vec3& p, const Vec3& extent)> label;
};

constexpr double kTubeDiameterMm = 84.0;
constexpr double kTubeInnerRadiusFraction = 0.615;
constexpr double kAbdomenWidthMm = 315.0;
constexpr double kAbdomenThicknessMm = 10.8;
constexpr double kAbdomenDomeHeightMm = 70.0;
constexpr double kPlateWidthMm = 100.0;

float tube_distance(const Vec3& p, const Vec3& extent) {
  const double outer = 0.5 * extent.x();
  const double inner = kTubeInnerRadiusFraction * outer;
  const double rho = std::hypot(p.x() - 0.5 * extent.x(), p.y() - 0.5 * extent.y());
  const double radial = std::max(rho - outer, inner - rho);
  const double axial = std::max(-p.z(), p.z() - extent.z());
  return static_cast<float>(std::max(radial, axial));
}

/// Outer skin surface of the abdomen as a height y(x, z) above the grid's bottom, and its gradient.
struct Dome {
  double height;
  Eigen::Vector2d gradient;
};
Dome abdomen_dome(const Vec3& p, const Vec3& extent) {
  const double half_x = 0.5 * extent.x();
  const double half_z = 0.5 * extent.z();
  const double u = (p.x() - half_x) / half_x;
  const double w = (p.z() - half_z) / half_z;
  const double base = kAbdomenThicknessMm + 1.0;
  const double rise = std::min(kAbdomenDomeHeightMm, extent.y() - base - 1.0);
  const double fu = 1.0 - u * u;
  const double fw = 1.0 - 0.35 * w * w;
  return {base + rise * fu * fw, {rise * (-2.0 * u / half_x) * fw, rise * fu * (-0.7 * w / half_z)}};
}

float abdomen_distance(const Vec3& p, const Vec3& extent) {
  const Dome dome = abdomen_dome(p, extent);
  const double slope = std::sqrt(1.0 + dome.gradient.squaredNorm());
  const double above_skin = (p.y() - dome.height) / slope;
  const double below_inner = (dome.height - kAbdomenThicknessMm - p.y()) / slope;
  const double sides = std::max({-p.x(), p.x() - extent.x(), -p.z(), p.z() - extent.z()});
  return static_cast<float>(std::max({above_skin, below_inner, sides}));
}

Label abdomen_label(const Vec3& p, const Vec3& extent) {
  const Dome dome = abdomen_dome(p, extent);
  const double slope = std::sqrt(1.0 + dome.gradient.squaredNorm());
  const double depth = (dome.height - p.y()) / slope / kAbdomenThicknessMm;  // 0 at skin, 1 at the inner layer
  if (depth < 0.2) return 1;  // skin
  if (depth < 0.5) return 2;  // fat
  return 3;                   // muscle
}

float plate_distance(const Vec3& p, const Vec3& extent) {
  const Vec3 half = 0.5 * extent;
  const Vec3 q = (p - half).cwiseAbs() - half;
  return static_cast<float>(q.maxCoeff());
}

const std::vector<ShapeDefinition>& shapes() {
  static const std::vector<ShapeDefinition> all = {
      {"cylinder", {21, 21, 26}, kTubeDiameterMm / 21, tube_distance, [](const Vec3&, const Vec3&) { return Label{1}; }},
      {"abdomen", {63, 21, 42}, kAbdomenWidthMm / 63, abdomen_distance, abdomen_label},
      // 100 x 100 mm, 4 cells = 10 mm thick
      {"plate", {40, 40, 4}, kPlateWidthMm / 40, plate_distance, [](const Vec3&, const Vec3&) { return Label{1}; }},
  };
  return all;
}

const ShapeDefinition& find_shape(std::string_view name) {
  for (const auto& s : shapes())
    if (s.name == name) return s;
  throw InputError(fmt::format("unknown built-in model '{}'; expected one of: {}", name,
                               fmt::join(builtin_shape_names(), ", ")));
}

}  // namespace

std::vector<std::string> builtin_shape_names() {
  std::vector<std::string> names;
  for (const auto& s : shapes()) names.push_back(s.name);
  return names;
}

bool is_builtin_shape(std::string_view name) {
  return std::any_of(shapes().begin(), shapes().end(), [&](const ShapeDefinition& s) { return s.name == name; });
}

Vec3i builtin_default_resolution(std::string_view name) { return find_shape(name).default_cells; }

LabelVolume make_builtin_shape(std::string_view name, const ShapeResolution& resolution) {
  const ShapeDefinition& shape = find_shape(name);
  // Physical extent of the default grid; the x extent is what a resolution divides.
  const Vec3 default_extent = shape.default_cell_size_mm * shape.default_cells.cast<double>();
  GridSpec grid;
  if (resolution.cells) {
    grid.dims = *resolution.cells;
    if (grid.dims.minCoeff() <= 0)
      throw InputError(fmt::format("resolution {}x{}x{}: expected a positive number of cells along each axis",
                                   grid.dims.x(), grid.dims.y(), grid.dims.z()));
    grid.cell_size_mm = default_extent.x() / grid.dims.x();
  } else if (resolution.cell_size_mm) {
    const double h = *resolution.cell_size_mm;
    if (!(h > 0) || !std::isfinite(h))
      throw InputError(fmt::format("cell size {} mm: expected a positive finite number", h));
    grid.cell_size_mm = h;
    const Vec3 cells = (default_extent / h).array().round().max(1.0);
    if (cells.maxCoeff() > 1e5)
      throw InputError(fmt::format("cell size {} mm gives {:.0f} cells along one axis; expected at most 100000", h,
                                   cells.maxCoeff()));
    grid.dims = cells.cast<int>();
  } else {
    grid.dims = shape.default_cells;
    grid.cell_size_mm = shape.default_cell_size_mm;
  }
  const Vec3 extent = grid.extent_mm();
  LabelVolume volume = make_empty_label_volume(grid, /*with_distance=*/true);
  for (int z = 0; z <= grid.dims.z(); ++z)
    for (int y = 0; y <= grid.dims.y(); ++y)
      for (int x = 0; x <= grid.dims.x(); ++x) {
        const Vec3i corner{x, y, z};
        volume.corner_distance_mm[static_cast<size_t>(grid.corner_index(corner))] =
            shape.distance_mm(grid.corner_position_mm(corner) - grid.origin_mm, extent);
      }
  for (int z = 0; z < grid.dims.z(); ++z)
    for (int y = 0; y < grid.dims.y(); ++y)
      for (int x = 0; x < grid.dims.x(); ++x) {
        const Vec3i v{x, y, z};
        const Vec3 center = grid.voxel_center_mm(v) - grid.origin_mm;
        if (shape.distance_mm(center, extent) < 0)
          volume.labels[static_cast<size_t>(grid.voxel_index(v))] = shape.label(center, extent);
      }
  if (name == "abdomen") volume.label_names = {{1, "skin"}, {2, "fat"}, {3, "muscle"}};
  else volume.label_names = {{1, "tissue"}};
  return volume;
}

}  // namespace cleave
