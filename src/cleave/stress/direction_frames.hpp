#pragma once
// Orthonormal eigenvector frames from interpolated line fields (paper section 6.3): the normal
// is kept, the Langer direction is projected onto the plane orthogonal to it and normalised, and
// the cross direction is their cross product.
//
//   std::vector<DirectionFrame> f = direction_frames(langer_tensors, normal_tensors);
//   const std::vector<Vec3> axes = normal_axes(normal_tensors);   // once: the normals never change
//   f = direction_frames(edited_langer_tensors, axes);            // the same frames, one eigen solve less
//
// n = principal eigenvector of the normal tensor; t = principal eigenvector of P T P with
// P = I - n n^T. Where a tensor carries no direction (all eigenvalues ~0, e.g. a piece without
// strokes, or the exact centre of two strokes crossing at right angles) the frame falls back to a
// fixed axis order so that no NaN is produced: normal -> z (or the Langer tensor's weakest axis),
// Langer -> the in-plane axis closest to x. Frames are right-handed: cross = normal x langer.
#include <vector>

#include "cleave/core/types.hpp"

namespace cleave {

struct DirectionFrame {
  Vec3 langer = Vec3::UnitX();  ///< n_1: Langer's line (largest tension)
  Vec3 cross = Vec3::UnitY();   ///< n_2: across Langer's line, in the surface
  Vec3 normal = Vec3::UnitZ();  ///< n_3: surface normal (eigenvalue 0 at the surface)
};

/// One frame per cell; both inputs hold one symmetric tensor per cell (same size, else InputError).
/// A non-finite tensor gives ComputeError "direction frames: the frame of cell N is not finite; ...".
std::vector<DirectionFrame> direction_frames(const std::vector<Mat3>& langer_tensors, const std::vector<Mat3>& normal_tensors);

/// The principal eigenvector of each cell's normal tensor, or zero where it carries no direction.
std::vector<Vec3> normal_axes(const std::vector<Mat3>& normal_tensors);

/// The same frames as from the normal tensors whose normal_axes these are.
std::vector<DirectionFrame> direction_frames(const std::vector<Mat3>& langer_tensors, const std::vector<Vec3>& normal_axes);

/// The frame of one cell (see above).
DirectionFrame direction_frame(const Mat3& langer_tensor, const Mat3& normal_tensor);

/// |d . e| turned into an angle in degrees in [0, 90]: the angle between two lines.
double angle_between_lines_deg(const Vec3& d, const Vec3& e);

}  // namespace cleave
