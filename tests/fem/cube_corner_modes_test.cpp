// The cube's element matrices in corner modes (fem/cube_corner_modes.hpp): the transform, the
// pairings, and products in modes equal to the dense products, for the stiffness of isotropic
// materials and the stress stiffness; a matrix without that form is refused.
#include <gtest/gtest.h>

#include "cleave/fem/cube_corner_modes.hpp"

namespace cleave {
namespace {

/// f_i = H sum_j form[3 i + j] .* (H d_j)(paired): the product as the AVX-512 pass computes it.
Vec24 product_in_modes(const std::array<Vec8, 9>& form, const Vec24& d) {
  const Mat8 h = corner_mode_transform();
  std::array<Vec8, 3> modes;
  for (int j = 0; j < 3; ++j) {
    Vec8 component;
    for (int a = 0; a < 8; ++a) component[a] = d[3 * a + j];
    modes[static_cast<std::size_t>(j)] = h * component;
  }
  Vec24 f;
  for (int i = 0; i < 3; ++i) {
    Vec8 sum = Vec8::Zero();
    for (int j = 0; j < 3; ++j)
      for (int m = 0; m < 8; ++m)
        sum[m] += form[static_cast<std::size_t>(3 * i + j)][m] * modes[static_cast<std::size_t>(j)][paired_mode(i, j, m)];
    const Vec8 corners = h * sum;
    for (int a = 0; a < 8; ++a) f[3 * a + i] = corners[a];
  }
  return f;
}

Vec24 probe() {
  Vec24 d;
  for (int k = 0; k < 24; ++k) d[k] = std::sin(1.3 * k + 0.4) + 0.1 * k;
  return d;
}

TEST(CubeCornerModes, TheTransformIsItsOwnInverseTimesEight) {
  const Mat8 h = corner_mode_transform();
  EXPECT_TRUE((h * h).isApprox(8.0 * Mat8::Identity(), 1e-15));
  EXPECT_EQ(h.row(0), Vec8::Ones().transpose());          // mode 0: the mean
  EXPECT_EQ(h(1, 0), 1.0);                               // mode 1 (x ramp): + at x = 0 ...
  EXPECT_EQ(h(1, 1), -1.0);                              // ... - at x = 1
  EXPECT_EQ(h(7, 7), -1.0);                              // xyz at the far corner
}

TEST(CubeCornerModes, PairingsSwapTheBitsOfTwoAxes) {
  EXPECT_EQ(paired_mode(0, 1, 1), 2);  // x ramp <-> y ramp
  EXPECT_EQ(paired_mode(0, 1, 5), 6);  // xz <-> yz
  EXPECT_EQ(paired_mode(0, 1, 3), 3);  // xy pairs with itself
  EXPECT_EQ(paired_mode(0, 2, 3), 6);  // xy <-> yz
  EXPECT_EQ(paired_mode(1, 2, 3), 5);  // xy <-> xz
  EXPECT_EQ(paired_mode(2, 1, 2), 4);  // symmetric in the axes
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      for (int m = 0; m < 8; ++m) EXPECT_EQ(paired_mode(i, j, paired_mode(i, j, m)), m);  // an involution
  for (int m = 0; m < 8; ++m) EXPECT_EQ(paired_mode(2, 2, m), m);
}

TEST(CubeCornerModes, StiffnessOfIsotropicCubesHasTheFormAndItsProductIsTheDenseOne) {
  for (const double h_mm : {0.5, 2.0})
    for (const double nu : {0.0, 0.3, 0.49}) {
      SCOPED_TRACE(testing::Message() << "h " << h_mm << " mm, nu " << nu);
      const Mat24 k = hex8_stiffness(h_mm, isotropic_elasticity(25.0, nu));
      const auto form = corner_mode_form(k);
      ASSERT_TRUE(form.has_value());
      const Vec24 d = probe();
      const Vec24 dense = k * d;
      EXPECT_LE((product_in_modes(*form, d) - dense).lpNorm<Eigen::Infinity>(), 1e-13 * dense.lpNorm<Eigen::Infinity>());
      // Rigid translations are mode 0 of every component: it carries no coefficient.
      for (const Vec8& block : *form) EXPECT_EQ(block[0], 0.0);
    }
}

TEST(CubeCornerModes, StressStiffnessHasTheFormAndItsProductIsTheDenseOne) {
  const std::array<Mat8, 6> basis = hex8_stress_stiffness_basis(1.5);
  const auto form = corner_mode_form(basis);
  ASSERT_TRUE(form.has_value());
  Eigen::Matrix<double, 6, 1> t;
  t << 12.0, -3.0, 5.0, 2.5, -1.0, 4.0;
  Mat8 s = Mat8::Zero();
  for (std::size_t q = 0; q < 6; ++q) s += t[static_cast<Eigen::Index>(q)] * basis[q];
  // One component's values (s acts on each alike): the normal parts on the modes themselves,
  // the shear parts on the modes paired across their axes.
  const Mat8 h = corner_mode_transform();
  constexpr std::array<std::array<int, 2>, 6> axes = {{{0, 0}, {1, 1}, {2, 2}, {0, 1}, {0, 2}, {1, 2}}};
  Vec8 d;
  for (int a = 0; a < 8; ++a) d[a] = std::cos(0.7 * a) + 0.2 * a;
  const Vec8 modes = h * d;
  Vec8 sum = Vec8::Zero();
  for (std::size_t q = 0; q < 6; ++q)
    for (int m = 0; m < 8; ++m)
      sum[m] += t[static_cast<Eigen::Index>(q)] * (*form)[q][m] * modes[paired_mode(axes[q][0], axes[q][1], m)];
  const Vec8 dense = s * d;
  EXPECT_LE((h * sum - dense).lpNorm<Eigen::Infinity>(), 1e-13 * dense.lpNorm<Eigen::Infinity>());
}

TEST(CubeCornerModes, AMatrixWithoutTheFormIsRefused) {
  // Normal-shear coupling (an anisotropic material): the x-x block couples the x ramp with y.
  Mat6 anisotropic = isotropic_elasticity(25.0, 0.3);
  anisotropic(0, 3) = anisotropic(3, 0) = 4.0;
  EXPECT_FALSE(corner_mode_form(hex8_stiffness(1.0, anisotropic)).has_value());
  // One entry off the pairing, at 1e-6 of the largest: above the tolerance.
  Mat24 k = hex8_stiffness(1.0, isotropic_elasticity(25.0, 0.3));
  const double largest = k.cwiseAbs().maxCoeff();
  k(0, 1) += 1e-6 * largest;
  k(1, 0) += 1e-6 * largest;
  EXPECT_FALSE(corner_mode_form(k).has_value());
  std::array<Mat8, 6> basis = hex8_stress_stiffness_basis(1.0);
  basis[3](0, 0) += 0.1;  // the xy part with a diagonal entry
  EXPECT_FALSE(corner_mode_form(basis).has_value());
}

}  // namespace
}  // namespace cleave
