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

std::vector<nlohmann::json> run_quick_bench() {
  const std::string command = std::string(CLEAVE_CLI_PATH) + " bench --quick --json --quiet";
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
    for (const char* peer : {"paper", "eigen_cg", "cholmod"}) {
      SCOPED_TRACE(peer);
      ASSERT_TRUE(m["peers"].contains(peer));
      const nlohmann::json& p = m["peers"][peer];
      ASSERT_TRUE(p.contains("relative_difference"));
      for (const auto& [stage, difference] : p["relative_difference"].items()) {
        SCOPED_TRACE(stage);
        EXPECT_LT(difference.get<double>(), stage == "vector" ? kFrameAgreementTolerance : kAgreementTolerance);
      }
      EXPECT_TRUE(p["relative_difference"].contains("step"));
      EXPECT_TRUE(p["relative_difference"].contains("preview"));
    }
  }
}

}  // namespace
}  // namespace cleave::bench
