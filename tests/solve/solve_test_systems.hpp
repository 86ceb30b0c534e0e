#pragma once
// Elastic test systems for the solvers: boxes of hexahedra (plates, blocks), optionally cut,
// with the stiffness assembled by the fem domain, one end clamped and a fixed load.
#include <functional>
#include <utility>
#include <vector>

#include "cleave/fem/assemble_stiffness.hpp"
#include "cleave/fem/fixed_dofs.hpp"
#include "cleave/model/tissue_model.hpp"
#include "cleave/solve/linear_solver.hpp"

namespace cleave::test {

constexpr double kTissueE_kPa = 80.0;  // the paper's abdominal wall
constexpr double kTissueNu = 0.4;

/// A solid box of `cells` cubes of edge h (mm), corner at the origin, label 1, E = 80 kPa, nu = 0.4.
inline TissueModel make_box(const Vec3i& cells, double h_mm) {
  LabelVolume labels;
  labels.grid.dims = cells;
  labels.grid.cell_size_mm = h_mm;
  labels.grid.origin_mm = Vec3::Zero();
  labels.labels.assign(static_cast<std::size_t>(labels.grid.voxel_count()), Label{1});
  Material m;
  m.youngs_modulus_kPa = kTissueE_kPa;
  m.poisson_ratio = kTissueNu;
  return make_tissue_model("box", std::move(labels), {{Label{1}, m}});
}

/// Cuts every link across the plane x = middle of the box (between voxel columns nx/2 - 1 and
/// nx/2) for cells whose voxel y is below `y_cells` (all of y: a full cut into two pieces).
inline void cut_across_middle(TissueModel& model, int y_cells) {
  LinkedVolume& volume = model.volume;
  const int middle = volume.grid().dims.x() / 2;
  std::vector<CellFace> faces;
  for (CellId c = 0; c < volume.cell_count(); ++c) {
    const Vec3i& v = volume.cell_voxel(c);
    if (v.x() == middle - 1 && v.y() < y_cells) faces.push_back({c, 1});
  }
  volume.cut_links(faces);
}

struct LinearSystem {
  SparseMatrix a;
  Vector b;
};

/// K u = f with the vertices on the planes x = 0 and (when `both_ends`) x = x_max held at zero,
/// f: a load of 1e-3 mN per vertex growing along x and y, mostly -z with some +y (not symmetric).
enum class Clamp { left_end, both_ends };
inline LinearSystem clamped_system(const TissueModel& model, Clamp clamp) {
  const LinkedVolume& volume = model.volume;
  const Vec3 extent = volume.grid().extent_mm();
  constexpr double kLoad_mN = 1e-3;
  constexpr double kTolerance_mm = 1e-9;
  LinearSystem s;
  s.a = assemble_stiffness(model);
  s.b = Vector::Zero(3 * volume.vertex_count());
  std::vector<VertexId> held;
  for (VertexId v = 0; v < volume.vertex_count(); ++v) {
    const Vec3 p = volume.vertex_position_mm(v);
    s.b.segment<3>(3 * v) = kLoad_mN * (1.0 + p.x() / extent.x() + 0.5 * p.y() / extent.y()) * Vec3(0.0, 0.3, -1.0);
    if (p.x() < kTolerance_mm || (clamp == Clamp::both_ends && p.x() > extent.x() - kTolerance_mm)) held.push_back(v);
  }
  const FixedDofs fixed = fix_vertices(volume.vertex_count(), held);
  eliminate_fixed_dofs(s.a, s.b, fixed);
  s.a.makeCompressed();
  return s;
}

}  // namespace cleave::test
