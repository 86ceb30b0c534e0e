#include <fmt/format.h>

#include "cleave/core/error.hpp"
#include "cleave/cut/body_surface.hpp"
#include "cleave/io/gltf_writer.hpp"
#include "cleave/io/ply_writer.hpp"
#include "cleave/pipeline/stages.hpp"
#include "cleave/surface/render_surface.hpp"
#include "cleave/surface/surface_mesh.hpp"
#include "cleave/surface/surface_topology.hpp"
#include "cleave/viz/cut_face_surface_arrays.hpp"

namespace cleave {

// The render surface of the cut body, deformed by the mechanics stage's displacement (if any),
// as surface.ply (with the triangle arrays "is_cut" and "cell", and the cut-face colouring of
// viz/cut_face_surface_arrays.hpp: "cut_face_depth", "released_traction_kPa" on triangles and
// vertices, vertex colours by released traction) and surface.gltf (the vertex arrays). Summary:
//   surface: {vertices, triangles, cut_triangles, closed_components, closed}
//   files:   the paths written, appended to the array
void stage_surface(RunContext& ctx) {
  const RenderSurface surface = build_render_surface(ctx.model);
  const std::vector<Vec3> positions = deformed_positions(surface, ctx.model.volume, ctx.displacement_mm);
  SurfaceMesh mesh = make_surface_mesh(surface, positions);
  const std::int64_t cut_triangles = attach_cut_face_arrays(mesh, surface, BodySurface(ctx.model), ctx.residual_stress_kPa);

  const SurfaceTopology topology = surface_topology(surface.triangles, surface.vertex_count());
  ctx.summary["surface"] = {{"vertices", surface.vertex_count()},
                            {"triangles", surface.triangle_count()},
                            {"cut_triangles", cut_triangles},
                            {"closed_components", topology.components},
                            {"closed", topology.closed_and_oriented()},
                            {"deformed", !ctx.displacement_mm.empty()}};

  if (!ctx.summary.contains("files")) ctx.summary["files"] = nlohmann::json::array();
  if (ctx.case_file.output.surface_ply) {
    const auto file = ctx.out_dir / "surface.ply";
    write_ply(file, mesh);
    ctx.summary["files"].push_back(file.string());
  }
  if (ctx.case_file.output.surface_gltf) {
    const auto file = ctx.out_dir / "surface.gltf";
    write_gltf(file, mesh);
    ctx.summary["files"].push_back(file.string());
  }
}

}  // namespace cleave
