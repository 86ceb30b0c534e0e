#pragma once
// Colouring the new cut surfaces (paper section 5, fig. 5 middle and right):
//   depth      0 at the skin, 1 at the inner layer. Interpolated between the two surfaces by
//              inverse distance: depth = d_skin / (d_skin + d_inner), with d_skin the distance to
//              the tangent plane of the nearest outer (skin) surface sample and d_inner that of the
//              nearest inner one (BodySurface sides); a body with no inner side (a plate) uses
//              d_skin / thickness under that point.
//   released traction ||sigma n|| (kPa) with n the cut face's normal: the residual stress the cut
//              released there; red for the highest, blue for the lowest (linear map).
//
//   std::vector<CellFace> faces = cut_faces(model.volume);                 // every cut link, both sides
//   CutFaceColours c = colour_cut_faces(surface, faces, residual_stress_kPa);
//   c.depth[i], c.released_traction_kPa[i], c.traction_rgb[i]              // per face i
#include <array>
#include <span>
#include <vector>

#include "cleave/cut/body_surface.hpp"

namespace cleave {

struct CutFaceColours {
  std::vector<double> depth;                   ///< per face, in [0, 1]
  std::vector<double> released_traction_kPa;   ///< per face, ||sigma n||
  std::vector<std::array<float, 3>> traction_rgb;  ///< per face, red = max, blue = min
  std::vector<std::array<float, 3>> depth_rgb;     ///< per face, red = skin (0), yellow = inner layer (1)
};

/// Both sides of every cut link (cell, face), in ascending cell order.
std::vector<CellFace> cut_faces(const LinkedVolume& volume);

/// ||sigma n|| for a unit normal n (kPa).
double released_traction_kPa(const Vec6& stress_kPa, const Vec3& normal);

/// Linear red (at hi) to blue (at lo) colour of `value`; grey-free, clamped.
std::array<float, 3> red_blue(double value, double lo, double hi);

/// Depth in [0, 1] of reference points p (mm), as described above.
std::vector<double> depth_between_skin_and_inner_layer(const BodySurface& surface, std::span<const Vec3> points_mm);

/// `residual_stress_kPa` per cell (empty: all traction 0).
CutFaceColours colour_cut_faces(const BodySurface& surface, std::span<const CellFace> faces,
                                std::span<const Vec6> residual_stress_kPa);

}  // namespace cleave
