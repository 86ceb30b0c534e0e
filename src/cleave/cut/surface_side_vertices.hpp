#pragma once
// The vertices of the linked volume on one side of the body's surface, e.g. the inner (deep)
// face of the abdominal wall, which lies on the body beneath and is held in a simulation
// (case "simulation.fixed": {"surface": "inner"}).
//
//   std::vector<VertexId> v = surface_side_vertices(BodySurface(model), SurfaceSide::inner);
//
// A boundary voxel face (no grid neighbour: cut faces do not count, whenever the cut was made)
// is on the side BodySurface::side_of gives for its centre projected onto the surface. Returns
// the corner vertices of those faces, ascending and unique; empty when the body has no such side
// (a plate has no inner side). SurfaceSide::all gives every boundary vertex.
#include <vector>

#include "cleave/cut/body_surface.hpp"

namespace cleave {

std::vector<VertexId> surface_side_vertices(const BodySurface& surface, SurfaceSide side);

}  // namespace cleave
