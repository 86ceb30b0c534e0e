// Dynamic step timings on the paper's 44,000-cell tube (Table 1), held at one end, under a
// sideways load, and the step system's products. Benchmarks, not tests: DISABLED_ so that they
// run only on request:
//   cleave_test_fem --gtest_also_run_disabled_tests --gtest_filter='*DynamicsBenchmark*'
// Environment: CLEAVE_BENCH_SOLVER (multigrid, eigen-cg, cholmod; default multigrid),
// CLEAVE_BENCH_STEPS (default 20), CLEAVE_BENCH_STEP_TOLERANCE (DynamicsSettings::step_tolerance),
// CLEAVE_BENCH_STRESS_KPA (a uniform residual tension s_xx = s_yy in every cell, so that the step
// carries the stress stiffness; default none), CLEAVE_BENCH_MATRIX_FREE (0: assemble the system
// every step; default 1), CLEAVE_BENCH_CUT_STEPS (the first this many steps each follow a cut
// that lengthens a slit through the tube's upper half by 2 cells: the step after a cut; default 0),
// CLEAVE_BENCH_ITERATIONS_PER_STEP (DynamicsSettings::iterations_per_step; default 0, no budget),
// CLEAVE_BENCH_SHAPE=abdomen (the abdomen at 126x41x84, 45,796 cells, held at its z = 0 end,
// instead of the tube; the steps only).
// Prints per-step times, iterations, residuals (and the start's) and the largest displacement;
// asserts only that every step converged or used its budget.
// DISABLED_BudgetAccuracy: the budgeted steps (CLEAVE_BENCH_ITERATIONS_PER_STEP, default
// kRealTimeIterationsPerStep) against steps solved to their tolerance, side by side on two copies
// of the model (2 kPa tension in x and y, a cut that grows over the first 14 of 24 steps; the
// tube's slit as above, the abdomen's in the plane between the cell layers x = 60 and 61 from y =
// 20 up, 4 cells deeper in z per step): per step the largest vertex difference over the largest
// displacement, the budgeted step's time (steps that rebuilt the multigrid's levels stand out) and
// residual; then the medians.
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <ctime>
#include <cstdio>
#include <cstdlib>
#include <numeric>
#include <string>

#include "cleave/core/allocator_tuning.hpp"
#include "cleave/fem/corotated_system_operator.hpp"
#include "cleave/fem/corotation.hpp"
#include "cleave/fem/dynamics.hpp"
#include "cleave/fem/lumped_mass.hpp"
#include "cleave/fem/stress_stiffness.hpp"
#include "cleave/shapes/builtin_shapes.hpp"
#include "../common/benchmark_support.hpp"

