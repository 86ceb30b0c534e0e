#pragma once
// Shared by the DISABLED_ benchmark harnesses (run only on request): the paper's 44,000-cell tube
// and a median wall time.
#include <algorithm>
#include <chrono>
#include <vector>

#include "cleave/model/tissue_model.hpp"
#include "cleave/shapes/builtin_shapes.hpp"

namespace cleave::test {

/// The paper's 44,000-cell tube (42 x 42 x 51), soft tissue E = 3 kPa, nu = 0.45.
inline TissueModel tube_44k() {
  ShapeResolution resolution;
  resolution.cells = Vec3i(42, 42, 51);
  Material m;
  m.youngs_modulus_kPa = 3.0;
  m.poisson_ratio = 0.45;
  return make_tissue_model("cylinder", make_builtin_shape("cylinder", resolution), {{Label{1}, m}});
}

/// Median wall time (ms) of 31 calls.
template <typename Work>
double median_ms(Work&& work) {
  std::vector<double> ms;
  for (int i = 0; i < 31; ++i) {
    const auto start = std::chrono::steady_clock::now();
    work();
    ms.push_back(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count());
  }
  std::sort(ms.begin(), ms.end());
  return ms[ms.size() / 2];
}

}  // namespace cleave::test
