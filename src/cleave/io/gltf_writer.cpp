#include "cleave/io/gltf_writer.hpp"

#include <algorithm>
#include <bit>
#include <cctype>
#include <cstring>
#include <limits>
#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "cleave/core/error.hpp"
#include "cleave/io/atomic_file.hpp"

namespace cleave {
namespace {

static_assert(std::endian::native == std::endian::little, "glTF buffers are little endian");

constexpr int kFloat = 5126;         // glTF componentType FLOAT
constexpr int kUnsignedInt = 5125;   // glTF componentType UNSIGNED_INT
constexpr int kArrayBuffer = 34962;  // bufferView target for vertex attributes
constexpr int kElementArrayBuffer = 34963;
constexpr int kTriangles = 4;        // primitive mode

std::string base64(const std::string& bytes) {
  static constexpr char kAlphabet[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  out.reserve((bytes.size() + 2) / 3 * 4);
  for (size_t i = 0; i < bytes.size(); i += 3) {
    const size_t n = std::min<size_t>(3, bytes.size() - i);
    std::uint32_t block = 0;
    for (size_t k = 0; k < 3; ++k)
      block = (block << 8) | (k < n ? static_cast<unsigned char>(bytes[i + k]) : 0u);
    for (size_t k = 0; k < 4; ++k) out += k <= n ? kAlphabet[(block >> (18 - 6 * k)) & 63u] : '=';
  }
  return out;
}

/// Accumulates the binary buffer, its views and accessors.
class GltfBuffers {
 public:
  int add_vec3(const std::vector<Vec3>& values, bool with_bounds) {
    std::vector<float> flat;
    flat.reserve(3 * values.size());
    Vec3f lo = Vec3f::Constant(std::numeric_limits<float>::infinity());
    Vec3f hi = -lo;
    for (const Vec3& v : values) {
      const Vec3f f = v.cast<float>();
      lo = lo.cwiseMin(f);
      hi = hi.cwiseMax(f);
      for (int a = 0; a < 3; ++a) flat.push_back(f[a]);
    }
    nlohmann::json accessor = {{"componentType", kFloat}, {"count", values.size()}, {"type", "VEC3"}};
    if (with_bounds) {
      accessor["min"] = {lo.x(), lo.y(), lo.z()};
      accessor["max"] = {hi.x(), hi.y(), hi.z()};
    }
    return add(flat.data(), flat.size() * sizeof(float), kArrayBuffer, accessor);
  }
  int add_vec3f(const std::vector<Vec3f>& values) {
    std::vector<float> flat;
    for (const Vec3f& v : values)
      for (int a = 0; a < 3; ++a) flat.push_back(v[a]);
    return add(flat.data(), flat.size() * sizeof(float), kArrayBuffer,
               {{"componentType", kFloat}, {"count", values.size()}, {"type", "VEC3"}});
  }
  int add_scalars(const std::vector<float>& values) {
    return add(values.data(), values.size() * sizeof(float), kArrayBuffer,
               {{"componentType", kFloat}, {"count", values.size()}, {"type", "SCALAR"}});
  }
  int add_indices(const std::vector<std::array<std::int32_t, 3>>& triangles) {
    std::vector<std::uint32_t> flat;
    flat.reserve(3 * triangles.size());
    for (const auto& t : triangles)
      for (std::int32_t v : t) flat.push_back(static_cast<std::uint32_t>(v));
    return add(flat.data(), flat.size() * sizeof(std::uint32_t), kElementArrayBuffer,
               {{"componentType", kUnsignedInt}, {"count", flat.size()}, {"type", "SCALAR"}});
  }
  void write_into(nlohmann::json& gltf) const {
    gltf["buffers"] = nlohmann::json::array(
        {{{"byteLength", bytes_.size()}, {"uri", "data:application/octet-stream;base64," + base64(bytes_)}}});
    gltf["bufferViews"] = views_;
    gltf["accessors"] = accessors_;
  }

 private:
  int add(const void* data, size_t size, int target, nlohmann::json accessor) {
    const size_t offset = bytes_.size();  // every array is 4-byte data, so offsets stay aligned
    bytes_.append(static_cast<const char*>(data), size);
    views_.push_back({{"buffer", 0}, {"byteOffset", offset}, {"byteLength", size}, {"target", target}});
    accessor["bufferView"] = views_.size() - 1;
    accessors_.push_back(accessor);
    return static_cast<int>(accessors_.size() - 1);
  }
  std::string bytes_;
  nlohmann::json views_ = nlohmann::json::array();
  nlohmann::json accessors_ = nlohmann::json::array();
};

}  // namespace

void write_gltf(const std::filesystem::path& file, const SurfaceMesh& mesh) {
  const size_t nv = mesh.positions_mm.size();
  if (mesh.triangles.empty() || nv == 0)
    throw InputError(fmt::format("{}: the surface has no triangles; nothing to write", file.string()));
  if (mesh.normals.size() != nv || (!mesh.vertex_colors.empty() && mesh.vertex_colors.size() != nv))
    throw InputError(fmt::format("{}: {} normals and {} colours for {} vertices; expected one normal (and colour) each",
                                 file.string(), mesh.normals.size(), mesh.vertex_colors.size(), nv));
  for (size_t i = 0; i < nv; ++i)
    if (!mesh.positions_mm[i].allFinite() || !mesh.normals[i].allFinite())
      throw ComputeError(fmt::format("{}: surface vertex {} has a non-finite position or normal", file.string(), i));

  GltfBuffers buffers;
  nlohmann::json attributes = nlohmann::json::object();
  attributes["POSITION"] = buffers.add_vec3(mesh.positions_mm, true);
  attributes["NORMAL"] = buffers.add_vec3(mesh.normals, false);
  if (!mesh.vertex_colors.empty()) attributes["COLOR_0"] = buffers.add_vec3f(mesh.vertex_colors);
  for (const NamedScalars& s : mesh.vertex_scalars) {
    if (s.values.size() != nv)
      throw InputError(fmt::format("{}: vertex array '{}' has {} values for {} vertices", file.string(), s.name,
                                   s.values.size(), nv));
    std::string name = "_";
    for (char c : s.name) name += static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
    attributes[name] = buffers.add_scalars(s.values);
  }
  const int indices = buffers.add_indices(mesh.triangles);

  nlohmann::json gltf = {
      {"asset", {{"version", "2.0"}, {"generator", "cleave"}, {"extras", {{"length_unit", "mm"}}}}},
      {"scene", 0},
      {"scenes", nlohmann::json::array({{{"nodes", {0}}}})},
      {"nodes", nlohmann::json::array({{{"mesh", 0}, {"name", "render surface"}}})},
      {"meshes", nlohmann::json::array({{{"name", "render surface"},
                                         {"primitives", nlohmann::json::array({{{"attributes", attributes},
                                                                                {"indices", indices},
                                                                                {"mode", kTriangles}}})}}})},
  };
  buffers.write_into(gltf);
  write_file_atomically(file, gltf.dump() + "\n");
}

}  // namespace cleave
