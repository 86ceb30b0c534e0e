#include "cleave/fem/cube_corner_modes.hpp"

#include <algorithm>
#include <bit>
#include <cmath>

namespace cleave {
namespace {

/// The axes whose mode bits G_k swaps (Voigt order); equal axes: the identity.
constexpr std::array<std::array<int, 2>, 6> kVoigtAxes = {{{0, 0}, {1, 1}, {2, 2}, {0, 1}, {0, 2}, {1, 2}}};

/// (H block H)(m, paired_mode(i, j, m)) / 64 into `coefficients`; false where an entry off the
/// pairing exceeds tolerance times `scale`.
bool paired_coefficients(const Mat8& block, int i, int j, double scale, double tolerance, Vec8& coefficients) {
  const Mat8 h = corner_mode_transform();
  const Mat8 modes = h * block * h;
  for (int m = 0; m < 8; ++m) {
    const int partner = paired_mode(i, j, m);
    for (int n = 0; n < 8; ++n)
      if (n != partner && std::abs(modes(m, n)) > tolerance * scale) return false;
    const double entry = modes(m, partner);
    coefficients[m] = std::abs(entry) > tolerance * scale ? entry / 64.0 : 0.0;  // rounding of a zero: zero
  }
  return true;
}

}  // namespace

Mat8 corner_mode_transform() {
  Mat8 h;
  for (int m = 0; m < 8; ++m)
    for (int a = 0; a < 8; ++a) h(m, a) = std::popcount(static_cast<unsigned>(m & a)) % 2 == 0 ? 1.0 : -1.0;
  return h;
}

int paired_mode(int i, int j, int mode) {
  if (i == j) return mode;
  const int bit_i = (mode >> i) & 1;
  const int bit_j = (mode >> j) & 1;
  return (mode & ~((1 << i) | (1 << j))) | (bit_i << j) | (bit_j << i);
}

std::optional<std::array<Vec8, 9>> corner_mode_form(const Mat24& stiffness, double tolerance) {
  // The scale is the largest mode entry, at most 64 times the largest matrix entry.
  const double scale = 64.0 * stiffness.cwiseAbs().maxCoeff();
  std::array<Vec8, 9> form;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) {
      Mat8 block;
      for (int a = 0; a < 8; ++a)
        for (int b = 0; b < 8; ++b) block(a, b) = stiffness(3 * a + i, 3 * b + j);
      if (!paired_coefficients(block, i, j, scale, tolerance, form[static_cast<std::size_t>(3 * i + j)])) return std::nullopt;
    }
  return form;
}

std::optional<std::array<Vec8, 6>> corner_mode_form(const std::array<Mat8, 6>& stress_basis, double tolerance) {
  double largest = 0;
  for (const Mat8& g : stress_basis) largest = std::max(largest, g.cwiseAbs().maxCoeff());
  std::array<Vec8, 6> form;
  for (std::size_t k = 0; k < 6; ++k)
    if (!paired_coefficients(stress_basis[k], kVoigtAxes[k][0], kVoigtAxes[k][1], 64.0 * largest, tolerance, form[k]))
      return std::nullopt;
  return form;
}

}  // namespace cleave
