#include "cleave/io/ply_precheck.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdlib>
#include <cstdint>
#include <fmt/format.h>
#include <sstream>
#include <string>
#include <string_view>
#include <vector>

#include "cleave/core/error.hpp"
#include "cleave/io/atomic_file.hpp"
#include "cleave/io/json_fields.hpp"

namespace cleave {
namespace {

/// Bytes of a PLY scalar type name, 0 when unknown.
std::size_t type_bytes(const std::string& type) {
  if (type == "char" || type == "uchar" || type == "int8" || type == "uint8") return 1;
  if (type == "short" || type == "ushort" || type == "int16" || type == "uint16") return 2;
  if (type == "int" || type == "uint" || type == "float" || type == "int32" || type == "uint32" || type == "float32")
    return 4;
  if (type == "double" || type == "float64") return 8;
  return 0;
}

bool is_integer_type(const std::string& type) {
  return type_bytes(type) > 0 && type != "float" && type != "float32" && type != "double" && type != "float64";
}

/// Element names are words ("vertex", "face"); assimp reads leading digits of a name as a count.
bool is_identifier(const std::string& name) {
  if (name.empty() || !(std::isalpha(static_cast<unsigned char>(name[0])) || name[0] == '_')) return false;
  return std::all_of(name.begin(), name.end(),
                     [](char c) { return std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '-'; });
}

struct PlyProperty {
  std::string name;
  std::size_t bytes = 0;        ///< scalar size, or the size of one list item
  std::size_t count_bytes = 0;  ///< size of the list count (0: not a list)
  bool integer = false;         ///< the scalar (or list item) type is an integer type
};

/// Whether an ASCII token is a number of the property's type: an integer (optional sign, digits,
/// at most 18 of them) or a finite real that strtod reads whole.
bool is_ascii_number(std::string_view token, bool integer) {
  if (integer) {
    const std::size_t digits_from = token.empty() || (token[0] != '-' && token[0] != '+') ? 0 : 1;
    const std::string_view digits = token.substr(digits_from);
    return !digits.empty() && digits.size() <= 18 && std::all_of(digits.begin(), digits.end(), [](char c) { return c >= '0' && c <= '9'; });
  }
  const std::string text(token);
  char* end = nullptr;
  const double value = std::strtod(text.c_str(), &end);
  return !text.empty() && end == text.c_str() + text.size() && std::isfinite(value);
}

/// The vertex index lists of faces, by the names PLY writers use.
bool is_vertex_index_list(const PlyProperty& p) { return p.count_bytes > 0 && (p.name == "vertex_indices" || p.name == "vertex_index"); }

struct PlyElement {
  std::string name;
  std::uint64_t count = 0;
  std::vector<PlyProperty> properties;
};

/// Reads an unsigned list count of `bytes` bytes at `p` (a negative signed count reads huge).
std::uint64_t list_count(const unsigned char* p, std::size_t bytes, bool big_endian) {
  std::uint64_t v = 0;
  for (std::size_t k = 0; k < bytes; ++k) v |= std::uint64_t{p[big_endian ? bytes - 1 - k : k]} << (8 * k);
  return v;
}

/// Walks the ASCII body as assimp reads it, one item per line: every value must be there and be a
/// number of its property's type, no line may hold more values than its element's properties,
/// every list count must be a whole number no larger than the tokens left on its line (assimp
/// allocated a list of 3444...4 items; found by fuzz_mesh_ply), and a face's vertex indices must
/// name vertices of the file. assimp is left only well-formed bodies: its own error paths on
/// malformed ones corrupted the heap (an ASan quarantine check failed inside assimp's importer
/// after 73 min of fuzz_mesh_ply).
void require_ascii_items_fit(const std::string& data, std::size_t pos, const std::vector<PlyElement>& elements,
                             const std::string& f) {
  std::uint64_t vertices = 0;
  for (const PlyElement& e : elements)
    if (e.name == "vertex") vertices = e.count;
  const auto not_a_number = [&](const PlyElement& e, std::uint64_t item, std::string_view token) {
    throw InputError(fmt::format("{}: element '{}' {} has the value '{}'; expected a number", f, e.name, item,
                                 utf8_prefix(utf8_sanitized(std::string(token)), 40)));
  };
  for (const PlyElement& e : elements) {
    for (std::uint64_t item = 0; item < e.count; ++item) {
      // the item's line (blank lines skipped)
      std::string_view line;
      while (line.find_first_not_of(" \t\r") == std::string_view::npos) {
        if (pos >= data.size())
          throw InputError(fmt::format("{}: the ASCII data ends while reading element '{}' {} of {} (truncated?)", f,
                                       e.name, item, e.count));
        const std::size_t eol = std::min(data.find('\n', pos), data.size());
        line = std::string_view(data).substr(pos, eol - pos);
        pos = eol + 1;
      }
      std::size_t at = 0;
      const auto next_token = [&]() -> std::string_view {
        while (at < line.size() && (line[at] == ' ' || line[at] == '\t' || line[at] == '\r')) ++at;
        const std::size_t begin = at;
        while (at < line.size() && line[at] != ' ' && line[at] != '\t' && line[at] != '\r') ++at;
        return line.substr(begin, at - begin);
      };
      for (const PlyProperty& p : e.properties) {
        const std::string_view token = next_token();
        if (token.empty())
          throw InputError(fmt::format("{}: element '{}' {} has fewer values than its {} properties", f, e.name, item,
                                       e.properties.size()));
        if (p.count_bytes == 0) {
          if (!is_ascii_number(token, p.integer)) not_a_number(e, item, token);
          continue;
        }
        const bool whole = std::all_of(token.begin(), token.end(), [](char c) { return c >= '0' && c <= '9'; });
        const std::uint64_t n = whole && token.size() <= 9 ? std::stoull(std::string(token)) : 0;
        if (!whole || token.size() > 9 || n > (line.size() - at + 1) / 2)
          throw InputError(fmt::format("{}: element '{}' {} has a list of '{}' items; expected a count its line can hold",
                                       f, e.name, item, utf8_prefix(utf8_sanitized(std::string(token)), 40)));
        const bool indices = e.name == "face" && is_vertex_index_list(p);
        for (std::uint64_t k = 0; k < n; ++k) {
          const std::string_view value = next_token();
          if (value.empty())
            throw InputError(fmt::format("{}: element '{}' {} has a list of {} items but fewer values", f, e.name, item, n));
          if (!is_ascii_number(value, p.integer)) not_a_number(e, item, value);
          if (indices && (value[0] == '-' || std::stoull(std::string(value[0] == '+' ? value.substr(1) : value)) >= vertices))
            throw InputError(fmt::format("{}: element 'face' {} refers to vertex {}; the file has {} vertices", f, item,
                                         utf8_prefix(std::string(value), 40), vertices));
        }
      }
      const std::string_view extra = next_token();
      if (!extra.empty())
        throw InputError(fmt::format("{}: element '{}' {} has more values than its {} properties (from '{}')", f, e.name,
                                     item, e.properties.size(), utf8_prefix(utf8_sanitized(std::string(extra)), 40)));
    }
  }
}

}  // namespace

void require_well_formed_ply(const std::filesystem::path& file) {
  const std::string data = read_file(file);
  const std::string f = file.string();
  // The header ends at a line that is exactly "end_header" ("end_headerint" made assimp hang in
  // read(); found by fuzz_mesh_ply).
  std::size_t header_end = std::string::npos;
  for (std::size_t at = data.find("\nend_header"); at != std::string::npos; at = data.find("\nend_header", at + 1)) {
    const std::size_t after = at + 11;
    if (after < data.size() && (data[after] == '\n' || (data[after] == '\r' && after + 1 < data.size() && data[after + 1] == '\n'))) {
      header_end = at + 1;
      break;
    }
  }
  if (data.rfind("ply", 0) != 0 || header_end == std::string::npos)
    throw InputError(fmt::format("{}: not a PLY file (expected 'ply' first and an 'end_header' line)", f));
  const auto malformed = [&](const std::string& line) {
    throw InputError(fmt::format("{}: malformed PLY header line '{}'", f, utf8_prefix(utf8_sanitized(line), 80)));
  };
  std::size_t pos = data.find('\n', header_end);
  pos = pos == std::string::npos ? data.size() : pos + 1;
  std::istringstream header(data.substr(0, header_end));
  bool binary = false, big_endian = false, format_seen = false;
  std::vector<PlyElement> elements;
  // Each line must be exactly what its keyword allows: nothing missing, nothing after it (assimp's
  // error paths on such headers corrupted the heap under fuzzing).
  const auto nothing_after = [](std::istringstream& words) {
    std::string extra;
    return !(words >> extra);
  };
  for (std::string line; std::getline(header, line);) {
    std::istringstream words(line);
    std::string keyword;
    words >> keyword;
    if (keyword.empty() || keyword == "ply" || keyword == "comment" || keyword == "obj_info") {
      continue;
    } else if (keyword == "format") {
      std::string format, version;
      words >> format >> version;
      // assimp reads an unknown format as ASCII and misparses the rest (a 64 GB allocation found by fuzz_mesh_ply)
      if ((format != "ascii" && format != "binary_little_endian" && format != "binary_big_endian") || version != "1.0" ||
          format_seen || !elements.empty() || !nothing_after(words))
        malformed(line);
      format_seen = true;
      binary = format == "binary_little_endian" || format == "binary_big_endian";
      big_endian = format == "binary_big_endian";
    } else if (keyword == "element") {
      PlyElement e;
      std::string count;
      words >> e.name >> count;
      const bool whole = !count.empty() && count.size() <= 18 &&
                         std::all_of(count.begin(), count.end(), [](char c) { return c >= '0' && c <= '9'; });
      if (!whole || !is_identifier(e.name) || !nothing_after(words)) malformed(line);
      e.count = std::stoull(count);
      elements.push_back(e);
    } else if (keyword == "property") {
      if (elements.empty()) malformed(line);
      std::string type;
      words >> type;
      PlyProperty p;
      if (type == "list") {
        std::string count_type, item_type;
        words >> count_type >> item_type >> p.name;
        p.count_bytes = type_bytes(count_type);
        p.bytes = type_bytes(item_type);
        p.integer = is_integer_type(item_type);
        if (p.count_bytes == 0 || p.bytes == 0 || !is_integer_type(count_type)) malformed(line);
      } else {
        words >> p.name;
        p.bytes = type_bytes(type);
        p.integer = is_integer_type(type);
        if (p.bytes == 0) malformed(line);
      }
      if (p.name.empty() || !nothing_after(words)) malformed(line);
      elements.back().properties.push_back(p);
    } else {
      malformed(line);  // assimp loops on some unknown lines (a hang found by fuzz_mesh_ply)
    }
  }
  if (!format_seen)
    throw InputError(fmt::format("{}: the PLY header has no format line; expected 'format ascii 1.0', "
                                 "'format binary_little_endian 1.0' or 'format binary_big_endian 1.0' before the elements",
                                 f));
  // Every item takes at least one byte in either encoding: a count beyond the file's size is a
  // corrupt header, and assimp would loop over it (an item without properties takes none).
  std::uint64_t items = 0;
  for (const PlyElement& e : elements) {
    if (e.count > 0 && e.properties.empty())
      throw InputError(fmt::format("{}: PLY element '{}' has {} items but no properties", f, e.name, e.count));
    items += e.count;  // each count < file size after the check below, so no overflow
    if (e.count > data.size() || items > data.size())
      throw InputError(fmt::format("{}: PLY header declares {} '{}' items; the file has only {} bytes", f, e.count,
                                   e.name, data.size()));
  }
  if (!binary) {
    require_ascii_items_fit(data, pos, elements, f);
    return;
  }
  const auto truncated = [&](const PlyElement& e, std::uint64_t item) {
    throw InputError(fmt::format("{}: the binary data ends at byte {} while reading element '{}' {} of {} (truncated?)",
                                 f, data.size(), e.name, item, e.count));
  };
  const std::size_t size = data.size();
  for (const PlyElement& e : elements) {
    // Elements without list properties have a fixed size: check them in one step.
    std::uint64_t fixed = 0;
    bool has_list = false;
    for (const PlyProperty& p : e.properties) {
      fixed += p.bytes;
      has_list = has_list || p.count_bytes > 0;
    }
    if (!has_list) {
      std::uint64_t bytes = 0;
      if (__builtin_mul_overflow(fixed, e.count, &bytes) || bytes > size - pos) truncated(e, (size - pos) / std::max<std::uint64_t>(fixed, 1));
      pos += static_cast<std::size_t>(bytes);
      continue;
    }
    for (std::uint64_t item = 0; item < e.count; ++item) {
      for (const PlyProperty& p : e.properties) {
        if (p.count_bytes == 0) {
          if (p.bytes > size - pos) truncated(e, item);
          pos += p.bytes;
          continue;
        }
        if (p.count_bytes > size - pos) truncated(e, item);
        const std::uint64_t n = list_count(reinterpret_cast<const unsigned char*>(data.data() + pos), p.count_bytes, big_endian);
        pos += p.count_bytes;
        std::uint64_t bytes = 0;
        if (__builtin_mul_overflow(n, p.bytes, &bytes) || bytes > size - pos) truncated(e, item);
        pos += static_cast<std::size_t>(bytes);
      }
    }
  }
}

}  // namespace cleave
