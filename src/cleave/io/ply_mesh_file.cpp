#include "cleave/io/ply_mesh_file.hpp"

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstdlib>
#include <fmt/format.h>
#include <limits>
#include <string_view>
#include <vector>

#include "cleave/core/error.hpp"
#include "cleave/io/atomic_file.hpp"
#include "cleave/io/json_fields.hpp"
#include "cleave/io/ply_header.hpp"

namespace cleave {
namespace {

std::string shown(std::string_view token) { return utf8_prefix(utf8_sanitized(std::string(token)), 40); }

/// Whether an ASCII token is a number of the given kind: an integer (optional sign, at most 18
/// digits) or a finite real that strtod reads whole.
bool is_ascii_number(std::string_view token, PlyNumberKind kind) {
  if (kind != PlyNumberKind::real) {
    const std::size_t digits_from = token.empty() || (token[0] != '-' && token[0] != '+') ? 0 : 1;
    const std::string_view digits = token.substr(digits_from);
    return !digits.empty() && digits.size() <= 18 &&
           std::all_of(digits.begin(), digits.end(), [](char c) { return c >= '0' && c <= '9'; });
  }
  const std::string text(token);
  char* end = nullptr;
  const double value = std::strtod(text.c_str(), &end);
  return !text.empty() && end == text.c_str() + text.size() && std::isfinite(value);
}

/// The values of an ASCII body: one item per line (blank lines skipped), values separated by
/// blanks, every value a number of its property's type, no more values than the item's properties.
class AsciiBody {
 public:
  AsciiBody(const std::string& data, std::size_t offset, const std::string& file) : data_(data), pos_(offset), file_(file) {}

  void begin_item(const PlyElement& e, std::uint64_t item) {
    element_ = &e;
    item_ = item;
    line_ = {};
    at_ = 0;
    while (line_.find_first_not_of(" \t\r") == std::string_view::npos) {
      if (pos_ >= data_.size())
        throw InputError(fmt::format("{}: the ASCII data ends while reading element '{}' {} of {} (truncated?)", file_,
                                     e.name, item, e.count));
      const std::size_t eol = std::min(data_.find('\n', pos_), data_.size());
      line_ = std::string_view(data_).substr(pos_, eol - pos_);
      pos_ = eol + 1;
    }
  }

  double scalar(const PlyScalarType& type) {
    const std::string_view token = next_token();
    if (token.empty())
      throw InputError(fmt::format("{}: element '{}' {} has fewer values than its {} properties", file_, element_->name,
                                   item_, element_->properties.size()));
    return number(token, type);
  }

  /// A list's item count: a whole number no larger than the values left on the line can hold.
  std::uint64_t list_count(const PlyProperty&) {
    const std::string_view token = next_token();
    if (token.empty())
      throw InputError(fmt::format("{}: element '{}' {} has fewer values than its {} properties", file_, element_->name,
                                   item_, element_->properties.size()));
    const bool whole = token.size() <= 9 && std::all_of(token.begin(), token.end(), [](char c) { return c >= '0' && c <= '9'; });
    const std::uint64_t n = whole ? std::strtoull(std::string(token).c_str(), nullptr, 10) : 0;
    if (!whole || n > (line_.size() - at_ + 1) / 2)
      throw InputError(fmt::format("{}: element '{}' {} has a list of '{}' items; expected a count its line can hold",
                                   file_, element_->name, item_, shown(token)));
    list_size_ = n;
    return n;
  }

  double list_value(const PlyScalarType& type) {
    const std::string_view token = next_token();
    if (token.empty())
      throw InputError(fmt::format("{}: element '{}' {} has a list of {} items but fewer values", file_, element_->name,
                                   item_, list_size_));
    return number(token, type);
  }

  void end_item() {
    const std::string_view extra = next_token();
    if (!extra.empty())
      throw InputError(fmt::format("{}: element '{}' {} has more values than its {} properties (from '{}')", file_,
                                   element_->name, item_, element_->properties.size(), shown(extra)));
  }

 private:
  std::string_view next_token() {
    while (at_ < line_.size() && (line_[at_] == ' ' || line_[at_] == '\t' || line_[at_] == '\r')) ++at_;
    const std::size_t begin = at_;
    while (at_ < line_.size() && line_[at_] != ' ' && line_[at_] != '\t' && line_[at_] != '\r') ++at_;
    return line_.substr(begin, at_ - begin);
  }

