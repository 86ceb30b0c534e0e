// Issue 8 item 4, for the design stages: no NaN or Inf reaches a result. The public API refuses
// non-finite strokes, control points and stresses (InputError); these tests feed non-finite or
// overflowing data through each stage's own API and expect a ComputeError naming the stage.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <string>

#include "cleave/core/error.hpp"
#include "cleave/stress/control_point_targets.hpp"
#include "cleave/stress/direction_frames.hpp"
#include "cleave/stress/eigenvalue_interpolation.hpp"
#include "cleave/stress/equilibrate_stress.hpp"
#include "cleave/stress/line_field_interpolation.hpp"
#include "cleave/stress/stroke_constraints.hpp"
#include "stress_test_models.hpp"

namespace cleave {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

/// The ComputeError message of f, or "no ComputeError".
template <typename F>
std::string compute_error(F&& f) {
  try {
    f();
  } catch (const ComputeError& e) {
    return e.what();
  }
  return "no ComputeError";
}

bool starts_with(const std::string& text, const std::string& prefix) { return text.rfind(prefix, 0) == 0; }

TEST(NumericalSafety, LineFieldInterpolationRefusesANonFiniteResult) {
  const TissueModel m = test::builtin_model("plate", {Vec3i(8, 8, 2), std::nullopt});
  LineFieldInterpolator interp(m.volume, DesignWeights{});
  std::vector<LineTarget> targets = {{0, Vec3::UnitX() * Vec3::UnitX().transpose()}};
  ASSERT_EQ(interp.interpolate(targets).size(), static_cast<std::size_t>(m.volume.cell_count()));  // a finite target works
  targets.push_back({3, Mat3::Constant(kNaN)});
  const std::string message = compute_error([&] { interp.interpolate(targets); });
  EXPECT_TRUE(starts_with(message, "line field interpolation: ")) << message;
}

TEST(NumericalSafety, DirectionFramesRefuseANonFiniteTensor) {
  std::vector<Mat3> langer(4, Vec3::UnitX() * Vec3::UnitX().transpose());
  std::vector<Mat3> normal(4, Vec3::UnitZ() * Vec3::UnitZ().transpose());
  EXPECT_EQ(direction_frames(langer, normal).size(), 4u);
  langer[2](0, 1) = langer[2](1, 0) = std::numeric_limits<double>::infinity();
  EXPECT_EQ(compute_error([&] { direction_frames(langer, normal); }),
            "direction frames: the frame of cell 2 is not finite; expected finite Langer and normal tensors");
}

TEST(NumericalSafety, EigenvalueInterpolationRefusesANonFiniteResult) {
  const TissueModel m = test::builtin_model("plate", {Vec3i(8, 8, 2), std::nullopt});
  const std::vector<DirectionFrame> frames(static_cast<std::size_t>(m.volume.cell_count()));
  for (const double w_e : {0.0, 1.0}) {
    for (const EigenvalueSolver solver : {EigenvalueSolver::cholesky, EigenvalueSolver::paper_cg}) {
      DesignWeights w;
      w.equilibrium = w_e;
      EigenvalueInterpolator interp(m.volume, w);
      std::vector<EigenvalueTarget> targets = {{0, Vec3(20, 10, 0)}};
      ASSERT_EQ(interp.solve(frames, targets, solver).eigenvalues_kPa.size(), static_cast<std::size_t>(m.volume.cell_count()));
      targets.push_back({5, Vec3(kNaN, 10, 0)});
      const std::string message = compute_error([&] { interp.solve(frames, targets, solver); });
      EXPECT_TRUE(starts_with(message, "eigenvalue interpolation: ")) << "w_E " << w_e << ": " << message;
    }
  }
}

TEST(NumericalSafety, EquilibrationRefusesForcesThatOverflow) {
  const TissueModel m = test::builtin_model("plate", {Vec3i(8, 8, 2), std::nullopt});
  std::vector<Vec6> stress(static_cast<std::size_t>(m.volume.cell_count()), Vec6::Zero());
  stress[0] << 1e307, -1e307, 1e307, 0, 0, 0;  // finite, but T sigma overflows
  stress[1] << -1e307, 1e307, -1e307, 0, 0, 0;
  const std::string message = compute_error([&] { equilibrate_stress(m, stress); });
  EXPECT_TRUE(starts_with(message, "stress equilibration: ")) << message;
}

}  // namespace
}  // namespace cleave