namespace cleave {
namespace {

using Clock = std::chrono::steady_clock;

using test::median_ms;
using test::tube_44k;

/// The 44k tube, or the abdomen at 126x41x84 with CLEAVE_BENCH_SHAPE=abdomen.
bool abdomen_requested() {
  const char* shape = std::getenv("CLEAVE_BENCH_SHAPE");
  return shape != nullptr && std::string(shape) == "abdomen";
}
TissueModel benchmark_model() {
  return abdomen_requested() ? make_tissue_model("abdomen", make_builtin_shape("abdomen", {Vec3i(126, 41, 84), std::nullopt}))
                             : tube_44k();
}

/// Held at its z = 0 end, 1e-3 mN along x on every vertex, mass damping 2/s.
void hold_base_and_push_along_x(const LinkedVolume& volume, DynamicsSettings& settings) {
  settings.mass_damping_per_s = 2.0;
  settings.external_force_mN = Vector::Zero(3 * volume.vertex_count());
  const double z0 = volume.grid().origin_mm.z();
  for (VertexId v = 0; v < volume.vertex_count(); ++v) {
    if (volume.vertex_position_mm(v).z() < z0 + 1e-9) settings.fixed_vertices.push_back(v);
    settings.external_force_mN[3 * v] = 1e-3;
  }
}

/// The slit between the cell layers y = 20 and 21, x < 4 + 2 step, upper half (z >= 25), where
/// still linked.
std::vector<CellFace> tube_slit(const LinkedVolume& volume, int step) {
  std::vector<CellFace> faces;
  for (CellId c = 0; c < volume.cell_count(); ++c) {
    const Vec3i v = volume.cell_voxel(c);
    if (v.y() == 20 && v.x() < 4 + 2 * step && v.z() >= 25 && volume.linked(c, 3)) faces.push_back({c, 3});
  }
  return faces;
}

// The step's system on the 44k tube (2 kPa tension in every cell, a small smooth displacement):
// one product cell by cell (CorotatedSystemOperator) against the same matrix assembled as block
// CSR, in float and double, and the operator's block diagonal. Three rounds; prints only.
TEST(DynamicsBenchmark, DISABLED_Tube44kSystemProducts) {
  const TissueModel model = tube_44k();
  const LinkedVolume& volume = model.volume;
  const ElementTable table = make_element_table(model);
  Vector u(3 * static_cast<Eigen::Index>(volume.vertex_count()));
  for (Eigen::Index i = 0; i < u.size(); ++i) u[i] = 0.05 * std::sin(0.001 * static_cast<double>(i));
  Vec6 tension = Vec6::Zero();
  tension[0] = tension[1] = 2.0;
  const std::vector<Vec6> residual(static_cast<std::size_t>(volume.cell_count()), tension);
  std::vector<Mat3> rotations;
  std::vector<Vec6> tensions;
  cell_rotations_and_tension(volume, table, residual, u, rotations, tensions);
  const Vector mass = lumped_mass(model, table);
  const std::vector<std::uint8_t> fixed(static_cast<std::size_t>(u.size()), 0);
  CorotatedSystemOperator op;
  op.set_topology(volume, table);
  op.set_state(rotations, tensions, 0.8, 0.8, 3600.0, mass, fixed);
  const BlockSparseMatrix<double> blocks = to_block_sparse<double>(op.assembled_matrix());
  BlockSparseMatrix<float> single;
  single.row_start = blocks.row_start;
  single.column = blocks.column;
  single.values.assign(blocks.values.begin(), blocks.values.end());
  const Eigen::VectorXf x_single = u.cast<float>();
  Eigen::VectorXf y_single;
  Vector y;
  std::printf("%d cells, %d vertices, %zu blocks\n", volume.cell_count(), volume.vertex_count(), blocks.blocks());
  // Mixed in sign in most cells, as a design's stress with its near-zero normal eigenvalue.
  Vec6 mixed = Vec6::Zero();
  mixed[0] = 2.0;
  mixed[1] = -1.0;
  mixed[3] = 0.5;
  const std::vector<Vec6> mixed_residual(static_cast<std::size_t>(volume.cell_count()), mixed);
  const bool wide = op.wide_cell_pass();
  for (int round = 0; round < 3; ++round) {
    const double operator_ms = median_ms([&] { op.multiply(x_single, y_single); });
    op.set_wide_cell_pass(false);
    const double portable_ms = median_ms([&] { op.multiply(x_single, y_single); });
    op.set_wide_cell_pass(wide);
    std::printf("float: operator %.2f ms (portable pass %.2f ms), blocks %.2f ms   double: operator %.2f ms, blocks %.2f ms   "
                "block diagonal %.2f ms\n",
                operator_ms, portable_ms, median_ms([&] { multiply(single, x_single, y_single); }),
                median_ms([&] { op.multiply(u, y); }), median_ms([&] { multiply(blocks, u, y); }),
                median_ms([&] { (void)op.inverse_diagonal_blocks(); }));
    std::vector<Eigen::Matrix3f> inverse_single;
    for (const Mat3& m : op.inverse_diagonal_blocks()) inverse_single.push_back(m.cast<float>());
    const Eigen::VectorXf b_single = x_single.reverse();
    Eigen::VectorXf z_single;
    std::printf("rotations and tensile parts: uniform tension %.2f ms, mixed stress %.2f ms\n",
                median_ms([&] { cell_rotations_and_tension(volume, table, residual, u, rotations, tensions); }),
                median_ms([&] { cell_rotations_and_tension(volume, table, mixed_residual, u, rotations, tensions); }));
    std::printf("float D^-1 (b - A x): in one pass %.2f ms, product then pass %.2f ms\n",
                median_ms([&] { op.jacobi_residual(inverse_single, b_single, x_single, z_single); }),
                median_ms([&] { op.VertexOperator::jacobi_residual(inverse_single, b_single, x_single, z_single); }));
  }
}

TEST(DynamicsBenchmark, DISABLED_Tube44kSteps) {
  keep_freed_memory_for_reuse();  // as the CLI and the studio do
  TissueModel model = benchmark_model();
  LinkedVolume& volume = model.volume;
  DynamicsSettings settings;
  const char* solver = std::getenv("CLEAVE_BENCH_SOLVER");
  if (solver != nullptr) settings.solver = solver_kind_from_name(solver);
  const char* steps_text = std::getenv("CLEAVE_BENCH_STEPS");
  const int steps = steps_text != nullptr ? std::atoi(steps_text) : 20;
  if (const char* tol = std::getenv("CLEAVE_BENCH_STEP_TOLERANCE"); tol != nullptr) settings.step_tolerance = std::atof(tol);
  if (const char* budget = std::getenv("CLEAVE_BENCH_ITERATIONS_PER_STEP"); budget != nullptr)
    settings.iterations_per_step = std::atoi(budget);
  hold_base_and_push_along_x(volume, settings);
  if (const char* free = std::getenv("CLEAVE_BENCH_MATRIX_FREE"); free != nullptr) settings.matrix_free = std::atoi(free) != 0;
  std::vector<Vec6> stress;
  if (const char* kpa = std::getenv("CLEAVE_BENCH_STRESS_KPA"); kpa != nullptr) {
    Vec6 s = Vec6::Zero();
    s[0] = s[1] = std::atof(kpa);
    stress.assign(static_cast<std::size_t>(volume.cell_count()), s);
  }
  Dynamics sim(model, stress, settings);
  const char* cut_text = std::getenv("CLEAVE_BENCH_CUT_STEPS");
  const int cut_steps = cut_text != nullptr ? std::atoi(cut_text) : 0;
  std::vector<double> ms, with_cut_ms;
  for (int i = 0; i < steps; ++i) {
    const auto cut_start = Clock::now();
    if (i < cut_steps) sim.topology_changed(volume.cut_links(tube_slit(volume, i)));
    const double cut_ms = std::chrono::duration<double, std::milli>(Clock::now() - cut_start).count();
    const auto t = Clock::now();
    const std::clock_t cpu = std::clock();
    const SolveReport r = sim.step(1.0 / 60.0);
    ms.push_back(std::chrono::duration<double, std::milli>(Clock::now() - t).count());
    with_cut_ms.push_back(ms.back() + cut_ms);
    const double cpu_ms = 1000.0 * static_cast<double>(std::clock() - cpu) / CLOCKS_PER_SEC;
    std::printf("step %2d  %8.1f ms wall  %8.1f ms cpu (all threads)  %3d it  residual %.1e (from %.1e)  "
                "cut before it %6.1f ms wall  |u| %.4g mm\n",
                i, ms.back(), cpu_ms, r.iterations, r.relative_residual, r.initial_relative_residual, cut_ms,
                sim.displacement().lpNorm<Eigen::Infinity>());
    std::fflush(stdout);
    EXPECT_TRUE(r.converged || r.iterations == settings.iterations_per_step);
  }
  std::sort(ms.begin(), ms.end());
  std::sort(with_cut_ms.begin(), with_cut_ms.end());
  std::printf("%s: %d cells, median step %.1f ms (with the cut before it %.1f ms), %d of %d steps matrix-free\n",
              std::string(sim.solver_name()).c_str(), volume.cell_count(), ms[ms.size() / 2], with_cut_ms[with_cut_ms.size() / 2],
              sim.matrix_free_steps(), steps);
}

TEST(DynamicsBenchmark, DISABLED_BudgetAccuracy) {
  keep_freed_memory_for_reuse();
  const bool abdomen = abdomen_requested();
  TissueModel budget_model = benchmark_model();
  TissueModel exact_model = budget_model;
  const LinkedVolume& volume = budget_model.volume;
  DynamicsSettings settings;
  hold_base_and_push_along_x(volume, settings);
  Vec6 tension = Vec6::Zero();
  tension[0] = tension[1] = 2.0;
  const std::vector<Vec6> stress(static_cast<std::size_t>(volume.cell_count()), tension);
  DynamicsSettings budgeted = settings;
  const char* budget = std::getenv("CLEAVE_BENCH_ITERATIONS_PER_STEP");
  budgeted.iterations_per_step = budget != nullptr ? std::atoi(budget) : kRealTimeIterationsPerStep;
  Dynamics fast(budget_model, stress, budgeted);
  Dynamics exact(exact_model, stress, settings);
  constexpr int kSteps = 24;
  constexpr int kCutSteps = 14;
  std::vector<double> errors, ms;
  for (int i = 0; i < kSteps; ++i) {
    if (i < kCutSteps)
      for (TissueModel* m : {&budget_model, &exact_model}) {
        std::vector<CellFace> faces;
        if (abdomen) {  // between the cell layers x = 60 and 61, y >= 20, 5 < z < 10 + 4 i
          for (CellId c = 0; c < m->volume.cell_count(); ++c) {
            const Vec3i v = m->volume.cell_voxel(c);
            if (v.x() == 60 && v.y() >= 20 && v.z() > 5 && v.z() < 10 + 4 * i && m->volume.linked(c, 1)) faces.push_back({c, 1});
          }
        } else {
          faces = tube_slit(m->volume, i);
        }
        (m == &budget_model ? fast : exact).topology_changed(m->volume.cut_links(faces));
      }
    const auto t = Clock::now();
    const SolveReport r = fast.step(1.0 / 60.0);
    ms.push_back(std::chrono::duration<double, std::milli>(Clock::now() - t).count());
    exact.step(1.0 / 60.0);
    const double largest_mm = exact.displacement().lpNorm<Eigen::Infinity>();
    errors.push_back((fast.displacement() - exact.displacement()).lpNorm<Eigen::Infinity>() / largest_mm);
    std::printf("step %2d  %7.1f ms  %d it  residual %.2e (from %.2e)  difference %.3e of the largest displacement, %.4g mm\n", i,
                ms.back(), r.iterations, r.relative_residual, r.initial_relative_residual, errors.back(), largest_mm);
    std::fflush(stdout);
  }
  const double mean_ms = std::accumulate(ms.begin() + 1, ms.end(), 0.0) / (kSteps - 1);
  std::sort(errors.begin(), errors.end());
  std::sort(ms.begin(), ms.end());
  std::printf("%d cells: difference median %.3e, largest %.3e; budgeted step median %.1f ms, mean after the first %.1f ms\n",
              volume.cell_count(), errors[errors.size() / 2], errors.back(), ms[ms.size() / 2], mean_ms);
}

}  // namespace
}  // namespace cleave