  double number(std::string_view token, const PlyScalarType& type) const {
    if (!is_ascii_number(token, type.kind))
      throw InputError(fmt::format("{}: element '{}' {} has the value '{}'; expected a number", file_, element_->name,
                                   item_, shown(token)));
    const std::string text(token);
    if (type.kind == PlyNumberKind::real) return std::strtod(text.c_str(), nullptr);
    return static_cast<double>(std::strtoll(text.c_str(), nullptr, 10));
  }

  const std::string& data_;
  std::size_t pos_;
  const std::string& file_;
  const PlyElement* element_ = nullptr;
  std::uint64_t item_ = 0;
  std::string_view line_;
  std::size_t at_ = 0;
  std::uint64_t list_size_ = 0;
};

/// The values of a binary body, little- or big-endian, bounds-checked against the file's size.
class BinaryBody {
 public:
  BinaryBody(const std::string& data, std::size_t offset, bool big_endian, const std::string& file)
      : data_(data), pos_(offset), big_endian_(big_endian), file_(file) {}

  void begin_item(const PlyElement& e, std::uint64_t item) {
    element_ = &e;
    item_ = item;
  }
  double scalar(const PlyScalarType& type) { return value(type); }
  double list_value(const PlyScalarType& type) { return value(type); }
  void end_item() {}

  /// A list's item count (a negative signed count reads huge); its items must fit in the file.
  std::uint64_t list_count(const PlyProperty& p) {
    const std::uint64_t n = raw(p.list_count.bytes);
    const bool negative = p.list_count.kind == PlyNumberKind::signed_integer &&
                          (n >> (8 * p.list_count.bytes - 1)) != 0;
    std::uint64_t bytes = 0;
    if (negative || __builtin_mul_overflow(n, p.value.bytes, &bytes) || bytes > data_.size() - pos_) truncated();
    return n;
  }

 private:
  [[noreturn]] void truncated() const {
    throw InputError(fmt::format("{}: the binary data ends at byte {} while reading element '{}' {} of {} (truncated?)",
                                 file_, data_.size(), element_->name, item_, element_->count));
  }

  std::uint64_t raw(std::size_t bytes) {
    if (bytes > data_.size() - pos_) truncated();
    std::uint64_t v = 0;
    for (std::size_t k = 0; k < bytes; ++k)
      v |= std::uint64_t{static_cast<unsigned char>(data_[pos_ + (big_endian_ ? bytes - 1 - k : k)])} << (8 * k);
    pos_ += bytes;
    return v;
  }

  double value(const PlyScalarType& type) {
    const std::uint64_t v = raw(type.bytes);
    switch (type.kind) {
      case PlyNumberKind::real:
        return type.bytes == 4 ? static_cast<double>(std::bit_cast<float>(static_cast<std::uint32_t>(v)))
                               : std::bit_cast<double>(v);
      case PlyNumberKind::signed_integer: {
        const unsigned shift = static_cast<unsigned>(64 - 8 * type.bytes);
        return static_cast<double>(static_cast<std::int64_t>(v << shift) >> shift);
      }
      case PlyNumberKind::unsigned_integer:
        return static_cast<double>(v);
    }
    return 0;
  }

