// Numerical safety at the edges of the physical range (issue 8, item 4): materials from a gel to
// bone, nearly incompressible tissue, and near-degenerate cuts (a cell hanging by one face, a cell
// cut loose on its own). Each must give finite results that still obey the physics, or a clear
// error; never a NaN.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "cleave/core/error.hpp"
#include "cleave/fem/dynamics.hpp"
#include "cleave/fem/lumped_mass.hpp"
#include "cleave/fem/solve_static.hpp"
#include "fem_test_models.hpp"

namespace cleave {
namespace {

/// Vertices on the lateral rim of a box of nx x ny cells of edge h (x or y at an edge).
std::vector<VertexId> lateral_rim(const LinkedVolume& volume, double width_x_mm, double width_y_mm) {
  std::vector<VertexId> rim;
  for (VertexId v = 0; v < volume.vertex_count(); ++v) {
    const Vec3 p = volume.vertex_position_mm(v);
    if (p.x() <= 0 || p.y() <= 0 || p.x() >= width_x_mm || p.y() >= width_y_mm) rim.push_back(v);
  }
  return rim;
}

double max_displacement_mm(const std::vector<Vec3>& u) {
  double m = 0;
  for (const Vec3& d : u) {
    EXPECT_TRUE(d.allFinite());
    m = std::max(m, d.norm());
  }
  return m;
}

Vec6 biaxial_kPa(double xx, double yy) {
  Vec6 s = Vec6::Zero();
  s << xx, yy, 0, 0, 0, 0;
  return s;
}

/// A plate of 8 x 8 x 2 cells (2 mm), rim held, slit through its middle along y, under 20 / 10 kPa.
StaticResult slit_plate_displacement(double youngs_kPa, double poisson) {
  TissueModel model = test::make_box_model({8, 8, 2}, 2.0, youngs_kPa, poisson);
  model.volume.cut_links(test::faces_between(model.volume, [&](CellId c) {
    const Vec3i v = model.volume.cell_voxel(c);
    return v.x() < 4 && v.y() >= 2 && v.y() < 6;  // a 8 mm slit between x = 3 and x = 4 cells
  }));
  const std::vector<Vec6> stress(static_cast<std::size_t>(model.volume.cell_count()), biaxial_kPa(20.0, 10.0));
  StaticOptions options;
  options.fixed_vertices = lateral_rim(model.volume, 16.0, 16.0);
  options.settings.relative_tolerance = 1e-10;
  return solve_static(model, stress, options);
}

TEST(ExtremeValues, StaticOpeningScalesAsOneOverYoungsModulusOverEightDecades) {
  // Linear statics: u = K(E)^-1 f with K proportional to E, so E * max|u| is the same for a gel
  // (0.01 kPa) and for bone (1 GPa = 1e6 kPa). The multigrid must not care about the scale.
  const double reference = 80.0 * max_displacement_mm(slit_plate_displacement(80.0, 0.4).displacement_mm);
  ASSERT_GT(reference, 0.0);
  for (const double e_kPa : {1e-2, 1.0, 1e4, 1e6}) {
    const StaticResult r = slit_plate_displacement(e_kPa, 0.4);
    EXPECT_TRUE(r.report.converged) << "E = " << e_kPa;
    EXPECT_NEAR(e_kPa * max_displacement_mm(r.displacement_mm) / reference, 1.0, 1e-7) << "E = " << e_kPa;
  }
}

TEST(ExtremeValues, NearlyIncompressibleTissueConvergesToFiniteOpenings) {
  // nu = 0.499 (bulk modulus 500x the shear modulus): volumetric locking makes the element stiff,
  // so the opening is smaller than at nu = 0.4, but finite, positive and converged.
  const StaticResult soft = slit_plate_displacement(80.0, 0.4);
  const StaticResult locked = slit_plate_displacement(80.0, 0.499);
  EXPECT_TRUE(locked.report.converged);
  const double u_locked = max_displacement_mm(locked.displacement_mm);
  EXPECT_GT(u_locked, 0.0);
  EXPECT_LT(u_locked, max_displacement_mm(soft.displacement_mm));
}

/// A 4 x 4 x 2 box (2 mm cells, E = 80 kPa, nu = 0.45) under 20 / 10 kPa and gravity, bottom
/// layer held. Cell (3,3,1) keeps only its link to (2,3,1) (a flap one cell wide); cell (0,0,1)
/// loses every link and becomes a free piece of one element. Both ring at ~2 kHz, far above what
/// dt = 1 ms resolves, and under a 25 % release strain.
struct DegenerateCuts {
  TissueModel model = test::make_box_model({4, 4, 2}, 2.0, 80.0, 0.45);
  CellId hanging = model.volume.cell_at_voxel({3, 3, 1});
  CellId loose = model.volume.cell_at_voxel({0, 0, 1});
  Vec3 gravity{0.0, 0.0, -9810.0};

