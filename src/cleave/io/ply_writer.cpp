#include "cleave/io/ply_writer.hpp"

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstring>
#include <fmt/format.h>

#include "cleave/core/error.hpp"
#include "cleave/io/atomic_file.hpp"

namespace cleave {
namespace {

static_assert(std::endian::native == std::endian::little, "the PLY writer copies little-endian bytes");

template <typename T>
void put(std::string& out, T value) {
  char bytes[sizeof(T)];
  std::memcpy(bytes, &value, sizeof(T));
  out.append(bytes, sizeof(T));
}

unsigned char color_byte(float c) { return static_cast<unsigned char>(std::lround(std::clamp(c, 0.0f, 1.0f) * 255.0f)); }

}  // namespace

void write_ply(const std::filesystem::path& file, const SurfaceMesh& mesh) {
  const size_t nv = mesh.positions_mm.size();
  const bool has_normals = mesh.normals.size() == nv;
  const bool has_colors = !mesh.vertex_colors.empty();
  if (has_colors && mesh.vertex_colors.size() != nv)
    throw InputError(fmt::format("{}: {} vertex colours for {} vertices", file.string(), mesh.vertex_colors.size(), nv));
  for (const NamedScalars& s : mesh.vertex_scalars)
    if (s.values.size() != nv)
      throw InputError(fmt::format("{}: vertex array '{}' has {} values for {} vertices", file.string(), s.name,
                                   s.values.size(), nv));
  for (const NamedScalars& s : mesh.triangle_scalars)
    if (s.values.size() != mesh.triangles.size())
      throw InputError(fmt::format("{}: triangle array '{}' has {} values for {} triangles", file.string(), s.name,
                                   s.values.size(), mesh.triangles.size()));
  for (size_t i = 0; i < nv; ++i)
    if (!mesh.positions_mm[i].allFinite() || (has_normals && !mesh.normals[i].allFinite()))
      throw ComputeError(fmt::format("{}: surface vertex {} has a non-finite position or normal", file.string(), i));

  std::string out = "ply\nformat binary_little_endian 1.0\ncomment cleave render surface, positions in mm\n";
  out += fmt::format("element vertex {}\nproperty float x\nproperty float y\nproperty float z\n", nv);
  if (has_normals) out += "property float nx\nproperty float ny\nproperty float nz\n";
  for (const NamedScalars& s : mesh.vertex_scalars) out += fmt::format("property float {}\n", s.name);
  if (has_colors) out += "property uchar red\nproperty uchar green\nproperty uchar blue\n";
  out += fmt::format("element face {}\nproperty list uchar int vertex_indices\n", mesh.triangles.size());
  for (const NamedScalars& s : mesh.triangle_scalars) out += fmt::format("property float {}\n", s.name);
  out += "end_header\n";

  const size_t vertex_bytes = 4 * (3 + (has_normals ? 3 : 0) + mesh.vertex_scalars.size()) + (has_colors ? 3 : 0);
  out.reserve(out.size() + nv * vertex_bytes + mesh.triangles.size() * (13 + 4 * mesh.triangle_scalars.size()));
  for (size_t i = 0; i < nv; ++i) {
    for (int a = 0; a < 3; ++a) put(out, static_cast<float>(mesh.positions_mm[i][a]));
    if (has_normals)
      for (int a = 0; a < 3; ++a) put(out, static_cast<float>(mesh.normals[i][a]));
    for (const NamedScalars& s : mesh.vertex_scalars) put(out, s.values[i]);
    if (has_colors)
      for (int a = 0; a < 3; ++a) put(out, color_byte(mesh.vertex_colors[i][a]));
  }
  for (size_t t = 0; t < mesh.triangles.size(); ++t) {
    put(out, static_cast<unsigned char>(3));
    for (std::int32_t v : mesh.triangles[t]) put(out, v);
    for (const NamedScalars& s : mesh.triangle_scalars) put(out, s.values[t]);
  }
  write_file_atomically(file, out);
}

}  // namespace cleave
