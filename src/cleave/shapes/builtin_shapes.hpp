#pragma once
// Built-in models, generated at any resolution from an analytic signed distance function:
//   cylinder  the paper's thick-walled tube (fig. 10, Table 1): outer diameter 84 mm, axis along z,
//             inner radius 0.615 of the outer; default 21x21x26 cells (4 mm), length = nz * cell size.
//   abdomen   a doubly curved abdominal-wall-like shell, 315 mm wide (x), 210 mm long (z), about
//             10.8 mm thick, with skin (label 1), fat (2) and muscle (3) layers from outside in;
//             default 63x21x42 cells (5 mm).
//   plate     a thin box 100 x 100 x 10 mm, for tests; default 40x40x4 cells (2.5 mm).
// The physical size is fixed; the resolution sets the cell size (x extent / nx), or the cell
// size sets the resolution.
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "cleave/grid/label_volume.hpp"

namespace cleave {

struct ShapeResolution {
  std::optional<Vec3i> cells;          ///< grid dimensions NX x NY x NZ
  std::optional<double> cell_size_mm;  ///< alternatively, the cell edge length
};

/// Names accepted by make_builtin_shape, in the order `cleave --help` lists them.
std::vector<std::string> builtin_shape_names();
bool is_builtin_shape(std::string_view name);

/// Default grid dimensions of a built-in shape (the paper's low resolution for cylinder/abdomen).
Vec3i builtin_default_resolution(std::string_view name);

/// Generates the shape's label volume with corner signed distances (sub-cell surface positions).
/// Throws InputError for an unknown name, non-positive dimensions or cell size, or a grid that
/// would not fit in memory.
LabelVolume make_builtin_shape(std::string_view name, const ShapeResolution& resolution = {});

}  // namespace cleave
