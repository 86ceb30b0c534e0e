#include "cleave/io/ply_header.hpp"

#include <algorithm>
#include <cctype>
#include <fmt/format.h>
#include <sstream>

#include "cleave/core/error.hpp"
#include "cleave/io/json_fields.hpp"

namespace cleave {
namespace {

/// A PLY scalar type by name; bytes == 0 when the name is unknown.
PlyScalarType scalar_type(const std::string& name) {
  using K = PlyNumberKind;
  if (name == "char" || name == "int8") return {1, K::signed_integer};
  if (name == "uchar" || name == "uint8") return {1, K::unsigned_integer};
  if (name == "short" || name == "int16") return {2, K::signed_integer};
  if (name == "ushort" || name == "uint16") return {2, K::unsigned_integer};
  if (name == "int" || name == "int32") return {4, K::signed_integer};
  if (name == "uint" || name == "uint32") return {4, K::unsigned_integer};
  if (name == "float" || name == "float32") return {4, K::real};
  if (name == "double" || name == "float64") return {8, K::real};
  return {};
}

/// Element names are words ("vertex", "face"); digits first read as a count in some parsers.
bool is_identifier(const std::string& name) {
  if (name.empty() || !(std::isalpha(static_cast<unsigned char>(name[0])) || name[0] == '_')) return false;
  return std::all_of(name.begin(), name.end(),
                     [](char c) { return std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '-'; });
}

/// The offset of the "end_header" line (a line that is exactly that, LF or CRLF), npos if none.
std::size_t end_header_line(const std::string& data) {
  for (std::size_t at = data.find("\nend_header"); at != std::string::npos; at = data.find("\nend_header", at + 1)) {
    const std::size_t after = at + 11;
    if (after < data.size() &&
        (data[after] == '\n' || (data[after] == '\r' && after + 1 < data.size() && data[after + 1] == '\n')))
      return at + 1;
  }
  return std::string::npos;
}

}  // namespace

PlyHeader parse_ply_header(const std::string& data, const std::string& f) {
  const std::size_t header_end = end_header_line(data);
  if (data.rfind("ply", 0) != 0 || header_end == std::string::npos)
    throw InputError(fmt::format("{}: not a PLY file (expected 'ply' first and an 'end_header' line)", f));
  const auto malformed = [&](const std::string& line) {
    throw InputError(fmt::format("{}: malformed PLY header line '{}'", f, utf8_prefix(utf8_sanitized(line), 80)));
  };
  PlyHeader header;
  const std::size_t eol = data.find('\n', header_end);
  header.body_offset = eol == std::string::npos ? data.size() : eol + 1;
  const auto nothing_after = [](std::istringstream& words) {
    std::string extra;
    return !(words >> extra);
  };
  std::istringstream lines(data.substr(0, header_end));
  bool format_seen = false;
  for (std::string line; std::getline(lines, line);) {
    std::istringstream words(line);
    std::string keyword;
    words >> keyword;
    if (keyword.empty() || keyword == "ply" || keyword == "comment" || keyword == "obj_info") continue;
    if (keyword == "format") {
      std::string format, version;
      words >> format >> version;
      if (format == "ascii") header.encoding = PlyEncoding::ascii;
      else if (format == "binary_little_endian") header.encoding = PlyEncoding::binary_little_endian;
      else if (format == "binary_big_endian") header.encoding = PlyEncoding::binary_big_endian;
      else malformed(line);
      if (version != "1.0" || format_seen || !header.elements.empty() || !nothing_after(words)) malformed(line);
      format_seen = true;
    } else if (keyword == "element") {
      PlyElement e;
      std::string count;
      words >> e.name >> count;
      const bool whole = !count.empty() && count.size() <= 18 &&
                         std::all_of(count.begin(), count.end(), [](char c) { return c >= '0' && c <= '9'; });
      if (!whole || !is_identifier(e.name) || !nothing_after(words)) malformed(line);
      e.count = std::stoull(count);
      header.elements.push_back(e);
    } else if (keyword == "property") {
      if (header.elements.empty()) malformed(line);
      std::string type;
      words >> type;
      PlyProperty p;
      if (type == "list") {
        std::string count_type, item_type;
        words >> count_type >> item_type >> p.name;
        p.list_count = scalar_type(count_type);
        p.value = scalar_type(item_type);
        if (p.list_count.bytes == 0 || p.list_count.kind == PlyNumberKind::real || p.value.bytes == 0) malformed(line);
      } else {
        words >> p.name;
        p.value = scalar_type(type);
        if (p.value.bytes == 0) malformed(line);
      }
      if (p.name.empty() || !nothing_after(words)) malformed(line);
      header.elements.back().properties.push_back(p);
    } else {
      malformed(line);
    }
  }
  if (!format_seen)
    throw InputError(fmt::format("{}: the PLY header has no format line; expected 'format ascii 1.0', "
                                 "'format binary_little_endian 1.0' or 'format binary_big_endian 1.0' before the elements",
                                 f));
  std::uint64_t items = 0;
  for (const PlyElement& e : header.elements) {
    if (e.count > 0 && e.properties.empty())
      throw InputError(fmt::format("{}: PLY element '{}' has {} items but no properties", f, e.name, e.count));
    items += e.count;  // each count <= the file's size after the check below, so no overflow
    if (e.count > data.size() || items > data.size())
      throw InputError(fmt::format("{}: PLY header declares {} '{}' items; the file has only {} bytes", f, e.count,
                                   e.name, data.size()));
  }
  return header;
}

}  // namespace cleave
