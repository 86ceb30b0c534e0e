// Equilibration timings on the paper's 44,000-cell tube (Table 1): one StressEquilibrator, then
// edits of a smooth designed stress that change it everywhere (no edit repeats one of the last
// two, so each is solved), and one product with Kc. Benchmarks, not tests: DISABLED_ so that it runs only on request:
//   cleave_test_stress --gtest_also_run_disabled_tests --gtest_filter='*EquilibrationBenchmark*'
// Environment: CLEAVE_BENCH_EDITS (default 20). Prints per-edit times and solves with the factor;
// asserts only that every edit reached the required balance and that the products agree.
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>

#include "cleave/fem/element_table.hpp"
#include "cleave/shapes/builtin_shapes.hpp"
#include "../common/benchmark_support.hpp"
#include "cleave/solve/sparse_multiply.hpp"
#include "cleave/stress/centre_point_stiffness.hpp"
#include "cleave/stress/equilibrate_stress.hpp"

namespace cleave {
namespace {

using Clock = std::chrono::steady_clock;

using test::median_ms;
using test::tube_44k;

/// A smooth stress that is not self-balanced; `edit` shifts its waves.
std::vector<Vec6> designed_stress(const TissueModel& model, int edit) {
  std::vector<Vec6> out(static_cast<std::size_t>(model.volume.cell_count()));
  const double phase = 0.1 * edit;
  for (CellId c = 0; c < model.volume.cell_count(); ++c) {
    const Vec3 x = model.volume.cell_center_mm(c);
    const double a = std::sin(0.05 * x.x() + phase), b = std::cos(0.04 * x.z() - phase);
    out[static_cast<std::size_t>(c)] << 20.0 * a, 10.0 + 5.0 * b, 3.0 * a * b, 2.0 * b, 1.0 * a, 0.5;
  }
  return out;
}

// One product with Kc: cell by cell (CentrePointStiffness) against its assembled matrix (CSR on
// all cores, as the equilibration multiplied before).
TEST(EquilibrationBenchmark, DISABLED_Tube44kProducts) {
  const TissueModel model = tube_44k();
  const std::vector<std::uint8_t> free(3 * static_cast<std::size_t>(model.volume.vertex_count()), 0);
  const CentrePointStiffness kc(model.volume, make_element_table(model), free);
  const SparseMatrix assembled = kc.assembled();
  const Vector x = Vector::Random(kc.rows());
  Vector y, z;
  for (int round = 0; round < 3; ++round) {
    const double cell_ms = median_ms([&] { kc.multiply(x, y); });
    const double csr_ms = median_ms([&] { multiply(assembled, x, z); });
    std::printf("round %d: cell by cell %.2f ms, assembled (%.0f MB) %.2f ms\n", round, cell_ms,
                static_cast<double>(assembled.nonZeros()) * 12e-6, csr_ms);
  }
  EXPECT_LT((y - z).norm(), 1e-12 * z.norm());
}

TEST(EquilibrationBenchmark, DISABLED_Tube44kEdits) {
  const TissueModel model = tube_44k();
  const char* edits_env = std::getenv("CLEAVE_BENCH_EDITS");
  const int edits = edits_env ? std::atoi(edits_env) : 20;
  StressEquilibrator equilibrator(model);
  std::vector<double> ms;
  for (int edit = 0; edit < edits; ++edit) {
    const std::vector<Vec6> designed = designed_stress(model, edit);
    const auto start = Clock::now();
    const EquilibrationResult r = equilibrator.equilibrate(designed);
    const double elapsed = std::chrono::duration<double, std::milli>(Clock::now() - start).count();
    if (edit > 0) ms.push_back(elapsed);
    std::printf("edit %2d: %7.1f ms, %d solves, reduction %.2e\n", edit, elapsed, r.refinement_steps, r.force_reduction);
    EXPECT_LE(r.force_reduction, 1e-10);
  }
  if (ms.empty()) return;
  std::sort(ms.begin(), ms.end());
  std::printf("median of %zu edits after the first: %.1f ms\n", ms.size(), ms[ms.size() / 2]);
}

}  // namespace
}  // namespace cleave
