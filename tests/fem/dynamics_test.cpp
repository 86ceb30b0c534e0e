// Corotational Newmark dynamics: energy conservation without damping, rest at the static
// solution with damping, momentum and free fall of pieces cut free, and no spurious forces from
// rigid rotations.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <span>

#include <Eigen/Geometry>

#include "cleave/core/error.hpp"
#include "cleave/fem/corotation.hpp"
#include "cleave/fem/dynamics.hpp"
#include "cleave/fem/lumped_mass.hpp"
#include "cleave/fem/solve_static.hpp"
#include "fem_test_models.hpp"

namespace cleave {
namespace {

constexpr double kTimeStep_s = 1e-3;   // about 1/25 of the cantilever's first period (~25 ms)
constexpr int kSteps = 1000;

/// A 12 x 4 x 4 mm cantilever of 2 mm cells (6 x 2 x 2), clamped at x = 0.
TissueModel cantilever_model() { return test::make_box_model({6, 2, 2}, 2.0, 80.0, 0.4); }

std::vector<VertexId> clamped_vertices(const LinkedVolume& volume) {
  std::vector<VertexId> out;
  for (VertexId v = 0; v < volume.vertex_count(); ++v)
    if (volume.vertex_position_mm(v).x() < 1e-9) out.push_back(v);
  return out;
}

/// Downward end load (mN) on the vertices of the free end x = 12 mm.
Vector end_load(const LinkedVolume& volume, double total_mN) {
  Vector f = Vector::Zero(3 * volume.vertex_count());
  std::vector<VertexId> end;
  for (VertexId v = 0; v < volume.vertex_count(); ++v)
    if (volume.vertex_position_mm(v).x() > 12.0 - 1e-9) end.push_back(v);
  for (const VertexId v : end) f[3 * v + 2] = -total_mN / static_cast<double>(end.size());
  return f;
}

Vector flatten(const std::vector<Vec3>& u) {
  Vector out(3 * static_cast<Eigen::Index>(u.size()));
  for (std::size_t v = 0; v < u.size(); ++v) out.segment<3>(3 * static_cast<Eigen::Index>(v)) = u[v];
  return out;
}

StaticResult static_deflection(const TissueModel& model, double load_mN) {
  StaticOptions options;
  options.solver = SolverKind::cholmod;
  options.settings.relative_tolerance = 1e-12;
  options.fixed_vertices = clamped_vertices(model.volume);
  options.external_force_mN = end_load(model.volume, load_mN);
  return solve_static(model, {}, options);
}

/// Exact (CHOLMOD, 1e-12) dynamics of the clamped cantilever, no load.
DynamicsSettings exact_cantilever_settings(const LinkedVolume& volume) {
  DynamicsSettings settings;
  settings.solver = SolverKind::cholmod;
  settings.solve.relative_tolerance = 1e-12;
  settings.fixed_vertices = clamped_vertices(volume);
  return settings;
}

/// Releases the simulation from the cantilever bent by a 0.05 mN end load, at rest.
void release_from_bent_shape(const TissueModel& model, Dynamics& sim) {
  const Vector u0 = flatten(static_deflection(model, 0.05).displacement_mm);
  sim.set_state(u0, Vector::Zero(u0.size()));
}

TEST(Dynamics, UndampedNewmarkConservesEnergyOver1000Steps) {
  const TissueModel model = cantilever_model();
  DynamicsSettings settings = exact_cantilever_settings(model.volume);
  settings.numerical_damping = 0;  // the average acceleration rule: no numerical damping
  Dynamics sim(model, {}, settings);
  release_from_bent_shape(model, sim);
  const double e0 = sim.elastic_energy_uJ();
  ASSERT_GT(e0, 0.0);
  double worst = 0, min_elastic = e0;
  for (int i = 0; i < kSteps; ++i) {
    sim.step(kTimeStep_s);
    const double e = sim.kinetic_energy_uJ() + sim.elastic_energy_uJ();
    worst = std::max(worst, std::abs(e - e0) / e0);
    min_elastic = std::min(min_elastic, sim.elastic_energy_uJ());
  }
  std::printf("undamped: max relative energy error %.2e over %d steps\n", worst, kSteps);
  EXPECT_LT(worst, 0.01);
  EXPECT_LT(min_elastic, 0.1 * e0);  // it really oscillates: energy passes through the kinetic form
}

TEST(Dynamics, DampedMotionComesToRestAtTheStaticSolution) {
  const TissueModel model = cantilever_model();
  const StaticResult target = static_deflection(model, 0.02);
  DynamicsSettings settings = exact_cantilever_settings(model.volume);
  settings.external_force_mN = end_load(model.volume, 0.02);
  settings.mass_damping_per_s = 200.0;    // near-critical for the first mode (omega ~ 250 / s)
  settings.stiffness_damping_s = 1e-4;
  Dynamics sim(model, {}, settings);
  for (int i = 0; i < kSteps; ++i) sim.step(kTimeStep_s);
  const Vector expected = flatten(target.displacement_mm);
  const double diff = (sim.displacement() - expected).lpNorm<Eigen::Infinity>() / expected.lpNorm<Eigen::Infinity>();
  std::printf("damped: max |u - u_static| / max |u_static| = %.2e, max |v| = %.2e mm/s\n", diff,
              sim.velocity().lpNorm<Eigen::Infinity>());
  EXPECT_LT(diff, 1e-3);
  EXPECT_LT(sim.velocity().lpNorm<Eigen::Infinity>(), 1e-6 * expected.lpNorm<Eigen::Infinity>() / kTimeStep_s);
}

TEST(Dynamics, DefaultNumericalDampingBarelyTouchesTheResolvedOscillation) {
  // The cantilever's first mode (period ~25 ms) at dt = 1 ms (omega dt ~ 0.25): HHT with the
  // default a = 0.2 is second-order accurate there, so after 100 ms (4 periods) more than 90 % of
  // the energy is left (measured 94.8 %); it does decay (what the damping is for).
  const TissueModel model = cantilever_model();
  Dynamics sim(model, {}, exact_cantilever_settings(model.volume));
  release_from_bent_shape(model, sim);
  const double e0 = sim.elastic_energy_uJ();
  for (int i = 0; i < 100; ++i) sim.step(kTimeStep_s);
  const double e = sim.kinetic_energy_uJ() + sim.elastic_energy_uJ();
  std::printf("default numerical damping: energy after 100 ms %.3f of the initial\n", e / e0);
  EXPECT_GT(e, 0.9 * e0);
  EXPECT_LT(e, 0.999 * e0);
}

/// The cantilever's energy after 100 ms released from the bent shape under generalized-alpha with
/// `radius`, at steps of dt, over the initial; with the largest distance from the average
/// acceleration rule's motion over the largest displacement, when `off` is given.
double generalized_alpha_energy(double radius, double dt, double* off = nullptr) {
  const TissueModel model = cantilever_model();
  DynamicsSettings settings = exact_cantilever_settings(model.volume);
  settings.high_frequency_radius = radius;
  DynamicsSettings average_settings = exact_cantilever_settings(model.volume);
  average_settings.numerical_damping = 0.0;
  Dynamics sim(model, {}, settings);
  Dynamics average(model, {}, average_settings);
  release_from_bent_shape(model, sim);
  release_from_bent_shape(model, average);
  const double e0 = sim.elastic_energy_uJ();
  const double amplitude = sim.displacement().lpNorm<Eigen::Infinity>();
  double distance = 0;
  for (int i = 0; i < static_cast<int>(std::lround(0.1 / dt)); ++i) {
    sim.step(dt);
    if (off != nullptr) {
      average.step(dt);
      distance = std::max(distance, (sim.displacement() - average.displacement()).lpNorm<Eigen::Infinity>());
    }
  }
  if (off != nullptr) *off = distance / amplitude;
  return (sim.kinetic_energy_uJ() + sim.elastic_energy_uJ()) / e0;
}

TEST(Dynamics, GeneralizedAlphaDampsOnlyWhatTheStepCannotResolve) {
  // Radius 1: no numerical damping at all, the motion of the average acceleration rule (both
  // second order and energy-conserving for this nearly linear swing).
  double off = 0;
  const double kept_at_one = generalized_alpha_energy(1.0, kTimeStep_s, &off);
  // Radius 0 (the studio's opening, against the modes 30 ms steps cannot resolve) damps the
  // resolved first mode (omega dt ~ 0.25) too, as a higher-order effect of the step: halving it
  // cuts the energy's logarithmic decay more than threefold (measured 4.2).
  const double kept_coarse = generalized_alpha_energy(0.0, kTimeStep_s);
  const double kept_fine = generalized_alpha_energy(0.0, 0.5 * kTimeStep_s);
  std::printf("generalized-alpha: radius 1 keeps %.4f of the energy over 100 ms (off average acceleration by %.2e of the "
              "amplitude); radius 0 keeps %.3f at 1 ms, %.3f at 0.5 ms\n",
              kept_at_one, off, kept_coarse, kept_fine);
  EXPECT_NEAR(kept_at_one, 1.0, 0.01);
  EXPECT_LT(off, 0.05);
  EXPECT_LT(kept_coarse, 0.999);
  EXPECT_GT(std::log(kept_coarse) / std::log(kept_fine), 3.0);
}

TEST(Dynamics, PiecesCutFreeKeepZeroMomentumAndFallFreelyUnderGravity) {
  TissueModel model = test::make_box_model({6, 4, 2}, 2.0, 80.0, 0.4);
  Vec6 stress;
  stress << 20.0, 10.0, 0, 0, 0, 0;
  std::vector<Vec6> field(static_cast<std::size_t>(model.volume.cell_count()), stress);
  const Vec3 gravity{0.0, 0.0, -9810.0};
  DynamicsSettings settings;
  settings.solver = SolverKind::cholmod;
  settings.solve.relative_tolerance = 1e-12;
  settings.gravity_mm_per_s2 = gravity;
  Dynamics sim(model, field, settings);
  // Cut the body in two; both halves are free pieces driven by their released stress.
  const CutReport cut = model.volume.cut_links(test::faces_between(model.volume, [&](CellId c) { return model.volume.cell_voxel(c).x() < 3; }));
  ASSERT_EQ(model.volume.component_count(), 2);
  sim.topology_changed(cut);
  const Vector mass = lumped_mass(model);
  const int steps = 200;
  for (int i = 0; i < steps; ++i) sim.step(kTimeStep_s);
  ASSERT_TRUE(sim.displacement().allFinite());
  const double t = steps * kTimeStep_s;
  // Internal forces cancel in sum: the centre of mass falls as 1/2 g t^2 and the momentum is m g t.
  Vec3 momentum = Vec3::Zero(), mean_u = Vec3::Zero();
  for (VertexId v = 0; v < model.volume.vertex_count(); ++v)
    for (int i = 0; i < 3; ++i) {
      momentum[i] += mass[3 * v + i] * sim.velocity()[3 * v + i];
      mean_u[i] += mass[3 * v + i] * sim.displacement()[3 * v + i];
    }
  const double total_kg = mass.sum() / 3.0;
  mean_u /= total_kg;
  const Vec3 fall = 0.5 * gravity * t * t;
  EXPECT_LT((mean_u - fall).norm(), 1e-8 * fall.norm());
  EXPECT_LT((momentum - total_kg * gravity * t).norm(), 1e-8 * total_kg * gravity.norm() * t);
}

// After a cut the multigrid keeps its coarse levels (the Galerkin operators of the new matrix,
// with the divided vertices' prolongation rows copied) instead of a new setup; the steps that
// follow must still be the exact ones: two cuts mid-simulation, against CHOLMOD.
TEST(Dynamics, CutsMidSimulationWithTheKeptMultigridLevelsFollowTheExactSolve) {
  const TissueModel uncut = test::make_box_model({24, 12, 3}, 1.0, 80.0, 0.4);
  Vec6 stress;
  stress << 20.0, 10.0, 0, 0, 0, 0;
  const std::vector<Vec6> field(static_cast<std::size_t>(uncut.volume.cell_count()), stress);
  const auto run = [&](SolverKind solver) {
    TissueModel model = uncut;
    Dynamics sim(model, field, test::held_plate_settings(model.volume, solver));
    for (int i = 0; i < 3; ++i) sim.step(kTimeStep_s);
    for (const int depth : {5, 9}) {  // a slit across the middle, then deeper
      sim.topology_changed(test::cut_plate_slit(model, depth));
      for (int i = 0; i < 4; ++i) sim.step(kTimeStep_s);
    }
    return sim.displacement();
  };
  const Vector multigrid = run(SolverKind::multigrid_cg);
  const Vector exact = run(SolverKind::cholmod);
  ASSERT_EQ(multigrid.size(), exact.size());
  const double difference = (multigrid - exact).norm() / exact.norm();
  std::printf("two cuts mid-simulation: multigrid with kept levels vs CHOLMOD, relative difference %.2e\n", difference);
  EXPECT_LT(difference, 1e-7);
}

TEST(Dynamics, LargeRigidRotationOfAStressFreeBodyGivesNoElasticForce) {
  const TissueModel model = test::make_box_model({3, 2, 2}, 2.0);
  const Mat3 rotation = Eigen::AngleAxisd(1.1, Vec3(1.0, 2.0, 0.5).normalized()).toRotationMatrix();
  Vector u(3 * model.volume.vertex_count());
  for (VertexId v = 0; v < model.volume.vertex_count(); ++v) {
    const Vec3 x = model.volume.vertex_position_mm(v);
    u.segment<3>(3 * v) = rotation * x - x;
  }
  DynamicsSettings settings;
  settings.solver = SolverKind::cholmod;
  settings.solve.relative_tolerance = 1e-12;
  Dynamics sim(model, {}, settings);
  sim.set_state(u, Vector::Zero(u.size()));
  EXPECT_LT(sim.elastic_energy_uJ(), 1e-20);
  for (int i = 0; i < 10; ++i) sim.step(kTimeStep_s);
  EXPECT_LT((sim.displacement() - u).lpNorm<Eigen::Infinity>(), 1e-10);
  // Each cell's corotational frame is the applied rotation.
  std::vector<Mat3> frames;
  cell_rotations(model.volume, u, frames);
  for (const Mat3& r : frames) EXPECT_LT((r - rotation).norm(), 1e-12);
}

TEST(Dynamics, PolarDecompositionRecoversTheRotation) {
  const Mat3 rotation = Eigen::AngleAxisd(2.5, Vec3(-0.3, 0.4, 1.0).normalized()).toRotationMatrix();
  Mat3 stretch;
  stretch << 1.2, 0.1, -0.05, 0.1, 0.9, 0.02, -0.05, 0.02, 1.05;
  EXPECT_LT((rotation_from_deformation_gradient(rotation * stretch) - rotation).norm(), 1e-12);
  EXPECT_LT((rotation_from_deformation_gradient(Mat3::Identity()) - Mat3::Identity()).norm(), 1e-15);
  // An inverted element still gets a proper rotation.
  Mat3 inverted = Mat3::Identity();
  inverted(2, 2) = -0.1;
  EXPECT_NEAR(rotation_from_deformation_gradient(inverted).determinant(), 1.0, 1e-12);
}

// The Newton iteration of the polar factor gives the SVD's rotation to rounding: random rotations
// times symmetric stretches from tissue strains to 1:100, a nearly flat cell, and inverted ones
// (which go to the SVD and keep its flipped axis). Its result is orthogonal with det +1.
TEST(Dynamics, PolarRotationByNewtonEqualsTheSvdOne) {
  std::mt19937 random(7);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  const auto random_rotation = [&] {
    return Mat3(Eigen::AngleAxisd(3.0 * unit(random), Vec3(unit(random), unit(random), unit(random)).normalized()));
  };
  double worst = 0;
  for (int i = 0; i < 300; ++i) {
    const Mat3 q = random_rotation();
    const double spread = i < 100 ? 0.3 : (i < 200 ? 3.0 : 100.0);  // largest / smallest principal stretch
    const Vec3 stretches(1.0, 1.0 + (spread - 1.0) * (0.5 + 0.5 * unit(random)), spread);
    const Mat3 s = q * stretches.asDiagonal() * q.transpose();  // symmetric positive definite
    const Mat3 f = random_rotation() * (i < 100 ? Mat3(Mat3::Identity() + 0.3 * unit(random) * s) : s);
    const Mat3 newton = rotation_from_deformation_gradient(f);
    worst = std::max(worst, (newton - rotation_by_svd(f)).cwiseAbs().maxCoeff());
    EXPECT_LT((newton * newton.transpose() - Mat3::Identity()).cwiseAbs().maxCoeff(), 1e-13);
    EXPECT_NEAR(newton.determinant(), 1.0, 1e-13);
  }
  EXPECT_LT(worst, 1e-12);
  Mat3 flat = Mat3::Identity();
  flat(1, 1) = 1e-9;
  EXPECT_LT((rotation_from_deformation_gradient(flat) - rotation_by_svd(flat)).cwiseAbs().maxCoeff(), 1e-12);
  for (const double squash : {-0.1, -2.0}) {
    Mat3 inverted = random_rotation();
    inverted.col(1) *= squash;
    EXPECT_EQ(rotation_from_deformation_gradient(inverted), rotation_by_svd(inverted));
  }
}

// The polar rotations taken four at a time in SIMD lanes are those of the one-at-a-time Newton
// iteration to rounding, whatever each lane's neighbours do: tissue strains, stretches to 1:100,
// identity, and inverted, flat and non-finite gradients (which go to the SVD lane by lane; a
// non-finite one has the all-NaN rotation, where Eigen's SVD would leave entries unset) mixed
// into the same groups of four, for counts that do not fill the last group. Spans of different
// sizes are refused by name.
TEST(Dynamics, PolarRotationsInLanesEqualTheOneAtATimeOnes) {
  std::mt19937 random(11);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  std::vector<Mat3> gradients;
  for (int i = 0; i < 203; ++i) {
    const Mat3 q(Eigen::AngleAxisd(3.0 * unit(random), Vec3(unit(random), unit(random), unit(random)).normalized()));
    Mat3 f = Mat3::Identity();
    switch (i % 7) {
      case 0: break;  // undeformed: settles at once beside lanes that need more steps
      case 1: f.col(1) *= -0.2; break;                   // inverted
      case 2: f(2, 2) = 1e-9; break;                      // nearly flat
      case 3: f = Mat3::Constant(std::nan("")); break;    // not finite
      case 4: f.diagonal() = Vec3(1.0, 10.0, 100.0); break;  // 1:100
      default:
        for (int e = 0; e < 9; ++e) f(e / 3, e % 3) += 0.1 * unit(random);  // tissue strains
    }
    gradients.push_back(q * f);
  }
  for (const std::size_t count : {std::size_t{1}, std::size_t{3}, std::size_t{4}, std::size_t{7}, std::size_t{8}, std::size_t{9},
                                  std::size_t{16}, gradients.size()}) {
    std::vector<Mat3> rotations(count);
    rotations_from_deformation_gradients(std::span<const Mat3>(gradients.data(), count), rotations);
    for (std::size_t i = 0; i < count; ++i) {
      const Mat3 alone = rotation_from_deformation_gradient(gradients[i]);
      if (!gradients[i].allFinite()) {
        EXPECT_TRUE(alone.array().isNaN().all()) << "gradient " << i;
        EXPECT_TRUE(rotations[i].array().isNaN().all()) << "gradient " << i;
        continue;
      }
      EXPECT_LT((rotations[i] - alone).cwiseAbs().maxCoeff(), 1e-14) << "gradient " << i << " of " << count;
      EXPECT_NEAR(rotations[i].determinant(), 1.0, 1e-13) << "gradient " << i;
    }
  }
  std::vector<Mat3> too_few(2);
  try {
    rotations_from_deformation_gradients(gradients, too_few);
    ADD_FAILURE() << "expected InputError";
  } catch (const InputError& e) {
    EXPECT_STREQ(e.what(), "polar decomposition: 203 deformation gradients but room for 2 rotations");
  }
}

}  // namespace
}  // namespace cleave