  const std::string& data_;
  std::size_t pos_;
  bool big_endian_;
  const std::string& file_;
  const PlyElement* element_ = nullptr;
  std::uint64_t item_ = 0;
};

/// Where the mesh's data sits in the header's elements.
struct MeshLayout {
  const PlyElement* vertex = nullptr;
  std::array<std::size_t, 3> xyz{};  ///< property indices of x, y, z in the vertex element
  const PlyElement* face = nullptr;  ///< null: no faces
  std::size_t corners = 0;           ///< property index of the face's vertex index list
};

MeshLayout mesh_layout(const PlyHeader& header, const std::string& f) {
  MeshLayout layout;
  for (const PlyElement& e : header.elements) {
    if (e.name == "vertex" && layout.vertex == nullptr) layout.vertex = &e;
    if (e.name == "face" && layout.face == nullptr) layout.face = &e;
  }
  if (layout.vertex == nullptr)
    throw InputError(fmt::format("{}: the PLY file has no 'vertex' element; expected one with properties x, y and z", f));
  const std::vector<PlyProperty>& vertex_properties = layout.vertex->properties;
  for (std::size_t axis = 0; axis < 3; ++axis) {
    const std::string name(1, "xyz"[axis]);
    const auto it = std::find_if(vertex_properties.begin(), vertex_properties.end(),
                                 [&](const PlyProperty& p) { return p.name == name && !p.is_list(); });
    if (it == vertex_properties.end())
      throw InputError(fmt::format("{}: PLY element 'vertex' has no scalar property '{}'; expected x, y and z", f, name));
    layout.xyz[axis] = static_cast<std::size_t>(it - vertex_properties.begin());
  }
  if (layout.face != nullptr) {
    const std::vector<PlyProperty>& face_properties = layout.face->properties;
    const auto it = std::find_if(face_properties.begin(), face_properties.end(), [](const PlyProperty& p) {
      return p.is_list() && (p.name == "vertex_indices" || p.name == "vertex_index");
    });
    if (it == face_properties.end())
      throw InputError(fmt::format("{}: PLY element 'face' has no list property 'vertex_indices' (or 'vertex_index')", f));
    layout.corners = static_cast<std::size_t>(it - face_properties.begin());
  }
  return layout;
}

template <class Body>
TriangleMesh read_elements(Body& body, const PlyHeader& header, double scale, const std::string& f) {
  const MeshLayout layout = mesh_layout(header, f);
  const std::uint64_t vertex_count = layout.vertex->count;
  if (vertex_count > static_cast<std::uint64_t>(std::numeric_limits<int>::max()))
    throw InputError(fmt::format("{}: more than 2^31 vertices", f));
  TriangleMesh mesh;
  mesh.vertices_mm.reserve(static_cast<std::size_t>(vertex_count));
  std::vector<int> corners;
  for (const PlyElement& e : header.elements) {
    const bool is_vertex = &e == layout.vertex, is_face = &e == layout.face;
    for (std::uint64_t item = 0; item < e.count; ++item) {
      body.begin_item(e, item);
      Vec3 position = Vec3::Zero();
      corners.clear();
      for (std::size_t k = 0; k < e.properties.size(); ++k) {
        const PlyProperty& p = e.properties[k];
        if (!p.is_list()) {
          const double value = body.scalar(p.value);
          if (is_vertex)
            for (std::size_t axis = 0; axis < 3; ++axis)
              if (layout.xyz[axis] == k) position[static_cast<Eigen::Index>(axis)] = value;
          continue;
        }
        const std::uint64_t n = body.list_count(p);
        const bool keep = is_face && k == layout.corners;
        for (std::uint64_t j = 0; j < n; ++j) {
          const double value = body.list_value(p.value);
          if (!keep) continue;
          if (!(value >= 0 && value < static_cast<double>(vertex_count) && value == std::floor(value)))
            throw InputError(fmt::format("{}: element 'face' {} refers to vertex {}; the file has {} vertices", f, item,
                                         value, vertex_count));
          corners.push_back(static_cast<int>(value));
        }
      }
      body.end_item();
      if (is_vertex) {
        if (!position.allFinite())
          throw InputError(fmt::format("{}: vertex {} is ({}, {}, {}); expected finite coordinates", f, item, position.x(),
                                       position.y(), position.z()));
        mesh.vertices_mm.push_back(scale * position);
      }
      for (std::size_t c = 2; c < corners.size(); ++c)  // fewer than 3 corners: a point or line, ignored
        mesh.triangles.push_back({corners[0], corners[c - 1], corners[c]});
    }
  }
  return mesh;
}

}  // namespace

TriangleMesh read_ply_mesh(const std::filesystem::path& file, double scale) {
  const std::string data = read_file(file);
  const std::string f = file.string();
  const PlyHeader header = parse_ply_header(data, f);
  if (header.encoding == PlyEncoding::ascii) {
    AsciiBody body(data, header.body_offset, f);
    return read_elements(body, header, scale, f);
  }
  BinaryBody body(data, header.body_offset, header.encoding == PlyEncoding::binary_big_endian, f);
  return read_elements(body, header, scale, f);
}

}  // namespace cleave
