// No drift: a residual stress in equilibrium on the uncut body (T sigma = 0 at every vertex)
// leaves the body at rest, statically and over 1,000 dynamic steps.
#include <gtest/gtest.h>

#include <Eigen/SparseCholesky>
#include <random>

#include "cleave/fem/dynamics.hpp"
#include "cleave/fem/hex8_element.hpp"
#include "cleave/fem/residual_stress_forces.hpp"
#include "cleave/fem/solve_static.hpp"
#include "fem_test_models.hpp"

namespace cleave {
namespace {

/// T as a sparse (3 n_v x 6 n_c) matrix, assembled here independently of the library's loop.
Eigen::SparseMatrix<double> stress_divergence_matrix(const LinkedVolume& volume) {
  const Mat24x6 te = hex8_stress_divergence(volume.grid().cell_size_mm);
  std::vector<Eigen::Triplet<double>> entries;
  for (CellId c = 0; c < volume.cell_count(); ++c)
    for (int a = 0; a < 8; ++a)
      for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 6; ++j) entries.emplace_back(3 * volume.corner_vertex(c, a) + i, 6 * c + j, te(3 * a + i, j));
  Eigen::SparseMatrix<double> t(3 * volume.vertex_count(), 6 * volume.cell_count());
  t.setFromTriplets(entries.begin(), entries.end());
  return t;
}

/// A random 20 kPa-scale stress field projected onto the null space of T: sigma - T^T (T T^T)^+ T sigma.
std::vector<Vec6> equilibrated_stress(const LinkedVolume& volume) {
  std::mt19937 random(7);
  std::uniform_real_distribution<double> uniform(-20.0, 20.0);
  Eigen::VectorXd sigma(6 * volume.cell_count());
  for (Eigen::Index i = 0; i < sigma.size(); ++i) sigma[i] = uniform(random);
  const Eigen::SparseMatrix<double> t = stress_divergence_matrix(volume);
  Eigen::SparseMatrix<double> normal = t * t.transpose();
  // T T^T is singular only along the 6 rigid motions, which T sigma never has a component of.
  Eigen::SparseMatrix<double> identity(normal.rows(), normal.cols());
  identity.setIdentity();
  normal += 1e-12 * identity;
  const Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> ldlt(normal);
  for (int refinement = 0; refinement < 3; ++refinement) sigma -= t.transpose() * ldlt.solve(t * sigma);
  std::vector<Vec6> out(static_cast<std::size_t>(volume.cell_count()));
  for (CellId c = 0; c < volume.cell_count(); ++c) out[static_cast<std::size_t>(c)] = sigma.segment<6>(6 * c);
  return out;
}

TEST(NoDrift, EquilibratedResidualStressLeavesTheUncutBodyAtRest) {
  const TissueModel model = test::make_box_model({5, 4, 3}, 2.0);
  const std::vector<Vec6> stress = equilibrated_stress(model.volume);
  double magnitude = 0;
  for (const Vec6& s : stress) magnitude = std::max(magnitude, s.lpNorm<Eigen::Infinity>());
  ASSERT_GT(magnitude, 5.0);  // a genuinely non-zero residual stress (kPa)
  const Vector forces = residual_stress_forces(model.volume, stress);
  ASSERT_LT(forces.lpNorm<Eigen::Infinity>(), 1e-9 * magnitude * 4.0);  // T sigma = 0 (mN; faces are 4 mm^2)

  const double limit_mm = 1e-6 * model.size_mm();
  StaticOptions options;
  options.solver = SolverKind::cholmod;
  const StaticResult r = solve_static(model, stress, options);
  double worst = 0;
  for (const Vec3& u : r.displacement_mm) worst = std::max(worst, u.norm());
  std::printf("no drift: static max |u| = %.2e mm (limit %.1e)\n", worst, limit_mm);
  EXPECT_LT(worst, limit_mm);

  DynamicsSettings settings;
  settings.solver = SolverKind::cholmod;
  Dynamics sim(model, stress, settings);
  double dynamic_worst = 0;
  for (int i = 0; i < 1000; ++i) {
    sim.step(1e-3);
    dynamic_worst = std::max(dynamic_worst, sim.displacement().lpNorm<Eigen::Infinity>());
  }
  std::printf("no drift: dynamic max |u| over 1000 steps = %.2e mm\n", dynamic_worst);
  EXPECT_LT(dynamic_worst, limit_mm);
}

TEST(NoDrift, UniformStressIsNotSelfBalancedOnAFreeBody) {
  // The counter-check: a non-zero uniform stress (paper section 3.1: it cannot be residual) does
  // move a free body. Plane-stress-free box under sigma_xx = p: released strain -p/E along x.
  const TissueModel model = test::make_box_model({4, 2, 2}, 2.0, 80.0, 0.4);
  Vec6 stress;
  stress << 8.0, 0, 0, 0, 0, 0;
  StaticOptions options;
  options.solver = SolverKind::cholmod;
  options.settings.relative_tolerance = 1e-12;
  const StaticResult r = solve_static(model, std::vector<Vec6>(static_cast<std::size_t>(model.volume.cell_count()), stress), options);
  EXPECT_EQ(r.free_components, 1);
  for (VertexId v = 0; v < model.volume.vertex_count(); ++v) {
    const Vec3 x = model.volume.vertex_position_mm(v) - Vec3(4.0, 2.0, 2.0);  // from the centre
    const Vec3 expected{-8.0 / 80.0 * x.x(), 0.4 * 8.0 / 80.0 * x.y(), 0.4 * 8.0 / 80.0 * x.z()};
    EXPECT_LT((r.displacement_mm[static_cast<std::size_t>(v)] - expected).norm(), 1e-9) << "vertex " << v;
  }
}

}  // namespace
}  // namespace cleave
