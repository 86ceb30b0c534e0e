#include "cleave/cut/surface_side_vertices.hpp"

#include <algorithm>

namespace cleave {

std::vector<VertexId> surface_side_vertices(const BodySurface& surface, SurfaceSide side) {
  const LinkedVolume& volume = surface.model().volume;
  const double h = volume.grid().cell_size_mm;
  std::vector<VertexId> out;
  for (CellId c = 0; c < volume.cell_count(); ++c)
    for (Face f = 0; f < kFaceCount; ++f) {
      if (volume.neighbor(c, f) != kNone) continue;
      if (side != SurfaceSide::all) {
        const Vec3 centre = volume.cell_center_mm(c) + 0.5 * h * face_step(f).cast<double>();
        const auto p = surface.project(centre, h);
        const SurfacePoint s = p ? *p : SurfacePoint{centre, face_step(f).cast<double>()};
        if (surface.side_of(s) != side) continue;
      }
      for (const int k : face_corners(f)) out.push_back(volume.corner_vertex(c, k));
    }
  std::sort(out.begin(), out.end());
  out.erase(std::unique(out.begin(), out.end()), out.end());
  return out;
}

}  // namespace cleave
