#include "cleave/io/ply_reader.hpp"

#include <algorithm>
#include <bit>
#include <cstring>
#include <fmt/format.h>
#include <sstream>

#include "cleave/core/error.hpp"
#include "cleave/io/atomic_file.hpp"

namespace cleave {
namespace {

static_assert(std::endian::native == std::endian::little, "the PLY reader copies little-endian bytes");

enum class PlyType { int8, uint8, int16, uint16, int32, uint32, float32, float64 };

struct Property {
  std::string name;
  PlyType type = PlyType::float32;
  bool is_list = false;
  PlyType count_type = PlyType::uint8;
};

struct Element {
  std::string name;
  size_t count = 0;
  std::vector<Property> properties;
};

size_t size_of(PlyType t) {
  switch (t) {
    case PlyType::int8:
    case PlyType::uint8: return 1;
    case PlyType::int16:
    case PlyType::uint16: return 2;
    case PlyType::int32:
    case PlyType::uint32:
    case PlyType::float32: return 4;
    case PlyType::float64: return 8;
  }
  return 0;
}

class Reader {
 public:
  Reader(const std::filesystem::path& file, const std::string& data, size_t pos) : file_(file), data_(data), pos_(pos) {}

  double read(PlyType t) {
    if (pos_ + size_of(t) > data_.size())
      throw InputError(fmt::format("{}: the data ends early at byte {}; expected more vertices or faces", file_.string(),
                                   data_.size()));
    const char* p = data_.data() + pos_;
    pos_ += size_of(t);
    switch (t) {
      case PlyType::int8: return get<std::int8_t>(p);
      case PlyType::uint8: return get<std::uint8_t>(p);
      case PlyType::int16: return get<std::int16_t>(p);
      case PlyType::uint16: return get<std::uint16_t>(p);
      case PlyType::int32: return get<std::int32_t>(p);
      case PlyType::uint32: return get<std::uint32_t>(p);
      case PlyType::float32: return static_cast<double>(get<float>(p));
      case PlyType::float64: return get<double>(p);
    }
    return 0;
  }

