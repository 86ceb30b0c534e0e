// Compiled with -mavx512f -mavx512dq (src/cleave/CMakeLists.txt); see the header for why this
// file includes nothing but the intrinsics.
#include "cleave/fem/corotated_cells_avx512.hpp"

#if defined(__AVX512F__) && defined(__AVX512DQ__)
#include <immintrin.h>

namespace cleave {

const bool kAvx512CellPassCompiled = true;

namespace {

/// A permute index that fills the lower half with lane `lower` and the upper with lane `upper`.
__m512i halves(int lower, int upper) {
  return _mm512_inserti64x4(_mm512_castsi256_si512(_mm256_set1_epi32(lower)), _mm256_set1_epi32(upper), 1);
}

/// Two 8-float rows side by side: [first, second].
__m512 pair(const float* first, const float* second) {
  return _mm512_insertf32x8(_mm512_castps256_ps512(_mm256_loadu_ps(first)), _mm256_loadu_ps(second), 1);
}

/// Two 8-id rows side by side: [first, second].
__m512i pair_ids(const std::int32_t* first, const std::int32_t* second) {
  return _mm512_inserti64x4(_mm512_castsi256_si512(_mm256_loadu_si256(reinterpret_cast<const __m256i*>(first))),
                            _mm256_loadu_si256(reinterpret_cast<const __m256i*>(second)), 1);
}

/// +1 in the lanes whose index has `bit` clear, -1 where it is set.
__m512 butterfly_signs(int bit) {
  alignas(64) float signs[16];
  for (int lane = 0; lane < 16; ++lane) signs[lane] = (lane & bit) != 0 ? -1.0f : 1.0f;
  return _mm512_load_ps(signs);
}
__m512d butterfly_signs_double(int bit) {
  alignas(64) double signs[8];
  for (int lane = 0; lane < 8; ++lane) signs[lane] = (lane & bit) != 0 ? -1.0 : 1.0;
  return _mm512_load_pd(signs);
}

/// `mode` (0-7) with its bits `first` and `second` swapped (paired_mode of
/// fem/cube_corner_modes.hpp, which this file cannot include).
int bits_swapped(int mode, int first, int second) {
  const int a = (mode >> first) & 1;
  const int b = (mode >> second) & 1;
  return (mode & ~((1 << first) | (1 << second))) | (a << second) | (b << first);
}

/// Lane permutations within each 8-lane half that swap two bits of the lane index (the mode
/// pairings): [0, 2, 1, 3, ...] for bits 0 and 1, and so on.
__m512i swapping_bits(int first, int second) {
  alignas(64) std::int32_t index[16];
  for (int lane = 0; lane < 16; ++lane) index[lane] = (lane & 8) | bits_swapped(lane & 7, first, second);
  return _mm512_load_si512(index);
}
__m512i swapping_bits_double(int first, int second) {
  alignas(64) std::int64_t index[8];
  for (int m = 0; m < 8; ++m) index[m] = bits_swapped(m, first, second);
  return _mm512_load_si512(index);
}

/// The constants of a pass, made once per call of the kernel.
struct FloatConstants {
  __m512 sign[3] = {butterfly_signs(1), butterfly_signs(2), butterfly_signs(4)};
  __m512i swap_xz = swapping_bits(0, 2);
  __m512i swap_yz = swapping_bits(1, 2);
  /// [single][k]: the permutes that spread R(k) (k = 3 j + i) of each cell over its half, from
  /// [R_c, first 7 of R_{c+1}] and [last 2 of R_{c+1}] (single: R_c alone in both halves).
  __m512i rotation_spread[2][9];
  /// [single][q]: the permutes that spread t_q of each cell over its half, from [t_c, t_{c+1}].
  __m512i tension_spread[2][6];
  FloatConstants() {
    for (int k = 0; k < 9; ++k) {
      rotation_spread[0][k] = halves(k, 9 + k);
      rotation_spread[1][k] = halves(k, k);
    }
    for (int q = 0; q < 6; ++q) {
      tension_spread[0][q] = halves(q, 6 + q);
      tension_spread[1][q] = halves(q, q);
    }
  }
};
struct DoubleConstants {
  __m512d sign[3] = {butterfly_signs_double(1), butterfly_signs_double(2), butterfly_signs_double(4)};
  __m512i swap_xy = swapping_bits_double(0, 1);
  __m512i swap_xz = swapping_bits_double(0, 2);
  __m512i swap_yz = swapping_bits_double(1, 2);
};

/// The Walsh-Hadamard transform of each 8-lane half (it is its own inverse times 8): three
/// butterflies, lane a with lane a ^ bit, the sum where the bit is clear and the difference
/// where it is set.
__m512 corner_modes(__m512 v, const FloatConstants& k) {
  v = _mm512_fmadd_ps(v, k.sign[0], _mm512_permute_ps(v, 0xB1));                        // lanes 1 0 3 2
  v = _mm512_fmadd_ps(v, k.sign[1], _mm512_permute_ps(v, 0x4E));                        // lanes 2 3 0 1
  return _mm512_fmadd_ps(v, k.sign[2], _mm512_shuffle_f32x4(v, v, _MM_SHUFFLE(2, 3, 0, 1)));  // 4-lane groups swapped
}
__m512d corner_modes(__m512d v, const DoubleConstants& k) {
  v = _mm512_fmadd_pd(v, k.sign[0], _mm512_permute_pd(v, 0x55));
  v = _mm512_fmadd_pd(v, k.sign[1], _mm512_permutex_pd(v, _MM_SHUFFLE(1, 0, 3, 2)));
  return _mm512_fmadd_pd(v, k.sign[2], _mm512_shuffle_f64x2(v, v, _MM_SHUFFLE(1, 0, 3, 2)));
}

/// Modes paired across x and y (bits 0 and 1): within each 4-lane group, lanes 0 2 1 3.
__m512 paired_xy(__m512 v) { return _mm512_permute_ps(v, 0xD8); }

/// Cells c and c + 1 (or c twice, `single`: only c is written).
void cell_pair(const CorotatedCellsInput& in, const FloatConstants& constants, std::size_t c, bool single) {
  const std::size_t d = single ? c : c + 1;
  // The corners' x, y, z (world).
  const __m512i corner_ids = pair_ids(in.corners + 8 * c, in.corners + 8 * d);
  const __m512i offsets = _mm512_mullo_epi32(corner_ids, _mm512_set1_epi32(3));
  __m512 world[3];
  for (int j = 0; j < 3; ++j) world[j] = _mm512_i32gather_ps(offsets, in.x + j, 4);
  // R(i, j) of each cell spread over its half: [R_c(i, j) x 8, R_d(i, j) x 8], k = 3 j + i.
  __m512 rotation[9];
  {
    // R_c (9 floats) and R_{c+1}'s first 7, then its last 2; a single cell reads only its own 9.
    const __m512 lower = _mm512_maskz_loadu_ps(single ? 0x1FF : 0xFFFF, in.rotation + 9 * c);
    const __m512 upper = _mm512_maskz_loadu_ps(single ? 0x0 : 0x3, in.rotation + 9 * c + 16);
    for (int k = 0; k < 9; ++k) rotation[k] = _mm512_permutex2var_ps(lower, constants.rotation_spread[single][k], upper);
  }
  // Into the cells' frames, d_i = sum_j R_ji x_j, and into modes.
  __m512 local[3];
  for (int i = 0; i < 3; ++i) {
    local[i] = _mm512_mul_ps(rotation[3 * i + 0], world[0]);
    local[i] = _mm512_fmadd_ps(rotation[3 * i + 1], world[1], local[i]);
    local[i] = _mm512_fmadd_ps(rotation[3 * i + 2], world[2], local[i]);
    local[i] = corner_modes(local[i], constants);
  }
  // The blocks' mode coefficients, [3 i + j], each cell's in its half.
  const float* k_c = in.stiffness_modes + 72 * static_cast<std::size_t>(in.material[c]);
  const float* k_d = in.stiffness_modes + 72 * static_cast<std::size_t>(in.material[d]);
  __m512 k[9];
  for (std::size_t b = 0; b < 9; ++b)
    k[b] = k_c == k_d ? _mm512_broadcast_f32x8(_mm256_loadu_ps(k_c + 8 * b)) : pair(k_c + 8 * b, k_d + 8 * b);
  // The mode pairings: by_xy[j] is d^_j with the x and y modes swapped, and so on.
  __m512 by_xy[3], by_xz[3], by_yz[3];
  for (int j = 0; j < 3; ++j) {
    by_xy[j] = paired_xy(local[j]);
    by_xz[j] = _mm512_permutexvar_ps(constants.swap_xz, local[j]);
    by_yz[j] = _mm512_permutexvar_ps(constants.swap_yz, local[j]);
  }
  // f^_i = k_ii d^_i + sum_{j != i} k_ij (d^_j paired as i, j).
  __m512 f[3];
  f[0] = _mm512_fmadd_ps(k[2], by_xz[2], _mm512_fmadd_ps(k[1], by_xy[1], _mm512_mul_ps(k[0], local[0])));
  f[1] = _mm512_fmadd_ps(k[5], by_yz[2], _mm512_fmadd_ps(k[3], by_xy[0], _mm512_mul_ps(k[4], local[1])));
  f[2] = _mm512_fmadd_ps(k[7], by_yz[1], _mm512_fmadd_ps(k[6], by_xz[0], _mm512_mul_ps(k[8], local[2])));
  if (in.tension != nullptr) {
    // s = sum_q t_q G_q for each component alike: the normal parts on the modes themselves, the
    // shear parts on the pairs. t_q of each cell spread over its half (6 + 6 floats).
    const __m512 t = _mm512_maskz_loadu_ps(single ? 0x3F : 0xFFF, in.tension + 6 * c);
    __m512 spread[6];
    for (int q = 0; q < 6; ++q) spread[q] = _mm512_permutexvar_ps(constants.tension_spread[single][q], t);
    __m512 g[6];
    for (std::size_t q = 0; q < 6; ++q) g[q] = _mm512_mul_ps(spread[q], _mm512_broadcast_f32x8(_mm256_loadu_ps(in.stress_modes + 8 * q)));
    const __m512 normal = _mm512_add_ps(g[0], _mm512_add_ps(g[1], g[2]));
    for (int i = 0; i < 3; ++i) {
      f[i] = _mm512_fmadd_ps(normal, local[i], f[i]);
      f[i] = _mm512_fmadd_ps(g[3], by_xy[i], f[i]);
      f[i] = _mm512_fmadd_ps(g[4], by_xz[i], f[i]);
      f[i] = _mm512_fmadd_ps(g[5], by_yz[i], f[i]);
    }
  }
  // Back to the corners (the 1 / 64 is in the coefficients) and into the world: out_i = sum_j R_ij f_j.
  for (int i = 0; i < 3; ++i) f[i] = corner_modes(f[i], constants);
  __m512 out[3];
  for (int i = 0; i < 3; ++i) {
    out[i] = _mm512_mul_ps(rotation[i], f[0]);
    out[i] = _mm512_fmadd_ps(rotation[3 + i], f[1], out[i]);
    out[i] = _mm512_fmadd_ps(rotation[6 + i], f[2], out[i]);
  }
  // Cell c's x, y, z (lower halves), then cell c + 1's (upper halves): 48 floats in a row.
  float* to = in.per_cell + 24 * c;
  _mm512_storeu_ps(to, _mm512_shuffle_f32x4(out[0], out[1], _MM_SHUFFLE(1, 0, 1, 0)));
  if (single) {
    _mm256_storeu_ps(to + 16, _mm512_castps512_ps256(out[2]));
    return;
  }
  _mm512_storeu_ps(to + 16, _mm512_shuffle_f32x4(out[2], out[0], _MM_SHUFFLE(3, 2, 1, 0)));
  _mm512_storeu_ps(to + 32, _mm512_shuffle_f32x4(out[1], out[2], _MM_SHUFFLE(3, 2, 3, 2)));
}

/// f^_i = k_ii d^_i + sum_{j != i} k_ij (d^_j paired as i, j) for one cell's modes `local`
/// (k: its material's 72 coefficients), and the pairings of `local` for the stress parts.
void stiffness_in_modes(const double* k, const DoubleConstants& constants, const __m512d local[3], __m512d by_xy[3], __m512d by_xz[3],
                        __m512d by_yz[3], __m512d f[3]) {
  const auto coefficient = [&](int block) { return _mm512_loadu_pd(k + 8 * block); };
  for (int j = 0; j < 3; ++j) {
    by_xy[j] = _mm512_permutexvar_pd(constants.swap_xy, local[j]);
    by_xz[j] = _mm512_permutexvar_pd(constants.swap_xz, local[j]);
    by_yz[j] = _mm512_permutexvar_pd(constants.swap_yz, local[j]);
  }
  f[0] = _mm512_fmadd_pd(coefficient(2), by_xz[2], _mm512_fmadd_pd(coefficient(1), by_xy[1], _mm512_mul_pd(coefficient(0), local[0])));
  f[1] = _mm512_fmadd_pd(coefficient(5), by_yz[2], _mm512_fmadd_pd(coefficient(3), by_xy[0], _mm512_mul_pd(coefficient(4), local[1])));
  f[2] = _mm512_fmadd_pd(coefficient(7), by_yz[1], _mm512_fmadd_pd(coefficient(6), by_xz[0], _mm512_mul_pd(coefficient(8), local[2])));
}

/// The corners' x, y, z (world) of the cell whose 8 vertex ids are `corners`, from `x` (3 per vertex).
void gather_corners(const std::int32_t* corners, const double* x, __m512d world[3]) {
  const __m256i offsets = _mm256_mullo_epi32(_mm256_loadu_si256(reinterpret_cast<const __m256i*>(corners)), _mm256_set1_epi32(3));
  for (int j = 0; j < 3; ++j) world[j] = _mm512_i32gather_pd(offsets, x + j, 8);
}

/// Into the cell's frame, d_i = sum_j R_ji w_j (r: R column-major, R(i, j) at 3 j + i).
void to_cell_frame(const double* r, const __m512d world[3], __m512d local[3]) {
  for (int i = 0; i < 3; ++i) {
    local[i] = _mm512_mul_pd(_mm512_set1_pd(r[3 * i + 0]), world[0]);
    local[i] = _mm512_fmadd_pd(_mm512_set1_pd(r[3 * i + 1]), world[1], local[i]);
    local[i] = _mm512_fmadd_pd(_mm512_set1_pd(r[3 * i + 2]), world[2], local[i]);
  }
}

/// Back into the world, out_i = sum_j R_ij f_j, stored as the cell's 8 x, 8 y, 8 z at `to`.
void store_in_world(const double* r, const __m512d f[3], double* to) {
  for (int i = 0; i < 3; ++i) {
    __m512d out = _mm512_mul_pd(_mm512_set1_pd(r[i]), f[0]);
    out = _mm512_fmadd_pd(_mm512_set1_pd(r[3 + i]), f[1], out);
    out = _mm512_fmadd_pd(_mm512_set1_pd(r[6 + i]), f[2], out);
    _mm512_storeu_pd(to + 8 * i, out);
  }
}

/// Cell c in double: lanes are its 8 corners (modes, once transformed).
void cell_double(const CorotatedCellsInputDouble& in, const DoubleConstants& constants, std::size_t c) {
  __m512d world[3];
  gather_corners(in.corners + 8 * c, in.x, world);
  const double* r = in.rotation + 9 * c;
  __m512d local[3];
  to_cell_frame(r, world, local);
  for (int i = 0; i < 3; ++i) local[i] = corner_modes(local[i], constants);
  __m512d by_xy[3], by_xz[3], by_yz[3];
  __m512d f[3];
  stiffness_in_modes(in.stiffness_modes + 72 * static_cast<std::size_t>(in.material[c]), constants, local, by_xy, by_xz, by_yz, f);
  const double* t = in.tension != nullptr ? in.tension + 6 * c : nullptr;
  if (t != nullptr && (t[0] != 0 || t[1] != 0 || t[2] != 0 || t[3] != 0 || t[4] != 0 || t[5] != 0)) {
    __m512d g[6];
    for (std::size_t q = 0; q < 6; ++q) g[q] = _mm512_mul_pd(_mm512_set1_pd(t[q]), _mm512_loadu_pd(in.stress_modes + 8 * q));
    const __m512d normal = _mm512_add_pd(g[0], _mm512_add_pd(g[1], g[2]));
    for (int i = 0; i < 3; ++i) {
      f[i] = _mm512_fmadd_pd(normal, local[i], f[i]);
      f[i] = _mm512_fmadd_pd(g[3], by_xy[i], f[i]);
      f[i] = _mm512_fmadd_pd(g[4], by_xz[i], f[i]);
      f[i] = _mm512_fmadd_pd(g[5], by_yz[i], f[i]);
    }
  }
  for (int i = 0; i < 3; ++i) f[i] = corner_modes(f[i], constants);
  store_in_world(r, f, in.per_cell + 24 * c);
}

/// Cell c's elastic and stress forces in double: R [K^e (R^T (X_e + x_e) - X_e) + T^e s].
/// `rest`: the corners' positions relative to corner 0 at rest, h (a_x, a_y, a_z).
void cell_forces(const CorotatedForcesInput& in, const DoubleConstants& constants, const __m512d rest[3], std::size_t c) {
  // The rest positions plus the displacement.
  __m512d world[3];
  gather_corners(in.corners + 8 * c, in.x, world);
  for (int j = 0; j < 3; ++j) world[j] = _mm512_add_pd(rest[j], world[j]);
  const double* r = in.rotation + 9 * c;
  // d_i = sum_j R_ji (X + x)_j - X_i in the cell's frame, into modes (the rigid translation, mode
  // 0, has no stiffness: no need to take corner 0's displacement off).
  __m512d local[3];
  to_cell_frame(r, world, local);
  for (int i = 0; i < 3; ++i) local[i] = corner_modes(_mm512_sub_pd(local[i], rest[i]), constants);
  __m512d by_xy[3], by_xz[3], by_yz[3];
  __m512d f[3];
  stiffness_in_modes(in.stiffness_modes + 72 * static_cast<std::size_t>(in.material[c]), constants, local, by_xy, by_xz, by_yz, f);
  for (int i = 0; i < 3; ++i) f[i] = corner_modes(f[i], constants);
  // The stress forces T^e s at the corners, component by component.
  if (in.stress != nullptr) {
    const double* s = in.stress + 6 * c;
    for (int i = 0; i < 3; ++i)
      for (int k = 0; k < 6; ++k)
        f[i] = _mm512_fmadd_pd(_mm512_set1_pd(s[k]), _mm512_loadu_pd(in.stress_divergence + 8 * (3 * k + i)), f[i]);
  }
  store_in_world(r, f, in.per_cell + 24 * c);
}

}  // namespace

void corotated_forces_avx512(const CorotatedForcesInput& in, std::size_t begin, std::size_t end) {
  const DoubleConstants constants;
  // h (a_x, a_y, a_z) per corner a: h (1 - sign) / 2 with the butterflies' signs.
  __m512d rest[3];
  for (int j = 0; j < 3; ++j)
    rest[j] = _mm512_mul_pd(_mm512_set1_pd(0.5 * in.cell_size_mm), _mm512_sub_pd(_mm512_set1_pd(1.0), constants.sign[j]));
  for (std::size_t c = begin; c < end; ++c) cell_forces(in, constants, rest, c);
}

void corotated_cells_avx512(const CorotatedCellsInputDouble& in, std::size_t begin, std::size_t end) {
  const DoubleConstants constants;
  for (std::size_t c = begin; c < end; ++c) cell_double(in, constants, c);
}

void corotated_cells_avx512(const CorotatedCellsInput& in, std::size_t begin, std::size_t end) {
  const FloatConstants constants;
  std::size_t c = begin;
  for (; c + 1 < end; c += 2) cell_pair(in, constants, c, false);
  if (c < end) cell_pair(in, constants, c, true);
}

}  // namespace cleave

#else  // built without AVX-512 (another architecture): never called, see kAvx512CellPassCompiled

namespace cleave {

const bool kAvx512CellPassCompiled = false;

void corotated_cells_avx512(const CorotatedCellsInput&, std::size_t, std::size_t) {}
void corotated_cells_avx512(const CorotatedCellsInputDouble&, std::size_t, std::size_t) {}
void corotated_forces_avx512(const CorotatedForcesInput&, std::size_t, std::size_t) {}

}  // namespace cleave

#endif
