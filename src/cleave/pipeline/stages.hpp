#pragma once
// The stages of a batch run, in the order run_case calls them. Each lives in its own file.
#include "cleave/pipeline/run_context.hpp"

namespace cleave {

/// Case sections "residual_stress" (given directly) or "design" (strokes + control points):
/// fills ctx.residual_stress_kPa and the design fields (stage_residual_stress.cpp).
void stage_residual_stress(RunContext& ctx);
/// Case sections "incisions" and "cuts": cuts links of ctx.model.volume (stage_cuts.cpp).
void stage_cuts(RunContext& ctx);
/// Case section "simulation": statics or corotational dynamics; fills ctx.displacement_mm
/// and the mechanics fields, frames.pvd for dynamic runs (stage_mechanics.cpp).
void stage_mechanics(RunContext& ctx);
/// Measures incisions (ellipses) and cuts (wound width, flap shrinkage) (stage_measure.cpp).
void stage_measure(RunContext& ctx);
/// Builds the render surface of the cut, deformed body and writes surface.ply / surface.gltf (stage_surface.cpp).
void stage_surface(RunContext& ctx);

}  // namespace cleave
