#pragma once
// The cube element's matrices in the corner-mode basis. The 8 corner values of a trilinear cube
// become 8 modes by the Walsh-Hadamard transform H(m, a) = (-1)^popcount(m & a) (H H = 8 I):
// mode 0 is the mean, modes 1, 2, 4 the linear ramps along x, y, z, modes 3, 5, 6 the bilinear
// xy, xz, yz and mode 7 the trilinear xyz. Derivatives of these modes are again modes times
// constants, and the cube's integrals (exact, and by 2 x 2 x 2 Gauss points) of products of
// distinct ones vanish, so every 8 x 8 block of an isotropic K^e (K(3 a + i, 3 b + j)) and every
// stress stiffness G_k is, in modes, a diagonal times a fixed pairing of modes: at most one
// entry per row. A block's product is then 8 multiplies and one lane permutation instead of 64
// multiply-adds (fem/corotated_cells_avx512.hpp).
//
//   if (auto form = corner_mode_form(k)) ...  // f_i = H sum_j form[3 i + j] .* pair_ij(H d_j)
//
// pair_ij is the identity for i == j and swaps the mode bits i and j otherwise (x <-> y ramps,
// xz <-> yz for i, j = x, y); G_k pairs as its Voigt component (xx, yy, zz: identity; xy, xz,
// yz: swap those bits).
#include <array>
#include <optional>

#include "cleave/fem/hex8_element.hpp"

namespace cleave {

using Vec8 = Eigen::Matrix<double, 8, 1>;

/// The Walsh-Hadamard matrix on the 8 corners (corner a = x + 2 y + 4 z, mode bits likewise).
Mat8 corner_mode_transform();

/// The mode that `mode` pairs with in block (i, j) (axes 0-2): `mode` itself for i == j, else
/// `mode` with bits i and j swapped.
int paired_mode(int i, int j, int mode);

/// The 9 blocks of `stiffness` (24 x 24, dof 3 a + i) in modes, divided by 64: [3 i + j](m) is
/// (H K_ij H)(m, paired_mode(i, j, m)) / 64, so that f_i = H sum_j c_ij .* d^_j(paired) with
/// d^_j = H d_j; coefficients within `tolerance` times the largest mode entry of zero are zero.
/// Nothing where an entry off the pairing exceeds that (a material that is not isotropic, a cell
/// that is not a cube).
std::optional<std::array<Vec8, 9>> corner_mode_form(const Mat24& stiffness, double tolerance = 1e-10);

/// The six stress stiffness matrices G_k (Voigt: xx, yy, zz, xy, xz, yz) in modes, divided by
/// 64, paired as their components; nothing where one does not hold that form.
std::optional<std::array<Vec8, 6>> corner_mode_form(const std::array<Mat8, 6>& stress_basis, double tolerance = 1e-10);

}  // namespace cleave
