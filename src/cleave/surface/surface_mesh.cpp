#include "cleave/surface/surface_mesh.hpp"

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <fmt/format.h>

#include "cleave/core/error.hpp"
#include "cleave/surface/surface_measures.hpp"

namespace cleave {
namespace {

void attach(std::vector<NamedScalars>& arrays, const char* where, size_t expected, const std::string& name,
            std::vector<float> values) {
  if (name.empty() || !std::all_of(name.begin(), name.end(), [](char c) {
        return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_';
      }))
    throw InputError(fmt::format("surface {} array name '{}': expected letters, digits or '_'", where, name));
  if (values.size() != expected)
    throw InputError(fmt::format("surface {} array '{}' has {} values; expected {}", where, name, values.size(), expected));
  for (size_t i = 0; i < values.size(); ++i)
    if (!std::isfinite(values[i]))
      throw InputError(fmt::format("surface {} array '{}' has a non-finite value at {}; expected finite values", where,
                                   name, i));
  for (NamedScalars& a : arrays)
    if (a.name == name) {
      a.values = std::move(values);
      return;
    }
  arrays.push_back(NamedScalars{name, std::move(values)});
}

}  // namespace

SurfaceMesh make_surface_mesh(const RenderSurface& surface, const std::vector<Vec3>& positions_mm) {
  if (positions_mm.size() != surface.reference_mm.size())
    throw InputError(fmt::format("surface mesh: {} positions given for a surface of {} vertices", positions_mm.size(),
                                 surface.reference_mm.size()));
  SurfaceMesh mesh;
  mesh.positions_mm = positions_mm;
  mesh.triangles = surface.triangles;
  mesh.normals = vertex_normals(mesh.triangles, mesh.positions_mm);
  std::vector<float> is_cut(surface.triangles.size());
  std::vector<float> cell(surface.triangles.size());
  for (std::int32_t t = 0; t < surface.triangle_count(); ++t) {
    is_cut[static_cast<size_t>(t)] = surface.triangle_is_cut(t) ? 1.0f : 0.0f;
    cell[static_cast<size_t>(t)] = static_cast<float>(surface.triangle_cell(t));
  }
  attach_triangle_scalars(mesh, "is_cut", std::move(is_cut));
  attach_triangle_scalars(mesh, "cell", std::move(cell));
  return mesh;
}

void attach_vertex_scalars(SurfaceMesh& mesh, const std::string& name, std::vector<float> values) {
  attach(mesh.vertex_scalars, "vertex", mesh.positions_mm.size(), name, std::move(values));
}

void attach_triangle_scalars(SurfaceMesh& mesh, const std::string& name, std::vector<float> values) {
  attach(mesh.triangle_scalars, "triangle", mesh.triangles.size(), name, std::move(values));
}

std::vector<float> triangle_to_vertex_scalars(const SurfaceMesh& mesh, const std::vector<float>& triangle_values) {
  if (triangle_values.size() != mesh.triangles.size())
    throw InputError(fmt::format("triangle values: {} given for {} triangles", triangle_values.size(),
                                 mesh.triangles.size()));
  std::vector<double> sum(mesh.positions_mm.size(), 0.0);
  std::vector<double> weight(mesh.positions_mm.size(), 0.0);
  for (size_t t = 0; t < mesh.triangles.size(); ++t) {
    if (!std::isfinite(triangle_values[t])) continue;
    const auto& tri = mesh.triangles[t];
    const Vec3& a = mesh.positions_mm[static_cast<size_t>(tri[0])];
    const double area = 0.5 * (mesh.positions_mm[static_cast<size_t>(tri[1])] - a)
                                  .cross(mesh.positions_mm[static_cast<size_t>(tri[2])] - a)
                                  .norm();
    for (std::int32_t v : tri) {
      sum[static_cast<size_t>(v)] += area * static_cast<double>(triangle_values[t]);
      weight[static_cast<size_t>(v)] += area;
    }
  }
  std::vector<float> values(sum.size(), 0.0f);
  for (size_t v = 0; v < values.size(); ++v)
    if (weight[v] > 0) values[v] = static_cast<float>(sum[v] / weight[v]);
  return values;
}

std::vector<Vec3f> blue_to_red_colors(const std::vector<float>& values, float lo, float hi) {
  std::vector<Vec3f> colors(values.size());
  for (size_t i = 0; i < values.size(); ++i) {
    const float s = hi > lo && std::isfinite(values[i]) ? std::clamp((values[i] - lo) / (hi - lo), 0.0f, 1.0f) : 0.0f;
    colors[i] = Vec3f(s, 0.0f, 1.0f - s);
  }
  return colors;
}

}  // namespace cleave
