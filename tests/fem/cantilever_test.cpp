// A cantilever under an end load against Timoshenko beam theory, and convergence under
// refinement through the thickness (trilinear hexahedra lock in bending at coarse resolution).
#include <gtest/gtest.h>

#include "cleave/fem/solve_static.hpp"
#include "fem_test_models.hpp"

namespace cleave {
namespace {

constexpr double kWidth_mm = 4.0;     // square cross-section b x b
constexpr double kLength_mm = 32.0;   // L = 8 b
constexpr double kE_kPa = 80.0;
constexpr double kNu = 0.3;
constexpr double kLoad_mN = 0.05;     // total end load, -z

/// Timoshenko deflection P L^3 / (3 E I) + P L / (kappa G A), Cowper's kappa for a rectangle.
double timoshenko_deflection_mm() {
  const double i = kWidth_mm * kWidth_mm * kWidth_mm * kWidth_mm / 12.0;
  const double area = kWidth_mm * kWidth_mm;
  const double g = kE_kPa / (2.0 * (1.0 + kNu));
  const double kappa = 10.0 * (1.0 + kNu) / (12.0 + 11.0 * kNu);
  return kLoad_mN * kLength_mm * kLength_mm * kLength_mm / (3.0 * kE_kPa * i) + kLoad_mN * kLength_mm / (kappa * g * area);
}

/// Mean z deflection of the free end face, for `n` cells through the thickness; the end x = 0 is
/// clamped and the load is spread as a uniform shear traction over the end face x = L.
double fe_end_deflection_mm(int n) {
  const double h = kWidth_mm / n;
  const TissueModel model = test::make_box_model({8 * n, n, n}, h, kE_kPa, kNu);
  const LinkedVolume& volume = model.volume;
  StaticOptions options;
  options.solver = SolverKind::cholmod;
  options.settings.relative_tolerance = 1e-10;
  options.external_force_mN = Vector::Zero(3 * volume.vertex_count());
  const double traction = kLoad_mN / (kWidth_mm * kWidth_mm);
  std::vector<VertexId> end;
  for (CellId c = 0; c < volume.cell_count(); ++c)
    if (volume.cell_voxel(c).x() == 8 * n - 1)
      for (const int corner : face_corners(1)) options.external_force_mN[3 * volume.corner_vertex(c, corner) + 2] -= traction * h * h / 4;
  for (VertexId v = 0; v < volume.vertex_count(); ++v) {
    const double x = volume.vertex_position_mm(v).x();
    if (x < 1e-9) options.fixed_vertices.push_back(v);
    if (x > kLength_mm - 1e-9) end.push_back(v);
  }
  const StaticResult r = solve_static(model, {}, options);
  double sum = 0;
  for (const VertexId v : end) sum += r.displacement_mm[static_cast<std::size_t>(v)].z();
  return -sum / static_cast<double>(end.size());
}

TEST(Cantilever, EndDeflectionMatchesTimoshenkoAndConverges) {
  const double exact = timoshenko_deflection_mm();
  double previous_error = 1.0;
  for (const int n : {2, 4, 8}) {
    const double error = std::abs(fe_end_deflection_mm(n) - exact) / exact;
    std::printf("cantilever: %d cells through the thickness, relative error %.4f\n", n, error);
    EXPECT_LT(error, previous_error) << n << " cells through the thickness";
    previous_error = error;
  }
  EXPECT_LT(previous_error, 0.03) << "8 cells through the thickness (64 x 8 x 8 cells of 0.5 mm)";
}

}  // namespace
}  // namespace cleave
