#pragma once
// A guard in front of assimp's PLY importer, which reads past the end of its buffer on a PLY
// without "end_header" and on a binary PLY whose header declares more data than the file holds
// (segmentation faults found by fuzz_mesh_ply and by the bad-input catalogue).
#include <filesystem>

namespace cleave {

/// Throws InputError naming `file` unless it starts with "ply", has an "end_header" line, and
/// every line of its header is a well-formed format, comment, obj_info, element or property
/// line (known scalar types, counts from 0 that fit in the file, elements with properties). For a binary PLY (little- or big-endian) it also walks the declared elements, list
/// counts included, and refuses data shorter than declared, e.g. "body.ply: the binary data ends
/// at byte 312 while reading element 'vertex' 2 of 8 (truncated?)". An ASCII body is walked line
/// by line: every value a number of its property's type, no more values than properties, list
/// counts that fit, face vertex indices inside the file's vertices, so that assimp only ever
/// parses well-formed bodies (its error paths corrupted the heap under fuzzing).
void require_well_formed_ply(const std::filesystem::path& file);

}  // namespace cleave
