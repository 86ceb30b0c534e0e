#pragma once
// The header of a PLY file (http://paulbourke.net/dataformats/ply/): its encoding, its elements
// with their counts and properties, and where the body starts. Parsed strictly: every header line
// is exactly what its keyword allows, because the malformed headers fuzzing produced made the
// PLY parser cleave used before (assimp's) hang, allocate 64 GB or corrupt the heap.
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace cleave {

enum class PlyEncoding { ascii, binary_little_endian, binary_big_endian };

enum class PlyNumberKind { signed_integer, unsigned_integer, real };

/// A PLY scalar type: char/int8 ... double/float64.
struct PlyScalarType {
  std::size_t bytes = 0;
  PlyNumberKind kind = PlyNumberKind::real;
};

struct PlyProperty {
  std::string name;
  PlyScalarType value;       ///< the scalar, or the type of each list item
  PlyScalarType list_count;  ///< bytes == 0: not a list
  bool is_list() const { return list_count.bytes > 0; }
};

struct PlyElement {
  std::string name;
  std::uint64_t count = 0;  ///< at most the file's size in bytes
  std::vector<PlyProperty> properties;
};

struct PlyHeader {
  PlyEncoding encoding = PlyEncoding::ascii;
  std::vector<PlyElement> elements;
  std::size_t body_offset = 0;  ///< first byte after the "end_header" line
};

/// Parses the header of the PLY file whose whole content is `data` (`file` names it in errors).
/// Throws InputError naming the file unless it starts with "ply", has an "end_header" line, one
/// "format ascii|binary_little_endian|binary_big_endian 1.0" line before the elements, and every
/// other line is a comment, obj_info, element ("element NAME COUNT") or property line ("property
/// TYPE NAME" or "property list COUNT_TYPE ITEM_TYPE NAME") with nothing after its fields; every
/// element with items has properties, and no count exceeds the file's size in bytes (each item
/// takes at least one byte). E.g. "m.ply: malformed PLY header line 'element vertex 1.5'".
PlyHeader parse_ply_header(const std::string& data, const std::string& file);

}  // namespace cleave
