#include "cleave/fem/hex8_element.hpp"

#include <array>
#include <cmath>

namespace cleave {
namespace {

/// 2-point Gauss rule on [0, 1]: points 1/2 -+ 1/(2 sqrt 3), weights 1/2 each.
constexpr std::array<double, 2> kGaussPoints{0.5 - 0.5 / 1.7320508075688772, 0.5 + 0.5 / 1.7320508075688772};
constexpr double kGaussWeight = 0.5;

/// Gradient of N_a with respect to xi (local coordinates in [0, 1]^3).
Eigen::Matrix<double, 8, 3> shape_gradients_local(const Vec3& xi) {
  Eigen::Matrix<double, 8, 3> g;
  for (int a = 0; a < 8; ++a) {
    const Vec3 s{static_cast<double>(a & 1), static_cast<double>((a >> 1) & 1), static_cast<double>((a >> 2) & 1)};
    // 1D factor: xi for s = 1, 1 - xi for s = 0; derivative +1 or -1.
    Vec3 f, df;
    for (int d = 0; d < 3; ++d) {
      f[d] = s[d] > 0 ? xi[d] : 1.0 - xi[d];
      df[d] = s[d] > 0 ? 1.0 : -1.0;
    }
    g(a, 0) = df[0] * f[1] * f[2];
    g(a, 1) = f[0] * df[1] * f[2];
    g(a, 2) = f[0] * f[1] * df[2];
  }
  return g;
}

template <typename Integrand>
void for_each_gauss_point(double h_mm, Integrand&& integrand) {
  const double weight = kGaussWeight * kGaussWeight * kGaussWeight * h_mm * h_mm * h_mm;
  for (double z : kGaussPoints)
    for (double y : kGaussPoints)
      for (double x : kGaussPoints) integrand(Vec3{x, y, z}, weight);
}

}  // namespace

Mat6 isotropic_elasticity(double E, double nu) {
  const double lambda = E * nu / ((1 + nu) * (1 - 2 * nu));
  const double mu = E / (2 * (1 + nu));
  Mat6 d = Mat6::Zero();
  d.topLeftCorner<3, 3>().setConstant(lambda);
  for (int i = 0; i < 3; ++i) d(i, i) = lambda + 2 * mu;
  for (int i = 3; i < 6; ++i) d(i, i) = mu;
  return d;
}

Eigen::Matrix<double, 8, 1> hex8_shape_functions(const Vec3& xi) {
  Eigen::Matrix<double, 8, 1> n;
  for (int a = 0; a < 8; ++a)
    n[a] = ((a & 1) ? xi.x() : 1 - xi.x()) * (((a >> 1) & 1) ? xi.y() : 1 - xi.y()) *
           (((a >> 2) & 1) ? xi.z() : 1 - xi.z());
  return n;
}

Mat6x24 hex8_strain_matrix(const Vec3& xi, double h_mm) {
  const Eigen::Matrix<double, 8, 3> g = shape_gradients_local(xi) / h_mm;
  Mat6x24 b = Mat6x24::Zero();
  for (int a = 0; a < 8; ++a) {
    const int c = 3 * a;
    b(0, c + 0) = g(a, 0);
    b(1, c + 1) = g(a, 1);
    b(2, c + 2) = g(a, 2);
    b(3, c + 0) = g(a, 1);  // gamma_xy
    b(3, c + 1) = g(a, 0);
    b(4, c + 0) = g(a, 2);  // gamma_xz
    b(4, c + 2) = g(a, 0);
    b(5, c + 1) = g(a, 2);  // gamma_yz
    b(5, c + 2) = g(a, 1);
  }
  return b;
}

Mat24 hex8_stiffness(double h_mm, const Mat6& elasticity) {
  Mat24 k = Mat24::Zero();
  for_each_gauss_point(h_mm, [&](const Vec3& xi, double w) {
    const Mat6x24 b = hex8_strain_matrix(xi, h_mm);
    k.noalias() += w * b.transpose() * elasticity * b;
  });
  return k;
}

Mat24x6 hex8_stress_divergence(double h_mm) {
  Mat24x6 t = Mat24x6::Zero();
  for_each_gauss_point(h_mm, [&](const Vec3& xi, double w) { t.noalias() += w * hex8_strain_matrix(xi, h_mm).transpose(); });
  return t;
}

std::array<Mat8, 6> hex8_stress_stiffness_basis(double h_mm) {
  // Voigt k -> (i, j): xx, yy, zz, xy, xz, yz.
  constexpr std::array<std::array<int, 2>, 6> kIndices{{{0, 0}, {1, 1}, {2, 2}, {0, 1}, {0, 2}, {1, 2}}};
  std::array<Mat8, 6> g;
  for (Mat8& m : g) m.setZero();
  for_each_gauss_point(h_mm, [&](const Vec3& xi, double w) {
    const Eigen::Matrix<double, 8, 3> grad = shape_gradients_local(xi) / h_mm;
    for (int k = 0; k < 6; ++k) {
      const int i = kIndices[static_cast<std::size_t>(k)][0], j = kIndices[static_cast<std::size_t>(k)][1];
      Mat8 term = grad.col(i) * grad.col(j).transpose();
      if (i != j) term += grad.col(j) * grad.col(i).transpose();
      g[static_cast<std::size_t>(k)] += w * term;
    }
  });
  return g;
}

Mat24 hex8_consistent_mass(double h_mm, double density_kg_per_mm3) {
  Mat24 m = Mat24::Zero();
  for_each_gauss_point(h_mm, [&](const Vec3& xi, double w) {
    const Eigen::Matrix<double, 8, 1> n = hex8_shape_functions(xi);
    for (int a = 0; a < 8; ++a)
      for (int b = 0; b < 8; ++b)
        for (int d = 0; d < 3; ++d) m(3 * a + d, 3 * b + d) += w * density_kg_per_mm3 * n[a] * n[b];
  });
  return m;
}

Mat3 hex8_center_deformation_gradient(const Vec24& u, double h_mm) {
  // At the centre dN_a/dx_j = s_j / (4 h), s the corner's outward signs (+-1): column j of
  // F - I is the sum of u over the corners on the far side of axis j minus those on the near side.
  // Every step takes it for every cell: sums and differences, no products.
  Mat3 f = Mat3::Zero();
  for (int a = 0; a < 8; ++a) {
    const Vec3 ua = u.segment<3>(3 * a);
    for (int j = 0; j < 3; ++j) {
      if (((a >> j) & 1) != 0) f.col(j) += ua;
      else f.col(j) -= ua;
    }
  }
  f *= 0.25 / h_mm;
  f.diagonal().array() += 1.0;
  return f;
}

}  // namespace cleave
