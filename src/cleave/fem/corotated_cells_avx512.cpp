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

/// Two 8-float columns side by side: [first, second].
__m512 pair(const float* first, const float* second) {
  return _mm512_insertf32x8(_mm512_castps256_ps512(_mm256_loadu_ps(first)), _mm256_loadu_ps(second), 1);
}

/// Two 8-id rows side by side: [first, second].
__m512i pair_ids(const std::int32_t* first, const std::int32_t* second) {
  return _mm512_inserti64x4(_mm512_castsi256_si512(_mm256_loadu_si256(reinterpret_cast<const __m256i*>(first))),
                            _mm256_loadu_si256(reinterpret_cast<const __m256i*>(second)), 1);
}

/// Cells c and c + 1 (or c twice, `single`: only c is written).
void cell_pair(const CorotatedCellsInput& in, std::size_t c, bool single) {
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
    for (int k = 0; k < 9; ++k) {
      const int second = single ? k : 9 + k;  // lane of R_d(k) in [lower, upper]
      rotation[k] = _mm512_permutex2var_ps(lower, halves(k, second), upper);
    }
  }
  // Into the cells' frames: d_i = sum_j R_ji x_j.
  __m512 local[3];
  for (int i = 0; i < 3; ++i) {
    local[i] = _mm512_mul_ps(rotation[3 * i + 0], world[0]);
    local[i] = _mm512_fmadd_ps(rotation[3 * i + 1], world[1], local[i]);
    local[i] = _mm512_fmadd_ps(rotation[3 * i + 2], world[2], local[i]);
  }
  // f_i = sum_j K_ij d_j + s d_i, column b of each block times corner b's value.
  const float* k_c = in.stiffness + 9 * 64 * static_cast<std::size_t>(in.material[c]);
  const float* k_d = in.stiffness + 9 * 64 * static_cast<std::size_t>(in.material[d]);
  const bool same_material = k_c == k_d;
  const float* s_c = in.stress_stiffness != nullptr ? in.stress_stiffness + 64 * c : nullptr;
  const float* s_d = in.stress_stiffness != nullptr ? in.stress_stiffness + 64 * d : nullptr;
  __m512 f[3] = {_mm512_setzero_ps(), _mm512_setzero_ps(), _mm512_setzero_ps()};
  for (int b = 0; b < 8; ++b) {
    const __m512i spread = halves(b, 8 + b);  // corner b of each cell over its half
    __m512 value[3];
    for (int j = 0; j < 3; ++j) value[j] = _mm512_permutexvar_ps(spread, local[j]);
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) {
        const std::size_t column = 64 * static_cast<std::size_t>(3 * i + j) + 8 * static_cast<std::size_t>(b);
        const __m512 k = same_material ? _mm512_broadcast_f32x8(_mm256_loadu_ps(k_c + column)) : pair(k_c + column, k_d + column);
        f[i] = _mm512_fmadd_ps(k, value[j], f[i]);
      }
    if (s_c != nullptr) {
      const __m512 s = pair(s_c + 8 * b, s_d + 8 * b);
      for (int i = 0; i < 3; ++i) f[i] = _mm512_fmadd_ps(s, value[i], f[i]);
    }
  }
  // Back into the world: out_i = sum_j R_ij f_j.
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

/// Cell c in double: lanes are its 8 corners.
void cell_double(const CorotatedCellsInputDouble& in, std::size_t c) {
  const __m256i offsets =
      _mm256_mullo_epi32(_mm256_loadu_si256(reinterpret_cast<const __m256i*>(in.corners + 8 * c)), _mm256_set1_epi32(3));
  __m512d world[3];
  for (int j = 0; j < 3; ++j) world[j] = _mm512_i32gather_pd(offsets, in.x + j, 8);
  const double* r = in.rotation + 9 * c;  // R(i, j) at 3 j + i
  // Into the cell's frame: d_i = sum_j R_ji x_j.
  __m512d local[3];
  for (int i = 0; i < 3; ++i) {
    local[i] = _mm512_mul_pd(_mm512_set1_pd(r[3 * i + 0]), world[0]);
    local[i] = _mm512_fmadd_pd(_mm512_set1_pd(r[3 * i + 1]), world[1], local[i]);
    local[i] = _mm512_fmadd_pd(_mm512_set1_pd(r[3 * i + 2]), world[2], local[i]);
  }
  // f_i = sum_j K_ij d_j + s d_i, column b of each block (and of s) times corner b's value.
  const double* k = in.stiffness + 9 * 64 * static_cast<std::size_t>(in.material[c]);
  const double* t = in.tension != nullptr ? in.tension + 6 * c : nullptr;
  const bool with_tension = t != nullptr && (t[0] != 0 || t[1] != 0 || t[2] != 0 || t[3] != 0 || t[4] != 0 || t[5] != 0);
  __m512d f[3] = {_mm512_setzero_pd(), _mm512_setzero_pd(), _mm512_setzero_pd()};
  for (int b = 0; b < 8; ++b) {
    const __m512i spread = _mm512_set1_epi64(b);
    __m512d value[3];
    for (int j = 0; j < 3; ++j) value[j] = _mm512_permutexvar_pd(spread, local[j]);
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) {
        const __m512d column = _mm512_loadu_pd(k + 64 * static_cast<std::size_t>(3 * i + j) + 8 * static_cast<std::size_t>(b));
        f[i] = _mm512_fmadd_pd(column, value[j], f[i]);
      }
    if (with_tension) {
      // Column b of s = sum_q t_q G_q.
      __m512d s = _mm512_mul_pd(_mm512_set1_pd(t[0]), _mm512_loadu_pd(in.stress_basis + 8 * static_cast<std::size_t>(b)));
      for (int q = 1; q < 6; ++q)
        s = _mm512_fmadd_pd(_mm512_set1_pd(t[q]), _mm512_loadu_pd(in.stress_basis + 64 * static_cast<std::size_t>(q) + 8 * static_cast<std::size_t>(b)), s);
      for (int i = 0; i < 3; ++i) f[i] = _mm512_fmadd_pd(s, value[i], f[i]);
    }
  }
  // Back into the world: out_i = sum_j R_ij f_j.
  double* to = in.per_cell + 24 * c;
  for (int i = 0; i < 3; ++i) {
    __m512d out = _mm512_mul_pd(_mm512_set1_pd(r[i]), f[0]);
    out = _mm512_fmadd_pd(_mm512_set1_pd(r[3 + i]), f[1], out);
    out = _mm512_fmadd_pd(_mm512_set1_pd(r[6 + i]), f[2], out);
    _mm512_storeu_pd(to + 8 * i, out);
  }
}

}  // namespace

void corotated_cells_avx512(const CorotatedCellsInputDouble& in, std::size_t begin, std::size_t end) {
  for (std::size_t c = begin; c < end; ++c) cell_double(in, c);
}

void corotated_cells_avx512(const CorotatedCellsInput& in, std::size_t begin, std::size_t end) {
  std::size_t c = begin;
  for (; c + 1 < end; c += 2) cell_pair(in, c, false);
  if (c < end) cell_pair(in, c, true);
}

}  // namespace cleave

#else  // built without AVX-512 (another architecture): never called, see kAvx512CellPassCompiled

namespace cleave {

const bool kAvx512CellPassCompiled = false;

void corotated_cells_avx512(const CorotatedCellsInput&, std::size_t, std::size_t) {}
void corotated_cells_avx512(const CorotatedCellsInputDouble&, std::size_t, std::size_t) {}

}  // namespace cleave

#endif
