#pragma once
// The equilibrium residual the page shows on the body (display "equilibrium residual"):
// |T sigma| / h^2 (kPa) at each render-surface vertex, the force left at the uncut model's vertex
// of the surface vertex's grid corner, as a stress; 0 at held vertices (their force is the
// support's reaction). Only the rows of T at the surface's vertices are formed, in parallel.
#include <span>
#include <vector>

#include "cleave/grid/linked_volume.hpp"
#include "cleave/solve/linear_solver.hpp"
#include "cleave/surface/render_surface.hpp"

namespace cleave::studio {

/// `divergence`: stress_divergence_matrix(volume) (row-major, 3 rows per vertex).
std::vector<float> residual_per_surface_vertex(const LinkedVolume& volume, const SparseMatrix& divergence,
                                               std::span<const Vec6> stress_kPa, const RenderSurface& surface,
                                               std::span<const VertexId> held);

}  // namespace cleave::studio
