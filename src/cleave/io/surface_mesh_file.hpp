#pragma once
// Reading a triangle surface mesh from OBJ or STL (ASCII or binary) with assimp, or from OFF and
// PLY (ASCII, binary little- or big-endian) with cleave's own parsers (off_mesh_file.hpp,
// ply_mesh_file.hpp: assimp aborts on truncated OFF and corrupted the heap on malformed PLY).
#include <array>
#include <filesystem>
#include <vector>

#include "cleave/core/types.hpp"

namespace cleave {

/// An indexed triangle mesh. Orientation and closedness are not required here (the voxelizer
/// decides inside from the whole surface).
struct TriangleMesh {
  std::vector<Vec3> vertices_mm;               ///< positions (mm, already scaled)
  std::vector<std::array<int, 3>> triangles;   ///< vertex indices; polygons are triangulated
};

/// Reads `file` (format from its extension/content), triangulates polygons, merges identical
/// vertices, bakes node transforms, and multiplies every coordinate by `scale` (e.g. 1750 for a
/// mesh of height 1 that should be 1750 mm tall). Points and lines are ignored.
/// Throws InputError naming the file and the problem: missing file, a file assimp cannot parse
/// (malformed or truncated), no triangles, a non-finite coordinate (e.g. "vertex 3 is (nan, 0, 1)"),
/// or a scale that is not positive and finite.
TriangleMesh read_surface_mesh(const std::filesystem::path& file, double scale);

}  // namespace cleave
