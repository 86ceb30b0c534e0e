#pragma once
// Reading Object File Format (.off) triangle/polygon meshes. cleave parses OFF itself because
// assimp's OFF importer aborts (ai_assert) on truncated files instead of reporting an error.
#include <filesystem>

#include "cleave/io/surface_mesh_file.hpp"

namespace cleave {

/// Reads an OFF file: optional "OFF"/"COFF"/"NOFF"/"CNOFF"/"STOFF" header line, the counts
/// "vertices faces edges", one vertex per line (x y z, extra values such as colours ignored),
/// one face per line ("n i1 ... in", extra values ignored; polygons are fan-triangulated).
/// '#' starts a comment. Coordinates are multiplied by `scale`.
/// Throws InputError naming the file and the line: truncated file, a malformed number, a face
/// index out of range, a non-finite coordinate.
TriangleMesh read_off_mesh(const std::filesystem::path& file, double scale);

}  // namespace cleave
