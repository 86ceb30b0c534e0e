#pragma once
// Geometric measures of a triangle surface given its vertex positions: per-vertex normals and
// the enclosed volume.
#include <array>
#include <cstdint>
#include <vector>

#include "cleave/core/types.hpp"

namespace cleave {

/// Unit normal per vertex: the area-weighted mean of the normals of the triangles using it
/// (counter-clockwise triangles give outward normals). A vertex used by no triangle, or whose
/// triangles have no area, gets (0, 0, 0).
std::vector<Vec3> vertex_normals(const std::vector<std::array<std::int32_t, 3>>& triangles,
                                 const std::vector<Vec3>& positions_mm);

/// Volume enclosed by a closed, outward-oriented surface (mm^3), by the divergence theorem:
/// sum over triangles of (a . (b x c)) / 6. Several closed pieces add up.
double enclosed_volume_mm3(const std::vector<std::array<std::int32_t, 3>>& triangles,
                           const std::vector<Vec3>& positions_mm);

}  // namespace cleave
