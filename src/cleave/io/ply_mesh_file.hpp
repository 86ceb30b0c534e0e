#pragma once
// Reading a triangle surface mesh from a PLY file (ASCII, binary little- or big-endian) with
// cleave's own parser. assimp's PLY importer corrupted the heap on malformed input under fuzzing
// even behind a strict precheck (the uninstrumented library writes into freed memory; ASan only
// noticed later, at an unrelated free), so PLY no longer goes through it.
#include <filesystem>

#include "cleave/io/surface_mesh_file.hpp"

namespace cleave {

/// Reads the "vertex" element's x, y, z (any scalar type) and the "face" element's
/// "vertex_indices" (or "vertex_index") lists; other elements and properties are read and
/// skipped. Faces with fewer than 3 corners are ignored, polygons fan-triangulated. Coordinates
/// are multiplied by `scale`.
/// Throws InputError naming the file and the problem: a malformed header (parse_ply_header), an
/// ASCII value that is not a number of its property's type, an item line with too few or too many
/// values, a list count its line or the file cannot hold, truncated data, a face index outside the
/// file's vertices, a non-finite coordinate, no vertex element with x, y and z.
TriangleMesh read_ply_mesh(const std::filesystem::path& file, double scale);

}  // namespace cleave
