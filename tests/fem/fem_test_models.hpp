#pragma once
// Small models for the fem tests: boxes of cubic cells built straight from a label volume.
#include <map>

#include <Eigen/Geometry>

#include "cleave/fem/dynamics.hpp"
#include "cleave/model/tissue_model.hpp"

namespace cleave::test {

/// A solid box of nx x ny x nz cells of edge h (mm) with its corner at the origin, label 1,
/// material E (kPa), nu, density 1000 kg/m^3.
/// `label_of_voxel` may give other labels (materials from `extra_materials`, default otherwise).
using LabelOfVoxel = Label (*)(const Vec3i&);
inline TissueModel make_box_model(const Vec3i& cells, double h_mm, double youngs_modulus_kPa = 80.0,
                                  double poisson_ratio = 0.4, LabelOfVoxel label_of_voxel = nullptr,
                                  std::map<Label, Material> extra_materials = {}) {
  LabelVolume labels;
  labels.grid.dims = cells;
  labels.grid.cell_size_mm = h_mm;
  labels.grid.origin_mm = Vec3::Zero();
  labels.labels.assign(static_cast<std::size_t>(labels.grid.voxel_count()), Label{1});
  if (label_of_voxel != nullptr)
    for (int z = 0; z < cells.z(); ++z)
      for (int y = 0; y < cells.y(); ++y)
        for (int x = 0; x < cells.x(); ++x)
          labels.labels[static_cast<std::size_t>(labels.grid.voxel_index({x, y, z}))] = label_of_voxel({x, y, z});
  Material m;
  m.youngs_modulus_kPa = youngs_modulus_kPa;
  m.poisson_ratio = poisson_ratio;
  extra_materials[Label{1}] = m;
  return make_tissue_model("box", std::move(labels), std::move(extra_materials));
}

/// Uncut faces between the cells for which `inside` holds and the others, as cut_links input.
template <typename Inside>
std::vector<CellFace> faces_between(const LinkedVolume& volume, Inside&& inside) {
  std::vector<CellFace> faces;
  for (CellId c = 0; c < volume.cell_count(); ++c) {
    if (!inside(c)) continue;
    for (Face f = 0; f < kFaceCount; ++f) {
      const CellId n = volume.neighbor(c, f);
      if (n != kNone && !inside(n)) faces.push_back({c, f});
    }
  }
  return faces;
}

/// A turned (0.9 rad about an oblique axis) and wobbled state: no cell keeps the identity rotation.
inline Vector turned_displacement(const LinkedVolume& volume) {
  const Mat3 turn = Eigen::AngleAxisd(0.9, Vec3(0.3, -1.0, 0.5).normalized()).toRotationMatrix();
  Vector u(3 * static_cast<Eigen::Index>(volume.vertex_count()));
  for (VertexId i = 0; i < volume.vertex_count(); ++i) {
    const Vec3 x = volume.vertex_position_mm(i);
    const Vec3 wobble(0.06 * std::sin(1.1 * x.y()), 0.05 * std::cos(0.8 * x.x()), 0.04 * std::sin(x.x() + x.z()));
    u.segment<3>(3 * i) = turn * (x + wobble) - x;
  }
  return u;
}

/// The stressed plate of the cut-mid-simulation tests (24 x 12 x 3 cells of 1 mm) is held at
/// x = 0, damped (50 / s) and solved tightly (1e-11, no step tolerance), with `solver`.
inline DynamicsSettings held_plate_settings(const LinkedVolume& volume, SolverKind solver = SolverKind::multigrid_cg) {
  DynamicsSettings settings;
  settings.solver = solver;
  settings.solve.relative_tolerance = 1e-11;
  settings.step_tolerance = 0;
  settings.mass_damping_per_s = 50.0;
  for (VertexId v = 0; v < volume.vertex_count(); ++v)
    if (volume.vertex_position_mm(v).x() < 1e-9) settings.fixed_vertices.push_back(v);
  return settings;
}

/// Cuts the plate's slit across its middle (cells x < 12) down to y < depth.
inline CutReport cut_plate_slit(TissueModel& model, int depth) {
  return model.volume.cut_links(faces_between(model.volume, [&](CellId c) {
    const Vec3i& v = model.volume.cell_voxel(c);
    return v.x() < 12 && v.y() < depth;
  }));
}

/// A 24 x 12 x 3 plate of 1 mm cells (E = 20 kPa, nu = 0.45) under a uniform residual tension
/// (2, 1, 0.3 kPa in x, y, xy), with the slit across its middle (cells x < 12, y < 6) cut: the
/// wound opens when it is stepped (hold x = 0).
struct OpeningPlate {
  TissueModel model = make_box_model({24, 12, 3}, 1.0, 20.0, 0.45);
  std::vector<Vec6> stress;
  OpeningPlate() {
    Vec6 s;
    s << 2.0, 1.0, 0, 0.3, 0, 0;
    stress.assign(static_cast<std::size_t>(model.volume.cell_count()), s);
    cut_plate_slit(model, 6);
  }
};

}  // namespace cleave::test
