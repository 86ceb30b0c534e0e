#pragma once
// PLY (binary little endian) output of a surface mesh: vertex x y z nx ny nz (float), one float
// property per named vertex array, uchar red green blue when the mesh has colours; faces as
// `list uchar int vertex_indices` plus one float property per named triangle array. ParaView,
// MeshLab and Blender read it.
#include <filesystem>

#include "cleave/surface/surface_mesh.hpp"

namespace cleave {

/// Writes `mesh` to `file` atomically. Throws InputError naming the file when it cannot be
/// written, ComputeError when a position or normal is not finite.
void write_ply(const std::filesystem::path& file, const SurfaceMesh& mesh);

}  // namespace cleave
