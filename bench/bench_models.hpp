#pragma once
// The models `cleave bench` measures: the four of the paper's Table 1 (with the paper's own
// figures, one core of an Intel Core 2 Quad Q9450 at 2.66 GHz, 2008), the large tubes of
// `--large`, the tube series of the scaling curve, and the tiny models of `--quick`.
//
//   for (const BenchModel& m : table1_models()) ...   // m.shape = "cylinder", m.cells = {21, 21, 26}
//   BenchModel m = bench_model_by_key("cylinder-42");  // InputError listing the keys when unknown
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "cleave/core/types.hpp"

namespace cleave::bench {

/// Table 1 of Wu et al. 2012: cells, vertices and times (ms) on one 2008 core.
struct PaperFigures {
  int cells = 0;
  int vertices = 0;
  double ms_vector = 0;  ///< eigenvector interpolation (Langer + normal, orthonormalization)
  double ms_value = 0;   ///< eigenvalue interpolation (Laplacian + equilibrium, CG on normal equations)
  double ms_step = 0;    ///< one dynamic simulation step (corotational, implicit Newmark, multigrid)
};

struct BenchModel {
  std::string key;    ///< "cylinder-21", "abdomen-126", "tube-120", ...
  std::string shape;  ///< built-in shape name: "cylinder" or "abdomen"
  Vec3i cells = Vec3i::Zero();  ///< grid resolution NX x NY x NZ
  std::optional<PaperFigures> paper;  ///< present for the four Table 1 models
};

/// The four models of Table 1, in the paper's order.
std::vector<BenchModel> table1_models();
/// `--large`: the tube at 84x84x102 (about 350,000 cells) and 120x120x146 (over 1 million).
std::vector<BenchModel> large_models();
/// The tube at increasing resolution, about 5,000 to over 1 million cells (scaling curve; tube-100 is
/// about 590,000 cells, the largest whose solver stages fit beside other work on a 23 GB machine).
std::vector<BenchModel> scaling_models();
/// `--quick`: a small tube and a small abdomen (seconds in total; for smoke tests).
std::vector<BenchModel> quick_models();

/// Any model above by key; throws InputError naming the key and listing the known ones.
BenchModel bench_model_by_key(std::string_view key);

}  // namespace cleave::bench
