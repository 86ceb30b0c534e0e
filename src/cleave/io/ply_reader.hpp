#pragma once
// Reads the binary little-endian PLY files write_ply produces (and any PLY whose vertex
// properties are float/double/uchar scalars and whose faces are triangles given as
// `list uchar int|uint vertex_indices` followed by float scalars): the round trip of write_ply.
// Vertex properties x y z, nx ny nz and red green blue fill positions, normals and colours;
// every other vertex or face property becomes a named array.
#include <filesystem>

#include "cleave/surface/surface_mesh.hpp"

namespace cleave {

/// Throws InputError naming the file and the problem (missing, not PLY, ASCII or big endian,
/// unsupported property, truncated data, a face that is not a triangle, an index out of range).
SurfaceMesh read_ply(const std::filesystem::path& file);

}  // namespace cleave
