#include "studio/cut_face_values.hpp"

#include "cleave/viz/cut_face_colouring.hpp"

namespace cleave::studio {
namespace {

/// Calls visit(face index, surface vertex) for every surface vertex of every face's quad.
template <typename Visit>
void for_each_face_vertex(std::span<const CellFace> faces, const RenderSurface& surface, Visit&& visit) {
  for (std::size_t i = 0; i < faces.size(); ++i) {
    const std::int32_t q = surface.quad_of_face[6 * static_cast<std::size_t>(faces[i].cell) + static_cast<std::size_t>(faces[i].face)];
    if (q == kNone) continue;
    for (SurfaceVertexId v : surface.quads[static_cast<std::size_t>(q)].vertices) visit(i, static_cast<std::size_t>(v));
  }
}

/// The mean of per-face values at each surface vertex; -1 where no face touches it.
std::vector<float> mean_at_vertices(std::span<const CellFace> faces, const RenderSurface& surface,
                                    const std::vector<double>& per_face) {
  const auto n = static_cast<std::size_t>(surface.vertex_count());
  std::vector<double> sum(n, 0.0);
  std::vector<int> count(n, 0);
  for_each_face_vertex(faces, surface, [&](std::size_t i, std::size_t v) {
    sum[v] += per_face[i];
    ++count[v];
  });
  std::vector<float> out(n, -1.0f);
  for (std::size_t v = 0; v < n; ++v)
    if (count[v] > 0) out[v] = static_cast<float>(sum[v] / count[v]);
  return out;
}

}  // namespace

CutFaceLayout cut_face_layout(const BodySurface& body, const TissueModel& cut_model, const RenderSurface& surface) {
  CutFaceLayout out;
  out.faces = cut_faces(cut_model.volume);
  if (out.faces.empty()) return out;
  const LinkedVolume& volume = cut_model.volume;
  const double h = volume.grid().cell_size_mm;
  std::vector<Vec3> centres;
  centres.reserve(out.faces.size());
  for (const CellFace& f : out.faces) centres.push_back(volume.cell_center_mm(f.cell) + 0.5 * h * face_step(f.face).cast<double>());
  out.depth = mean_at_vertices(out.faces, surface, depth_between_skin_and_inner_layer(body, centres));
  for (const float d : out.depth) out.any = out.any || d >= 0;
  return out;
}

std::vector<float> cut_face_traction_kPa(const CutFaceLayout& layout, const RenderSurface& surface,
                                         std::span<const Vec6> stress_kPa) {
  if (layout.faces.empty()) return {};
  std::vector<double> traction;
  traction.reserve(layout.faces.size());
  for (const CellFace& f : layout.faces) {
    const Vec6 s = stress_kPa.empty() ? Vec6::Zero() : stress_kPa[static_cast<std::size_t>(f.cell)];
    traction.push_back(released_traction_kPa(s, face_step(f.face).cast<double>()));
  }
  return mean_at_vertices(layout.faces, surface, traction);
}

}  // namespace cleave::studio
