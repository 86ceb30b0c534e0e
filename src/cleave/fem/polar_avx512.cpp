// Compiled with -mavx512f -mavx512dq (src/cleave/CMakeLists.txt); see the header for why this
// file includes nothing but the intrinsics.
#include "cleave/fem/polar_avx512.hpp"

#if defined(__AVX512F__) && defined(__AVX512DQ__)
#include <immintrin.h>

namespace cleave {

unsigned polar_rotations_avx512(const double* f, double* rotations, int count, const PolarIteration& iteration) {
  // x[3 i + j]: entry (i, j) of every lane's X (column-major source: (i, j) at 9 lane + 3 j + i);
  // spare lanes repeat the first gradient.
  alignas(64) std::int64_t base[8];
  for (int lane = 0; lane < 8; ++lane) base[lane] = 9 * (lane < count ? lane : 0);
  const __m512i offsets = _mm512_load_si512(base);
  __m512d x[9];
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) x[3 * i + j] = _mm512_i64gather_pd(_mm512_add_epi64(offsets, _mm512_set1_epi64(3 * j + i)), f, 8);
  const __mmask8 lanes = static_cast<__mmask8>((1u << count) - 1u);
  __mmask8 settled = static_cast<__mmask8>(~lanes);
  __mmask8 to_svd = 0;
  const __m512d zero = _mm512_setzero_pd();
  const __m512d one = _mm512_set1_pd(1.0);
  const __m512d half = _mm512_set1_pd(0.5);
  const __m512d infinity = _mm512_set1_pd(__builtin_inf());
  const __m512d settled_change = _mm512_set1_pd(iteration.settled_change);
  const __m512d sign_bits = _mm512_set1_pd(-0.0);
  for (int k = 0; k < iteration.max_iterations && static_cast<__mmask8>(settled | to_svd) != 0xFF; ++k) {
    // X^-T = cofactor / det, the cofactor's columns the cross products of X's columns.
    __m512d cofactor[9];
    const auto cross_into = [&](int column, int p, int q) {
      cofactor[0 + column] = _mm512_sub_pd(_mm512_mul_pd(x[3 + p], x[6 + q]), _mm512_mul_pd(x[6 + p], x[3 + q]));
      cofactor[3 + column] = _mm512_sub_pd(_mm512_mul_pd(x[6 + p], x[0 + q]), _mm512_mul_pd(x[0 + p], x[6 + q]));
      cofactor[6 + column] = _mm512_sub_pd(_mm512_mul_pd(x[0 + p], x[3 + q]), _mm512_mul_pd(x[3 + p], x[0 + q]));
    };
    cross_into(0, 1, 2);
    cross_into(1, 2, 0);
    cross_into(2, 0, 1);
    const __m512d det = _mm512_add_pd(_mm512_add_pd(_mm512_mul_pd(x[0], cofactor[0]), _mm512_mul_pd(x[3], cofactor[3])),
                                      _mm512_mul_pd(x[6], cofactor[6]));
    __m512d cofactor_norm = zero;
    __m512d x_norm = zero;
    for (int e = 0; e < 9; ++e) {
      cofactor_norm = _mm512_add_pd(cofactor_norm, _mm512_mul_pd(cofactor[e], cofactor[e]));
      x_norm = _mm512_add_pd(x_norm, _mm512_mul_pd(x[e], x[e]));
    }
    // Inverted, flat or not finite: the SVD decides.
    const __mmask8 usable = static_cast<__mmask8>(_mm512_cmp_pd_mask(det, zero, _CMP_GT_OQ) &
                                                  _mm512_cmp_pd_mask(det, infinity, _CMP_LT_OQ));
    to_svd = static_cast<__mmask8>(to_svd | (~settled & ~usable));
    const __mmask8 moving = static_cast<__mmask8>(~(settled | to_svd));
    const __m512d safe_det = _mm512_mask_blend_pd(moving, one, det);
    const __m512d safe_x_norm = _mm512_mask_blend_pd(moving, one, x_norm);
    const __m512d g = _mm512_sqrt_pd(_mm512_div_pd(_mm512_sqrt_pd(_mm512_div_pd(cofactor_norm, safe_x_norm)), safe_det));
    const __m512d cofactor_scale = _mm512_div_pd(half, _mm512_mul_pd(g, safe_det));
    const __m512d x_scale = _mm512_mul_pd(half, g);
    __m512d change = zero;
    for (int e = 0; e < 9; ++e) {
      const __m512d next = _mm512_add_pd(_mm512_mul_pd(x_scale, x[e]), _mm512_mul_pd(cofactor_scale, cofactor[e]));
      change = _mm512_max_pd(change, _mm512_andnot_pd(sign_bits, _mm512_sub_pd(next, x[e])));
      x[e] = _mm512_mask_blend_pd(moving, x[e], next);
    }
    settled = static_cast<__mmask8>(settled | (moving & _mm512_cmp_pd_mask(change, settled_change, _CMP_LT_OQ)));
  }
  const __mmask8 done = static_cast<__mmask8>(settled & lanes);
  alignas(64) double entries[9][8];
  for (int e = 0; e < 9; ++e) _mm512_store_pd(entries[e], x[e]);
  for (int lane = 0; lane < count; ++lane) {
    if (((done >> lane) & 1u) == 0) continue;
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) rotations[9 * lane + 3 * j + i] = entries[3 * i + j][lane];
  }
  return done;
}

}  // namespace cleave

#else  // built without AVX-512: never called

namespace cleave {

unsigned polar_rotations_avx512(const double*, double*, int, const PolarIteration&) { return 0; }

}  // namespace cleave

#endif
