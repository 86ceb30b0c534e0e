// Solver timings on the paper's 44,000-cell tube (Table 1), static and one implicit Newmark step.
// A benchmark, not a test: DISABLED_ so that it runs only on request:
//   cleave_test_solve --gtest_also_run_disabled_tests --gtest_filter='*Benchmark*'
// It prints setup and solve times and iterations per solver and checks that the solvers agree.
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <string>

#include "cleave/core/allocator_tuning.hpp"
#include "cleave/fem/lumped_mass.hpp"
#include "cleave/solve/block_sparse_matrix.hpp"
#include "cleave/solve/multigrid_cg_solver.hpp"
#include "cleave/solve/sparse_multiply.hpp"
#include "cleave/solve/supernodal_substitution.hpp"
#include "cleave/shapes/builtin_shapes.hpp"
#include "cholmod_test_factor.hpp"
#include "solve_test_systems.hpp"

namespace cleave {
namespace {

using Clock = std::chrono::steady_clock;
double ms_since(Clock::time_point t) { return std::chrono::duration<double, std::milli>(Clock::now() - t).count(); }

constexpr double kTimeStep_s = 1.0 / 60.0;
constexpr double kNewmarkMassFactor = 4.0 / (kTimeStep_s * kTimeStep_s);  // beta = 1/4
constexpr double kLoad_mN = 1e-3;

struct Systems {
  TissueModel model;
  test::LinearSystem statics, dynamics;
};

/// A built-in shape at `cells` of the test tissue (one material).
TissueModel tissue_model(const std::string& shape, const Vec3i& cells) {
  ShapeResolution resolution;
  resolution.cells = cells;
  Material m;
  m.youngs_modulus_kPa = test::kTissueE_kPa;
  m.poisson_ratio = test::kTissueNu;
  return make_tissue_model(shape, make_builtin_shape(shape, resolution), {{Label{1}, m}});
}

Systems tube_44k() {
  Systems s{tissue_model("cylinder", Vec3i(42, 42, 51)), {}, {}};
  const LinkedVolume& volume = s.model.volume;
  const SparseMatrix k = assemble_stiffness(s.model);
  const Vector mass = lumped_mass(s.model);
  std::vector<VertexId> held;
  Vector f = Vector::Zero(3 * volume.vertex_count());
  const double z0 = volume.grid().origin_mm.z();
  for (VertexId v = 0; v < volume.vertex_count(); ++v) {
    if (volume.vertex_position_mm(v).z() < z0 + 1e-9) held.push_back(v);
    f[3 * v] = kLoad_mN;
  }
  const FixedDofs fixed = fix_vertices(volume.vertex_count(), held);
  s.statics = {k, f};
  eliminate_fixed_dofs(s.statics.a, s.statics.b, fixed);
  SparseMatrix dynamic = k;
  for (Eigen::Index i = 0; i < dynamic.rows(); ++i) dynamic.coeffRef(i, i) += kNewmarkMassFactor * mass[i];
  s.dynamics = {dynamic, f};
  eliminate_fixed_dofs(s.dynamics.a, s.dynamics.b, fixed);
  s.statics.a.makeCompressed();
  s.dynamics.a.makeCompressed();
  return s;
}

/// The statics of `model` held at its lowest x, a uniform load along x.
test::LinearSystem held_at_lowest_x(const TissueModel& model) {
  const LinkedVolume& volume = model.volume;
  std::vector<VertexId> held;
  Vector f = Vector::Constant(3 * volume.vertex_count(), kLoad_mN);
  const double x0 = volume.grid().origin_mm.x() + volume.grid().cell_size_mm;
  for (VertexId v = 0; v < volume.vertex_count(); ++v)
    if (volume.vertex_position_mm(v).x() < x0 + 1e-9) held.push_back(v);
  test::LinearSystem s{assemble_stiffness(model), f};
  eliminate_fixed_dofs(s.a, s.b, fix_vertices(volume.vertex_count(), held));
  s.a.makeCompressed();
  return s;
}

/// Best of `repeat` wall times (ms) of fn: the least disturbed run on a shared machine.
template <typename Fn>
double best_ms(int repeat, const Fn& fn) {
  double best = 1e300;
  for (int i = 0; i < repeat; ++i) {
    const auto t = Clock::now();
    fn();
    best = std::min(best, ms_since(t));
  }
  return best;
}

void run(const char* what, const test::LinearSystem& s, const LinkedVolume& volume) {
  SolveSettings settings;
  settings.relative_tolerance = 1e-8;
  Vector reference;
  std::vector<SolverKind> kinds{SolverKind::multigrid_cg, SolverKind::eigen_cg, SolverKind::cholmod};
  if (const char* only = std::getenv("CLEAVE_BENCH_SOLVER"); only != nullptr) kinds = {solver_kind_from_name(only)};
  for (const SolverKind kind : kinds) {
    auto solver = make_linear_solver(kind, settings);
    if (const char* precision = std::getenv("CLEAVE_BENCH_PRECISION"); kind == SolverKind::multigrid_cg && precision != nullptr) {
      MultigridOptions options;  // CLEAVE_BENCH_PRECISION=double: the double-precision cycle
      options.precision = std::string(precision) == "double" ? CyclePrecision::double_precision : CyclePrecision::single_precision;
      solver = make_multigrid_cg_solver(settings, options);
    }
    auto t = Clock::now();
    solver->setup(s.a, volume);
    const double setup_ms = ms_since(t);
    Vector x = Vector::Zero(s.b.size());
    t = Clock::now();
    const SolveReport cold = solver->solve(s.b, x);
    const double cold_ms = ms_since(t);
    const Vector b2 = 1.01 * s.b;  // the next step's load: a warm start from this solution
    SolveReport warm;
    Vector x_warm;
    const double warm_ms = best_ms(5, [&] {
      x_warm = x;
      warm = solver->solve(b2, x_warm);
    });
    x = x_warm;
    std::printf("%s %-9s setup %8.1f ms | cold solve %8.1f ms %4d it | warm solve (best of 5) %8.1f ms %4d it | residual %.1e\n", what,
                std::string(solver->name()).c_str(), setup_ms, cold_ms, cold.iterations, warm_ms, warm.iterations,
                warm.relative_residual);
    std::fflush(stdout);
    EXPECT_TRUE(cold.converged && warm.converged) << solver->name();
    if (reference.size() == 0) reference = x;
    EXPECT_LT((x - reference).norm() / reference.norm(), 1e-6) << solver->name();
  }
}

// The fine-level products a multigrid-CG iteration is made of, on the Newmark matrix of the
// 44k tube: scalar CSR in double (the CG's product before), block CSR in double (the CG's product
// now) and the smoother's fused residual + block Jacobi in float (block CSR).
TEST(SolverBenchmark, DISABLED_Tube44kProductKernels) {
  const Systems s = tube_44k();
  const SparseMatrix& a = s.dynamics.a;
  const Vector x = Vector::Ones(a.rows());
  Vector y;
  const BlockSparseMatrix<double> bd = to_block_sparse<double>(a);
  const BlockSparseMatrix<float> bf = to_block_sparse<float>(a);
  const Eigen::VectorXf xf = x.cast<float>();
  const Eigen::VectorXf bf_rhs = s.dynamics.b.cast<float>();
  Eigen::VectorXf yf;
  std::vector<Mat3f> identity(static_cast<std::size_t>(a.rows() / 3), Mat3f::Identity());
  constexpr int kRepeat = 30;
  const double csr = best_ms(kRepeat, [&] { multiply(a, x, y); });
  const double bsr_d = best_ms(kRepeat, [&] { multiply(bd, x, y); });
  const double bsr_f = best_ms(kRepeat, [&] { jacobi_residual(bf, identity, bf_rhs, xf, yf); });
  const double csr_mb = static_cast<double>(a.nonZeros()) * 12.0 / 1e6;
  const double bd_mb = static_cast<double>(bd.blocks()) * 76.0 / 1e6;
  const double bf_mb = static_cast<double>(bf.blocks()) * 40.0 / 1e6;
  std::printf("tube 42x42x51 Newmark matrix, %zu blocks; best of %d:\n", bd.blocks(), kRepeat);
  std::printf("  CSR double multiply       %7.2f ms  (%6.1f MB, %5.1f GB/s)\n", csr, csr_mb, csr_mb / csr);
  std::printf("  block CSR double multiply %7.2f ms  (%6.1f MB, %5.1f GB/s)\n", bsr_d, bd_mb, bd_mb / bsr_d);
  std::printf("  block CSR float D^-1 (b - A x) %7.2f ms  (%6.1f MB, %5.1f GB/s)\n", bsr_f, bf_mb, bf_mb / bsr_f);
  Vector reference;
  multiply(a, x, reference);
  multiply(bd, x, y);
  EXPECT_LT((y - reference).norm(), 1e-12 * reference.norm());
}

TEST(SolverBenchmark, DISABLED_Tube44kStaticAndNewmarkStep) {
  const Systems s = tube_44k();
  std::printf("tube 42x42x51: %d cells, %d vertices, %lld nonzeros\n", s.model.volume.cell_count(), s.model.volume.vertex_count(),
              static_cast<long long>(s.statics.a.nonZeros()));
  std::fflush(stdout);
  run("static ", s.statics, s.model.volume);
  run("newmark", s.dynamics, s.model.volume);
}

// The substitutions with a kept supernodal factor (the studio's preview and equilibration solve
// one column per edit, the direction field six): forward and back substitution timed apart, for
// one and for six columns, against cholmod_solve, on the statics of the 44k tube.
TEST(SolverBenchmark, DISABLED_Tube44kSubstitution) {
  keep_freed_memory_for_reuse();  // as the CLI does: no page faults for the repeated arrays
  Systems s = tube_44k();
  if (const char* shape = std::getenv("CLEAVE_BENCH_SHAPE"); shape != nullptr && std::string(shape) == "abdomen") {
    s.model = tissue_model("abdomen", Vec3i(126, 41, 84));
    s.statics = held_at_lowest_x(s.model);
  }
  test::CholmodFactor factor(s.statics.a);
  const SupernodalSubstitution substitution(factor.factor());
  const double factor_mb = static_cast<double>(factor.factor().xsize) * 8.0 / 1e6;
  std::printf("tube 42x42x51 statics: %lld rows, factor %.0f MB\n", static_cast<long long>(s.statics.a.rows()), factor_mb);
  const char* repeat_env = std::getenv("CLEAVE_BENCH_REPEAT");  // more repeats for a profiler
  const int kRepeat = repeat_env != nullptr ? std::max(1, std::atoi(repeat_env)) : 9;
  for (const Eigen::Index columns : {Eigen::Index{1}, Eigen::Index{6}}) {
    Eigen::MatrixXd b(s.statics.b.size(), columns);
    for (Eigen::Index c = 0; c < columns; ++c) b.col(c) = (1.0 + 0.1 * static_cast<double>(c)) * s.statics.b;
    Eigen::MatrixXd y, x;
    const double forward = best_ms(kRepeat, [&] { y = substitution.forward_of(factor.factor(), b); });
    const double backward = best_ms(kRepeat, [&] { x = substitution.backward_of(factor.factor(), y); });
    Eigen::MatrixXd reference;
    const double cholmod = best_ms(kRepeat, [&] { reference = factor.cholmod_solution(b); });
    std::printf("  %lld column(s): forward %7.2f ms (%5.1f GB/s), backward %7.2f ms (%5.1f GB/s), cholmod_solve %7.2f ms\n",
                static_cast<long long>(columns), forward, factor_mb / forward, backward, factor_mb / backward, cholmod);
    EXPECT_LT((x - reference).norm(), 1e-10 * reference.norm());
  }
}

}  // namespace
}  // namespace cleave
