#pragma once
// What the page colours on the cut faces (paper fig. 5), per render-surface vertex: the depth
// between skin and inner layer, fixed while the cuts do not change (kept per cut state: at 45k
// cells with the 108 preview incisions it took about a second), and the released traction
// ||sigma n||, which follows every design edit.
#include <span>
#include <vector>

#include "cleave/cut/body_surface.hpp"
#include "cleave/surface/render_surface.hpp"

namespace cleave::studio {

struct CutFaceLayout {
  std::vector<CellFace> faces;  ///< cut faces of the cut model that the render surface shows
  std::vector<float> depth;     ///< per surface vertex: mean over its cut faces, 0 skin .. 1 inner layer; -1 off them
  bool any = false;
};

/// `body`: the uncut model's surface (the skin and inner layer the depth is measured between).
CutFaceLayout cut_face_layout(const BodySurface& body, const TissueModel& cut_model, const RenderSurface& surface);

/// Per surface vertex, the mean released traction (kPa) of the layout's faces around it; -1 off
/// them. Empty when the layout has no faces.
std::vector<float> cut_face_traction_kPa(const CutFaceLayout& layout, const RenderSurface& surface,
                                         std::span<const Vec6> stress_kPa);

}  // namespace cleave::studio
