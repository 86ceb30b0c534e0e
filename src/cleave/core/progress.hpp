#pragma once
// Progress reporting for long work (loads, voxelization, solves). The library never prints;
// applications pass a callback (the CLI draws a bar on stderr, the studio sends messages).
#include <functional>
#include <string_view>

namespace cleave {

/// Called with a stage name and the fraction done in [0, 1]. May be empty (no reporting).
using ProgressFn = std::function<void(std::string_view stage, double fraction)>;

inline void report(const ProgressFn& progress, std::string_view stage, double fraction) {
  if (progress) progress(stage, fraction);
}

}  // namespace cleave
