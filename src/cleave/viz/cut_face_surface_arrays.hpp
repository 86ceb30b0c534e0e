#pragma once
// The cut-face colouring (viz/cut_face_colouring.hpp, paper fig. 5) as arrays of the output
// surface (surface.ply, surface.gltf), so that ParaView, MeshLab or a glTF viewer shows it:
//   triangle scalars  "cut_face_depth"         0 at the skin .. 1 at the inner layer
//                     "released_traction_kPa"  ||sigma n|| of the residual stress the cut released
//                     (both 0 on triangles that are not on a cut face; "is_cut" tells them apart)
//   vertex scalars    the same names: area-weighted mean over the vertex's cut triangles, 0 off the cuts
//   vertex colours    released traction, red (highest) to blue (lowest), on vertices of cut
//                     faces; a skin tone elsewhere. Left empty when nothing is cut.
//
//   SurfaceMesh mesh = make_surface_mesh(surface, positions);
//   attach_cut_face_arrays(mesh, surface, BodySurface(model), residual_stress_kPa);
#include <cstdint>
#include <span>

#include "cleave/cut/body_surface.hpp"
#include "cleave/surface/surface_mesh.hpp"

namespace cleave {

/// `mesh` must come from make_surface_mesh(surface, ...) (same triangles); `residual_stress_kPa`
/// per cell of body.model() (empty: traction 0). Returns the number of cut triangles.
std::int64_t attach_cut_face_arrays(SurfaceMesh& mesh, const RenderSurface& surface, const BodySurface& body,
                                    std::span<const Vec6> residual_stress_kPa);

}  // namespace cleave
