#include "cleave/viz/cut_face_surface_arrays.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "cleave/core/error.hpp"
#include "cleave/viz/cut_face_colouring.hpp"

namespace cleave {
namespace {

const Vec3f kSkinTone(0.87f, 0.72f, 0.62f);

}  // namespace

std::int64_t attach_cut_face_arrays(SurfaceMesh& mesh, const RenderSurface& surface, const BodySurface& body,
                                    std::span<const Vec6> residual_stress_kPa) {
  const std::size_t nt = mesh.triangles.size();
  if (nt != static_cast<std::size_t>(surface.triangle_count()))
    throw InputError("attach_cut_face_arrays: the mesh does not come from this render surface");
  // Cut faces in quad order; triangle t lies on quad t / 2.
  std::vector<CellFace> faces;
  std::vector<std::int64_t> face_of_quad(surface.quads.size(), -1);
  for (std::size_t q = 0; q < surface.quads.size(); ++q)
    if (surface.quads[q].is_cut) {
      face_of_quad[q] = static_cast<std::int64_t>(faces.size());
      faces.push_back({surface.quads[q].cell, surface.quads[q].face});
    }
  const CutFaceColours colours = colour_cut_faces(body, faces, residual_stress_kPa);

  constexpr float kOffCut = std::numeric_limits<float>::quiet_NaN();
  std::vector<float> depth(nt, kOffCut), traction(nt, kOffCut);
  std::int64_t cut_triangles = 0;
  for (std::size_t t = 0; t < nt; ++t) {
    const std::int64_t f = face_of_quad[t / 2];
    if (f < 0) continue;
    depth[t] = static_cast<float>(colours.depth[static_cast<std::size_t>(f)]);
    traction[t] = static_cast<float>(colours.released_traction_kPa[static_cast<std::size_t>(f)]);
    ++cut_triangles;
  }
  const std::vector<float> vertex_depth = triangle_to_vertex_scalars(mesh, depth);
  const std::vector<float> vertex_traction = triangle_to_vertex_scalars(mesh, traction);
  std::vector<std::uint8_t> on_cut(mesh.positions_mm.size(), 0);
  for (std::size_t t = 0; t < nt; ++t)
    if (!std::isnan(depth[t]))
      for (const std::int32_t v : mesh.triangles[t]) on_cut[static_cast<std::size_t>(v)] = 1;
  const auto zero_off_cut = [](std::vector<float> v) {
    for (float& x : v)
      if (std::isnan(x)) x = 0.0f;
    return v;
  };
  attach_triangle_scalars(mesh, "cut_face_depth", zero_off_cut(depth));
  attach_triangle_scalars(mesh, "released_traction_kPa", zero_off_cut(traction));
  attach_vertex_scalars(mesh, "cut_face_depth", vertex_depth);
  attach_vertex_scalars(mesh, "released_traction_kPa", vertex_traction);
  if (cut_triangles > 0) {
    const auto [lo, hi] = std::minmax_element(colours.released_traction_kPa.begin(), colours.released_traction_kPa.end());
    mesh.vertex_colors = blue_to_red_colors(vertex_traction, static_cast<float>(*lo), static_cast<float>(*hi));
    for (std::size_t v = 0; v < on_cut.size(); ++v)
      if (!on_cut[v]) mesh.vertex_colors[v] = kSkinTone;
  }
  return cut_triangles;
}

}  // namespace cleave
