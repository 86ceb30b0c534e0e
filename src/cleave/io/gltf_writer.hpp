#pragma once
// glTF 2.0 output of a surface mesh as one .gltf JSON file with the binary buffer embedded
// (base64 data URI): POSITION and NORMAL (float VEC3; POSITION with min/max), COLOR_0 (float
// VEC3) when the mesh has colours, each named vertex array as the application-specific float
// SCALAR attribute "_" + upper-case name (e.g. "_TRACTION_KPA"), and uint32 triangle indices.
// Positions stay in mm (asset.extras.length_unit = "mm"); glTF has no per-triangle attributes,
// so triangle arrays are left out (write_ply keeps them).
#include <filesystem>

#include "cleave/surface/surface_mesh.hpp"

namespace cleave {

/// Writes `mesh` to `file` atomically. Throws InputError for a mesh without triangles or a file
/// that cannot be written, ComputeError when a position or normal is not finite.
void write_gltf(const std::filesystem::path& file, const SurfaceMesh& mesh);

}  // namespace cleave