  DynamicsSettings settings() const {
    DynamicsSettings s;
    for (VertexId v = 0; v < model.volume.vertex_count(); ++v)
      if (model.volume.vertex_position_mm(v).z() <= 0) s.fixed_vertices.push_back(v);
    s.gravity_mm_per_s2 = gravity;
    s.solve.relative_tolerance = 1e-11;
    return s;
  }
  std::vector<Vec6> stress() const {
    return std::vector<Vec6>(static_cast<std::size_t>(model.volume.cell_count()), biaxial_kPa(20.0, 10.0));
  }
  void cut(Dynamics& sim) {
    const LinkedVolume& volume = model.volume;
    std::vector<CellFace> links;
    for (Face f = 0; f < kFaceCount; ++f) {
      if (volume.neighbor(loose, f) != kNone) links.push_back({loose, f});
      const CellId n = volume.neighbor(hanging, f);
      if (n != kNone && n != volume.cell_at_voxel({2, 3, 1})) links.push_back({hanging, f});
    }
    const CutReport report = model.volume.cut_links(links);
    ASSERT_EQ(volume.component_count(), 2);
    sim.topology_changed(report);
  }
};

TEST(ExtremeValues, ACellHangingByOneFaceAndACellCutLooseStayFiniteAndObeyMomentum) {
  DegenerateCuts d;
  const LinkedVolume& volume = d.model.volume;
  const CellId hanging = d.hanging, loose = d.loose;
  const Vec3 gravity = d.gravity;
  Dynamics sim(d.model, d.stress(), d.settings());
  d.cut(sim);

  const double dt_s = 1e-3;
  const int steps = 300;
  for (int i = 0; i < steps; ++i) {
    const SolveReport r = sim.step(dt_s);
    ASSERT_TRUE(r.converged) << "step " << i;
    ASSERT_TRUE(sim.displacement().allFinite()) << "step " << i;
  }
  // The loose cell is a free body: its internal forces cancel, so its centre of mass falls exactly
  // as 1/2 g t^2 (Newmark's average acceleration integrates constant acceleration exactly).
  const Vector mass = lumped_mass(d.model);
  Vec3 mean_u = Vec3::Zero();
  double cell_mass = 0;
  for (int k = 0; k < kCornerCount; ++k) {
    const VertexId v = volume.corner_vertex(loose, k);
    cell_mass += mass[3 * v];
    for (int i = 0; i < 3; ++i) mean_u[i] += mass[3 * v + i] * sim.displacement()[3 * v + i];
  }
  mean_u /= cell_mass;
  const double t = steps * dt_s;
  const Vec3 fall = 0.5 * gravity * t * t;
  EXPECT_LT((mean_u - fall).norm(), 1e-6 * fall.norm());
  // The hanging cell swings on its one face: it moves, but stays within a few cell sizes.
  double hanging_max_mm = 0;
  for (int k = 0; k < kCornerCount; ++k) {
    const VertexId v = volume.corner_vertex(hanging, k);
    hanging_max_mm = std::max(hanging_max_mm, sim.displacement().segment<3>(3 * v).norm());
  }
  EXPECT_GT(hanging_max_mm, 0.0);
  EXPECT_LT(hanging_max_mm, 3 * 2.0);
}

TEST(ExtremeValues, WithoutNumericalDampingTheDivergenceIsReportedNotReturned) {
  // The average acceleration rule (no numerical damping) with the classic frozen-rotation step
  // lets these pieces gain energy without bound; the step must stop with a message before the
  // numbers leave the model. (With the stress stiffness they do not diverge within 1000 steps,
  // but undamped they still tumble far from any rest: the numerical damping is what settles them.)
  DegenerateCuts d;
  DynamicsSettings settings = d.settings();
  settings.numerical_damping = 0;
  settings.stress_stiffness = false;
  Dynamics sim(d.model, d.stress(), settings);
  d.cut(sim);
  try {
    for (int i = 0; i < 1000; ++i) {
      sim.step(1e-3);
      ASSERT_LT(sim.displacement().lpNorm<Eigen::Infinity>(), kDivergedSizes * 2.0 * std::sqrt(36.0));
    }
    FAIL() << "expected the undamped degenerate pieces to diverge";
  } catch (const ComputeError& e) {
    EXPECT_THAT(std::string(e.what()), ::testing::HasSubstr("diverged: a vertex moved"));
    EXPECT_THAT(std::string(e.what()), ::testing::HasSubstr("add damping (simulation.damping) or use a smaller time step"));
  }
}

TEST(ExtremeValues, NumericalDampingOutsideItsRangeIsRefused) {
  DegenerateCuts d;
  DynamicsSettings settings = d.settings();
  settings.numerical_damping = -0.1;
  EXPECT_THROW(Dynamics(d.model, d.stress(), settings), InputError);
  settings.numerical_damping = std::nan("");
  try {
    Dynamics sim(d.model, d.stress(), settings);
    FAIL();
  } catch (const InputError& e) {
    EXPECT_STREQ(e.what(), "numerical damping is nan; expected a number from 0 to 1/3");
  }
}

}  // namespace
}  // namespace cleave
