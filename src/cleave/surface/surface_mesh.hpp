#pragma once
// A triangle mesh ready to write (PLY, glTF): positions, normals, triangles and named quantities
// on vertices and triangles (Polyscope's "structure + quantities"). Other stages attach their
// arrays here (e.g. the cut stage: "depth", "traction_kPa" on the cut faces) before writing.
//
//   SurfaceMesh mesh = make_surface_mesh(surface, positions);
//   attach_triangle_scalars(mesh, "traction_kPa", per_triangle_values);
//   attach_vertex_scalars(mesh, "traction_kPa", triangle_to_vertex_scalars(mesh, per_triangle_values));
//   mesh.vertex_colors = blue_to_red_colors(mesh.vertex_scalars.back().values, 0, max_kPa);
#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "cleave/surface/render_surface.hpp"

namespace cleave {

/// A named array, one value per vertex or per triangle. Name it with its unit ("traction_kPa")
/// or document it ("depth": 0 at the skin, 1 at the inner layer). Names are [A-Za-z0-9_].
struct NamedScalars {
  std::string name;
  std::vector<float> values;
};

struct SurfaceMesh {
  std::vector<Vec3> positions_mm;
  std::vector<Vec3> normals;  ///< unit, outward, per vertex
  std::vector<std::array<std::int32_t, 3>> triangles;  ///< counter-clockwise seen from outside
  std::vector<NamedScalars> vertex_scalars;    ///< each with one value per vertex
  std::vector<NamedScalars> triangle_scalars;  ///< each with one value per triangle
  std::vector<Vec3f> vertex_colors;            ///< empty, or RGB in [0, 1] per vertex
};

/// The render surface at `positions_mm` (reference or deformed), with area-weighted vertex
/// normals and the triangle scalars "is_cut" (1 on cut faces, 0 elsewhere) and "cell" (the cell
/// the triangle's face belongs to). Throws InputError when positions_mm has the wrong size.
SurfaceMesh make_surface_mesh(const RenderSurface& surface, const std::vector<Vec3>& positions_mm);

/// Adds (or replaces) a named per-vertex / per-triangle array. Throws InputError when the size
/// is wrong, the name is empty or not [A-Za-z0-9_], or a value is not finite (no NaN in results).
void attach_vertex_scalars(SurfaceMesh& mesh, const std::string& name, std::vector<float> values);
void attach_triangle_scalars(SurfaceMesh& mesh, const std::string& name, std::vector<float> values);

/// Per-vertex values from per-triangle values: the area-weighted mean over the triangles using
/// each vertex whose value is finite; pass NaN for triangles to leave out (e.g. those not on a
/// cut). A vertex without any finite value gets 0.
std::vector<float> triangle_to_vertex_scalars(const SurfaceMesh& mesh, const std::vector<float>& triangle_values);

/// Linear colour map from blue (value <= lo) to red (value >= hi), the paper's map for released
/// traction. lo == hi maps everything to blue.
std::vector<Vec3f> blue_to_red_colors(const std::vector<float>& values, float lo, float hi);

}  // namespace cleave
