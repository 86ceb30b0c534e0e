#include "bench_models.hpp"

#include <fmt/format.h>

#include <algorithm>

#include "cleave/core/error.hpp"

namespace cleave::bench {
namespace {

BenchModel tube(int n_across, int n_along) {
  return {fmt::format("tube-{}", n_across), "cylinder", Vec3i{n_across, n_across, n_along}, std::nullopt};
}

std::vector<BenchModel> all_models() {
  std::vector<BenchModel> all = table1_models();
  for (auto* list : {&large_models, &scaling_models, &quick_models})
    for (BenchModel& m : (*list)())
      if (std::none_of(all.begin(), all.end(), [&](const BenchModel& known) { return known.key == m.key; }))
        all.push_back(std::move(m));
  return all;
}

}  // namespace

std::vector<BenchModel> table1_models() {
  return {
      {"cylinder-21", "cylinder", Vec3i{21, 21, 26}, PaperFigures{5550, 7540, 261.4, 215.2, 83.3}},
      {"cylinder-42", "cylinder", Vec3i{42, 42, 51}, PaperFigures{44000, 51714, 5517, 8951, 637.4}},
      {"abdomen-63", "abdomen", Vec3i{63, 21, 42}, PaperFigures{5734, 10189, 155.6, 106.1, 98.6}},
      {"abdomen-126", "abdomen", Vec3i{126, 41, 84}, PaperFigures{45313, 62481, 3046, 3607, 707.8}},
  };
}

std::vector<BenchModel> large_models() { return {tube(84, 102), tube(120, 146)}; }

std::vector<BenchModel> scaling_models() {
  // Cells grow like n^3 (the tube's length grows with its cross-section: nz = 1.2 n + 1).
  return {tube(21, 26), tube(30, 37), tube(42, 51), tube(60, 73), tube(84, 102), tube(100, 121), tube(120, 146)};
}

std::vector<BenchModel> quick_models() {
  return {{"quick-tube", "cylinder", Vec3i{12, 12, 10}, std::nullopt},
          {"quick-abdomen", "abdomen", Vec3i{32, 11, 21}, std::nullopt}};
}

BenchModel bench_model_by_key(std::string_view key) {
  std::vector<BenchModel> all = all_models();
  for (BenchModel& m : all)
    if (m.key == key) return m;
  std::string known;
  for (const BenchModel& m : all) known += (known.empty() ? "" : ", ") + m.key;
  throw InputError(fmt::format("--models: unknown model '{}'; expected one of {}", key, known));
}

}  // namespace cleave::bench
