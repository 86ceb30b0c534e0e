#include "cleave/stress/surface_cells.hpp"

#include <Eigen/Eigenvalues>
#include <cmath>
#include <limits>

namespace cleave {
namespace {

Vec3 face_normal(Face f) { return face_step(f).cast<double>(); }

/// Gradient of the trilinear corner distance at the cell centre (mm/mm), or zero without distances.
Vec3 distance_gradient(const TissueModel& model, CellId c) {
  const LabelVolume& labels = model.labels;
  if (!labels.has_distance()) return Vec3::Zero();
  const GridSpec& grid = labels.grid;
  const Vec3i v = model.volume.cell_voxel(c);
  Vec3 g = Vec3::Zero();
  for (int corner = 0; corner < kCornerCount; ++corner) {
    const Vec3i o = corner_offset(corner);
    const double d = static_cast<double>(labels.corner_distance_mm[static_cast<std::size_t>(grid.corner_index(v + o))]);
    for (int axis = 0; axis < 3; ++axis) g[axis] += (o[axis] == 1 ? d : -d);
  }
  return g / (4.0 * grid.cell_size_mm);
}

}  // namespace

bool is_boundary_cell(const LinkedVolume& volume, CellId c) {
  for (Face f = 0; f < kFaceCount; ++f)
    if (!volume.linked(c, f)) return true;
  return false;
}

std::vector<CellId> boundary_cells(const LinkedVolume& volume) {
  std::vector<CellId> cells;
  for (CellId c = 0; c < volume.cell_count(); ++c)
    if (is_boundary_cell(volume, c)) cells.push_back(c);
  return cells;
}

std::optional<Vec3> surface_normal(const TissueModel& model, CellId c) {
  const LinkedVolume& volume = model.volume;
  if (!is_boundary_cell(volume, c)) return std::nullopt;
  // The signed distance only knows the uncut surface; use it where the open faces agree with it.
  Mat3 open_tensor = Mat3::Zero();
  Vec3 open_sum = Vec3::Zero();
  for (Face f = 0; f < kFaceCount; ++f) {
    if (volume.linked(c, f)) continue;
    open_tensor += face_normal(f) * face_normal(f).transpose();
    open_sum += face_normal(f);
  }
  const Vec3 g = distance_gradient(model, c);
  constexpr double kMinGradient = 1e-6;  // |grad d| below this (dimensionless) carries no direction
  if (g.norm() > kMinGradient && g.dot(open_sum) >= 0.0) return Vec3(g.normalized());
  const Eigen::SelfAdjointEigenSolver<Mat3> eig(open_tensor);
  Vec3 n = eig.eigenvectors().col(2);
  if (n.dot(open_sum) < 0.0) n = -n;
  return n;
}

SurfaceSnap snap_to_surface(const LinkedVolume& volume, const Vec3& p_mm, double tolerance_mm) {
  SurfaceSnap best;
  best.distance_mm = std::numeric_limits<double>::infinity();
  if (!p_mm.allFinite() || !(tolerance_mm >= 0.0)) return best;
  const GridSpec& grid = volume.grid();
  const double h = grid.cell_size_mm;
  const int reach = static_cast<int>(std::ceil(tolerance_mm / h)) + 1;
  const Vec3 g = (p_mm - grid.origin_mm) / h;
  // Guard against points so far away that voxel coordinates overflow: nothing is near them.
  const double limit = static_cast<double>(grid.dims.maxCoeff()) + reach + 1.0;
  for (int axis = 0; axis < 3; ++axis)
    if (g[axis] < -limit || g[axis] > 2.0 * limit) return best;
  const Vec3i center = grid.voxel_of(p_mm);
  for (int dz = -reach; dz <= reach; ++dz)
    for (int dy = -reach; dy <= reach; ++dy)
      for (int dx = -reach; dx <= reach; ++dx) {
        const CellId c = volume.cell_at_voxel(center + Vec3i(dx, dy, dz));
        if (c == kNone) continue;
        for (Face f = 0; f < kFaceCount; ++f) {
          if (volume.linked(c, f)) continue;
          const Vec3 q = volume.cell_center_mm(c) + 0.5 * h * face_normal(f);
          const double d = (q - p_mm).norm();
          if (d > tolerance_mm) continue;
          if (d < best.distance_mm || (d == best.distance_mm && c < best.cell)) best = {c, q, d};
        }
      }
  return best;
}

}  // namespace cleave