 private:
  template <typename T>
  static double get(const char* p) {
    T v;
    std::memcpy(&v, p, sizeof(T));
    return static_cast<double>(v);
  }
  const std::filesystem::path& file_;
  const std::string& data_;
  size_t pos_;
};

PlyType parse_type(const std::filesystem::path& file, const std::string& word) {
  static const std::pair<const char*, PlyType> kTypes[] = {
      {"char", PlyType::int8},     {"int8", PlyType::int8},       {"uchar", PlyType::uint8},
      {"uint8", PlyType::uint8},   {"short", PlyType::int16},     {"int16", PlyType::int16},
      {"ushort", PlyType::uint16}, {"uint16", PlyType::uint16},   {"int", PlyType::int32},
      {"int32", PlyType::int32},   {"uint", PlyType::uint32},     {"uint32", PlyType::uint32},
      {"float", PlyType::float32}, {"float32", PlyType::float32}, {"double", PlyType::float64},
      {"float64", PlyType::float64}};
  for (const auto& [name, type] : kTypes)
    if (word == name) return type;
  throw InputError(fmt::format("{}: unknown PLY property type '{}'", file.string(), word));
}

}  // namespace

SurfaceMesh read_ply(const std::filesystem::path& file) {
  const std::string data = read_file(file);
  const std::string end_marker = "end_header\n";
  const size_t header_end = data.find(end_marker);
  if (data.rfind("ply\n", 0) != 0 || header_end == std::string::npos)
    throw InputError(fmt::format("{}: not a PLY file (expected 'ply' and 'end_header')", file.string()));
  std::istringstream header(data.substr(0, header_end));
  std::vector<Element> elements;
  std::string line;
  while (std::getline(header, line)) {
    std::istringstream words(line);
    std::string keyword;
    words >> keyword;
    if (keyword == "format") {
      std::string format;
      words >> format;
      if (format != "binary_little_endian")
        throw InputError(fmt::format("{}: PLY format '{}'; expected binary_little_endian", file.string(), format));
    } else if (keyword == "element") {
      Element e;
      long long count = -1;
      words >> e.name >> count;
      if (count < 0) throw InputError(fmt::format("{}: PLY element '{}' has no valid count", file.string(), e.name));
      e.count = static_cast<size_t>(count);
      elements.push_back(e);
    } else if (keyword == "property") {
      if (elements.empty()) throw InputError(fmt::format("{}: PLY property before any element", file.string()));
      Property p;
      std::string type;
      words >> type;
      if (type == "list") {
        std::string count_type, item_type;
        words >> count_type >> item_type >> p.name;
        p.is_list = true;
        p.count_type = parse_type(file, count_type);
        p.type = parse_type(file, item_type);
      } else {
        p.type = parse_type(file, type);
        words >> p.name;
      }
      elements.back().properties.push_back(p);
    }
  }

  SurfaceMesh mesh;
  Reader reader(file, data, header_end + end_marker.size());
  for (const Element& e : elements) {
    if (e.name != "vertex" && e.name != "face")
      throw InputError(fmt::format("{}: PLY element '{}'; expected only vertex and face", file.string(), e.name));
    const bool is_vertex = e.name == "vertex";
    if (!is_vertex && (e.properties.empty() || !e.properties.front().is_list))
      throw InputError(fmt::format("{}: PLY faces must start with a vertex index list", file.string()));
    std::vector<NamedScalars>& named = is_vertex ? mesh.vertex_scalars : mesh.triangle_scalars;
    const auto is_builtin = [&](const std::string& n) {
      return is_vertex && (n == "x" || n == "y" || n == "z" || n == "nx" || n == "ny" || n == "nz" || n == "red" ||
                           n == "green" || n == "blue");
    };
    for (const Property& p : e.properties) {
      if (p.is_list && &p != &e.properties.front())
        throw InputError(fmt::format("{}: PLY list property '{}' is not supported here", file.string(), p.name));
      if (!p.is_list && !is_builtin(p.name)) named.push_back(NamedScalars{p.name, std::vector<float>(e.count)});
    }
    const bool has_normals = std::any_of(e.properties.begin(), e.properties.end(), [](const Property& p) { return p.name == "nx"; });
    const bool has_colors = std::any_of(e.properties.begin(), e.properties.end(), [](const Property& p) { return p.name == "red"; });
    if (is_vertex) {
      mesh.positions_mm.assign(e.count, Vec3::Zero());
      if (has_normals) mesh.normals.assign(e.count, Vec3::Zero());
      if (has_colors) mesh.vertex_colors.assign(e.count, Vec3f::Zero());
    } else {
      mesh.triangles.resize(e.count);
    }
    for (size_t i = 0; i < e.count; ++i) {
      size_t named_index = 0;
      for (const Property& p : e.properties) {
        if (p.is_list) {
          const double n = reader.read(p.count_type);
          if (n != 3) throw InputError(fmt::format("{}: face {} has {} vertices; expected triangles", file.string(), i, n));
          for (size_t k = 0; k < 3; ++k) {
            const double v = reader.read(p.type);
            if (v < 0 || v >= static_cast<double>(mesh.positions_mm.size()))
              throw InputError(fmt::format("{}: face {} uses vertex {}; expected 0..{}", file.string(), i, v,
                                           mesh.positions_mm.size()));
            mesh.triangles[i][k] = static_cast<std::int32_t>(v);
          }
          continue;
        }
        const double v = reader.read(p.type);
        const std::string& n = p.name;
        if (!is_builtin(n)) named[named_index++].values[i] = static_cast<float>(v);
        else if (n == "x" || n == "y" || n == "z") mesh.positions_mm[i][n[0] - 'x'] = v;
        else if (n == "nx" || n == "ny" || n == "nz") mesh.normals[i][n[1] - 'x'] = v;
        else {
          const int channel = n == "red" ? 0 : (n == "green" ? 1 : 2);
          mesh.vertex_colors[i][channel] = static_cast<float>(p.type == PlyType::uint8 ? v / 255.0 : v);
        }
      }
    }
  }
  return mesh;
}

}  // namespace cleave
