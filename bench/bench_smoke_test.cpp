// Smoke test of `cleave bench`: the quick run prints one well-formed JSON object per model, and
// every peer's results agree with cleave's. Timings are never asserted (they belong to the
// benchmark, not to tests); only shapes, counts and agreement are.
#include <gtest/gtest.h>

#include <array>
#include <cstdio>
#include <memory>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "bench_models.hpp"
#include "bench_scenario.hpp"
#include "cleave/fem/dynamics.hpp"
#include "cleave/core/address_sanitizer.hpp"
#include "cleave/shapes/builtin_shapes.hpp"
#include "implementation_setup.hpp"
#include "timing_statistics.hpp"

namespace cleave::bench {
namespace {

// Peers solve to the same relative tolerance (1e-8) as cleave; results differing by more than
// this are a real disagreement, not solver noise.
constexpr double kAgreementTolerance = 1e-5;
// Direction frames are compared through their line tensors; in cells where the interpolated line
// tensor is nearly isotropic (far from every stroke) the principal direction is ill-conditioned
// and amplifies the CG's 1e-10 residual, so the frames agree to a looser bound.
constexpr double kFrameAgreementTolerance = 1e-3;
// cleave's dynamic step stops its solve at 1e-5 of the Newmark predictor's residual
// (DynamicsSettings::step_tolerance) while CHOLMOD solves exactly and Eigen CG to 1e-8: after the
// bench's few steps (a cut every step, small displacements) the results differ by 3e-3 to 4.4e-3.
// The step's accuracy against a 1e-12 solve is asserted over 100 steps in
// tests/fem/dynamics_step_tolerance_test.cpp; here a real disagreement (a wrong system) is O(1).
constexpr double kStepAgreementTolerance = 2e-2;
// The budgeted steps (kRealTimeIterationsPerStep iterations each) against cleave's solved ones
// after the same few steps; their accuracy over a whole opening is asserted in
// tests/fem/dynamics_iteration_budget_test.cpp.
constexpr double kStepBudgetAgreementTolerance = 5e-2;

std::vector<nlohmann::json> run_quick_bench(const std::string& arguments = "--quick", const std::string& environment = "") {
  const std::string command = environment + std::string(CLEAVE_CLI_PATH) + " bench " + arguments + " --json --quiet";
  std::unique_ptr<FILE, int (*)(FILE*)> pipe(popen(command.c_str(), "r"), pclose);
  if (!pipe) return {};
  std::string output;
  std::array<char, 4096> buffer{};
  while (std::fgets(buffer.data(), static_cast<int>(buffer.size()), pipe.get()) != nullptr) output += buffer.data();
  std::vector<nlohmann::json> lines;
  std::istringstream in(output);
  std::string line;
  while (std::getline(in, line))
    if (!line.empty()) lines.push_back(nlohmann::json::parse(line));
  return lines;
}

TEST(TimingStatistics, MedianMinMaxOfOddAndEvenCounts) {
  const std::vector<double> odd{5.0, 1.0, 3.0};
  const TimingStatistics a = summarize_timings(odd);
  EXPECT_DOUBLE_EQ(a.median_ms, 3.0);
  EXPECT_DOUBLE_EQ(a.min_ms, 1.0);
  EXPECT_DOUBLE_EQ(a.max_ms, 5.0);
  EXPECT_EQ(a.count, 3);
  const std::vector<double> even{4.0, 1.0, 2.0, 10.0};
  EXPECT_DOUBLE_EQ(summarize_timings(even).median_ms, 3.0);
  EXPECT_EQ(summarize_timings(std::vector<double>{}).count, 0);
}

TEST(RelativeDifference, IsTheNormOfTheDifferenceOverTheReference) {
  Eigen::VectorXd reference(2), other(2);
  reference << 3.0, 4.0;
  other << 3.0, 4.5;
  EXPECT_DOUBLE_EQ(relative_difference(other, reference), 0.1);
  EXPECT_DOUBLE_EQ(relative_difference(Eigen::VectorXd::Zero(2), Eigen::VectorXd::Zero(2)), 0.0);
}

TEST(BenchModels, Table1ModelsCarryThePaperFigures) {
  const std::vector<BenchModel> models = table1_models();
  ASSERT_EQ(models.size(), 4u);
  EXPECT_EQ(models[1].cells, Vec3i(42, 42, 51));
  ASSERT_TRUE(models[1].paper.has_value());
  EXPECT_DOUBLE_EQ(models[1].paper->ms_value, 8951.0);
  EXPECT_EQ(models[3].paper->cells, 45313);
}

TEST(BenchSmoke, QuickRunPrintsOneObjectPerModelAndPeersAgree) {
  const std::vector<nlohmann::json> lines = run_quick_bench();
  ASSERT_EQ(lines.size(), quick_models().size());
  for (const nlohmann::json& m : lines) {
    SCOPED_TRACE(m.value("model", std::string("?")));
    for (const char* key : {"model", "cells", "vertices", "ms_vector", "ms_value", "ms_step", "ms_update", "peak_mb", "iterations", "peers"})
      EXPECT_TRUE(m.contains(key)) << key;
    EXPECT_GT(m["cells"].get<int>(), 0);
    EXPECT_GT(m["vertices"].get<int>(), m["cells"].get<int>() / 2);
    EXPECT_GT(m["peak_mb"].get<double>(), 0.0);
    ASSERT_TRUE(m["ms_step"].is_number());
    EXPECT_GT(m["iterations"]["step"].get<int>(), 0);
    EXPECT_GT(m["iterations"]["equilibrate"].get<int>(), 0);  // the stroke edits unbalance the design
    // The real-time step: the same steps within the budget, close to the solved ones.
    ASSERT_TRUE(m["ms_step_budget"].is_number());
    EXPECT_GT(m["iterations"]["step_budget"].get<int>(), 0);
    EXPECT_LE(m["iterations"]["step_budget"].get<int>(), kRealTimeIterationsPerStep);
    EXPECT_LT(m["relative_difference"]["step_budget"].get<double>(), kStepBudgetAgreementTolerance);
    // The picture comes first; each edit's final design is the picture's edit plus its completion.
    ASSERT_TRUE(m["ms_update_final"].is_number());
    ASSERT_TRUE(m["ms_update_drag_final"].is_number());
    EXPECT_GE(m["ms_update_final"].get<double>(), m["ms_update"].get<double>());
    EXPECT_GE(m["ms_update_drag_final"].get<double>(), m["ms_update_drag"].get<double>());
    // The CLI restarted itself with the heap in huge pages (glibc 2.36 on Debian 12; not under ASan).
    EXPECT_EQ(m["machine"]["malloc_huge_pages"].get<bool>(), !kAddressSanitizer);
    for (const char* peer : {"paper", "eigen_cg", "cholmod"}) {
      SCOPED_TRACE(peer);
      ASSERT_TRUE(m["peers"].contains(peer));
      const nlohmann::json& p = m["peers"][peer];
      ASSERT_TRUE(p.contains("relative_difference"));
      for (const auto& [stage, difference] : p["relative_difference"].items()) {
        SCOPED_TRACE(stage);
        const double tolerance = stage == "vector" ? kFrameAgreementTolerance
                                 : stage == "step" ? kStepAgreementTolerance
                                                   : kAgreementTolerance;
        EXPECT_LT(difference.get<double>(), tolerance);
      }
      EXPECT_TRUE(p["relative_difference"].contains("step"));
      EXPECT_TRUE(p["ms_step_budget"].is_null());
      EXPECT_EQ(p["skipped"]["step_budget"], "the real-time budget is cleave's; the peers solve every step");
      EXPECT_TRUE(p["relative_difference"].contains("preview"));
    }
  }
}

// CLEAVE_HUGE_PAGES=0 keeps the allocator as the C library starts it: no restart, no huge pages.
TEST(BenchSmoke, HugePagesCanBeTurnedOff) {
  const std::vector<nlohmann::json> lines = run_quick_bench("--quick --models quick-tube --peers none --repeat 1", "CLEAVE_HUGE_PAGES=0 ");
  ASSERT_EQ(lines.size(), 1u);
  EXPECT_FALSE(lines[0]["machine"]["malloc_huge_pages"].get<bool>());
}

TEST(BenchSmoke, AboveDesignMaxCellsTheDesignIsSkippedAndTheSolverStagesRunOnThePrescribedStress) {
  const std::vector<nlohmann::json> lines = run_quick_bench("--models quick-tube --peers none --repeat 1 --design-max-cells 100");
  ASSERT_EQ(lines.size(), 1u);
  const nlohmann::json& m = lines.front();
  EXPECT_EQ(m["residual_stress"], "prescribed");
  for (const char* stage : {"vector", "value", "value_point", "equilibrate", "update", "update_final", "update_drag_final"}) {
    SCOPED_TRACE(stage);
    EXPECT_TRUE(m["ms_" + std::string(stage)].is_null());
    ASSERT_TRUE(m["skipped"].contains(stage));
    EXPECT_NE(m["skipped"][stage].get<std::string>().find("--design-max-cells 100"), std::string::npos);
  }
  ASSERT_TRUE(m["ms_preview"].is_number());
  ASSERT_TRUE(m["ms_step"].is_number());
  EXPECT_GT(m["iterations"]["preview"].get<int>(), 0);
  EXPECT_GT(m["iterations"]["step"].get<int>(), 0);
}

TEST(BenchScenario, PrescribedStressIsBiaxialAboutTheZAxis) {
  TissueModel model = make_tissue_model("cylinder", make_builtin_shape("cylinder", {Vec3i{12, 12, 10}, std::nullopt}));
  const std::vector<Vec6> stress = prescribed_biaxial_stress(model, 20.0, 10.0);
  ASSERT_EQ(stress.size(), static_cast<std::size_t>(model.volume.cell_count()));
  const auto [lo, hi] = model.bounding_box_mm();
  const Vec3 centre = 0.5 * (lo + hi);
  for (CellId c = 0; c < model.volume.cell_count(); c += 17) {
    const Mat3 s = from_voigt(stress[static_cast<std::size_t>(c)]);
    Vec3 radial = model.volume.cell_center_mm(c) - centre;
    radial.z() = 0;
    radial.normalize();
    const Vec3 around = Vec3::UnitZ().cross(radial);
    EXPECT_NEAR(around.dot(s * around), 20.0, 1e-9);
    EXPECT_NEAR(s(2, 2), 10.0, 1e-9);
    EXPECT_NEAR(radial.dot(s * radial), 0.0, 1e-9);
  }
}

// The update edits move stroke 0 among three positions in turn: with two remembered results per
// stage, an edit that repeated one of the last two designs would time a recall, not an update.
TEST(BenchScenario, UpdateEditsCycleThroughThreeDistinctStrokePositions) {
  TissueModel model = make_tissue_model("cylinder", make_builtin_shape("cylinder", {Vec3i{12, 12, 10}, std::nullopt}));
  const BenchScenario scenario = make_bench_scenario(model, ScenarioOptions{});
  ASSERT_EQ(scenario.edited_strokes.size(), 2U);
  const std::vector<Vec3>& own = scenario.design.strokes.front().points_mm;
  const std::vector<Vec3>& first = scenario.edited_strokes[0].points_mm;
  const std::vector<Vec3>& second = scenario.edited_strokes[1].points_mm;
  EXPECT_NE(first, own);
  EXPECT_NE(second, own);
  EXPECT_NE(first, second);
}

}  // namespace
}  // namespace cleave::bench
