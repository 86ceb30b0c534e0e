// Compiled with -mavx512f -mavx512dq (src/cleave/CMakeLists.txt); see the header for why this
// file includes nothing but the intrinsics.
#include "cleave/fem/tensile_part_avx512.hpp"

#if defined(__AVX512F__) && defined(__AVX512DQ__)
#include <immintrin.h>

#include <cstdint>

namespace cleave {
namespace {

constexpr int kVoigtRow[6] = {0, 1, 2, 0, 0, 1};
constexpr int kVoigtColumn[6] = {0, 1, 2, 1, 2, 2};

__m512d absolute(__m512d x) { return _mm512_andnot_pd(_mm512_set1_pd(-0.0), x); }

/// One Jacobi rotation in the plane (p, q) of every lane's A, accumulated into V (Numerical
/// Recipes' form: t = sgn(theta) / (|theta| + sqrt(theta^2 + 1)), theta = (a_qq - a_pp) / 2 a_pq).
/// A lane whose a_pq is zero is not rotated; one whose theta^2 overflows gets t = 0 (its a_pq is
/// negligible against a_qq - a_pp).
void rotate(__m512d (&a)[3][3], __m512d (&v)[3][3], int p, int q) {
  const int r = 3 - p - q;
  const __m512d zero = _mm512_setzero_pd();
  const __m512d one = _mm512_set1_pd(1.0);
  const __m512d apq = a[p][q];
  const __mmask8 active = _mm512_cmp_pd_mask(apq, zero, _CMP_NEQ_OQ);
  const __m512d theta = _mm512_div_pd(_mm512_sub_pd(a[q][q], a[p][p]), _mm512_add_pd(apq, apq));
  const __m512d root = _mm512_sqrt_pd(_mm512_fmadd_pd(theta, theta, one));
  const __m512d sign = _mm512_or_pd(one, _mm512_and_pd(theta, _mm512_set1_pd(-0.0)));
  __m512d t = _mm512_div_pd(sign, _mm512_add_pd(absolute(theta), root));
  t = _mm512_maskz_mov_pd(static_cast<__mmask8>(active & _mm512_cmp_pd_mask(t, t, _CMP_ORD_Q)), t);
  const __m512d c = _mm512_div_pd(one, _mm512_sqrt_pd(_mm512_fmadd_pd(t, t, one)));
  const __m512d s = _mm512_mul_pd(t, c);
  const __m512d shift = _mm512_mul_pd(t, apq);
  a[p][p] = _mm512_sub_pd(a[p][p], shift);
  a[q][q] = _mm512_add_pd(a[q][q], shift);
  a[p][q] = a[q][p] = _mm512_maskz_mov_pd(static_cast<__mmask8>(~active), apq);
  const __m512d arp = a[r][p];
  const __m512d arq = a[r][q];
  a[r][p] = a[p][r] = _mm512_fnmadd_pd(s, arq, _mm512_mul_pd(c, arp));
  a[r][q] = a[q][r] = _mm512_fmadd_pd(s, arp, _mm512_mul_pd(c, arq));
  for (int k = 0; k < 3; ++k) {
    const __m512d vkp = v[k][p];
    const __m512d vkq = v[k][q];
    v[k][p] = _mm512_fnmadd_pd(s, vkq, _mm512_mul_pd(c, vkp));
    v[k][q] = _mm512_fmadd_pd(s, vkp, _mm512_mul_pd(c, vkq));
  }
}

}  // namespace

void tensile_parts_avx512(const double* stress, double* tension, int count, const JacobiSweeps& sweeps) {
  // Spare lanes repeat the first tensor.
  alignas(64) std::int64_t base[8];
  for (int lane = 0; lane < 8; ++lane) base[lane] = 6 * (lane < count ? lane : 0);
  const __m512i offsets = _mm512_load_si512(base);
  __m512d a[3][3];
  for (int k = 0; k < 6; ++k) {
    const __m512d component = _mm512_i64gather_pd(_mm512_add_epi64(offsets, _mm512_set1_epi64(k)), stress, 8);
    a[kVoigtRow[k]][kVoigtColumn[k]] = a[kVoigtColumn[k]][kVoigtRow[k]] = component;
  }
  const __m512d zero = _mm512_setzero_pd();
  // A tensor with an entry that is not a finite number gives no number (as Eigen's decomposition
  // does), so that the caller's finiteness checks see it: max() and the settling test would not.
  __m512d magnitude = zero;
  for (int i = 0; i < 3; ++i)
    for (int j = i; j < 3; ++j) magnitude = _mm512_add_pd(magnitude, absolute(a[i][j]));
  const __mmask8 finite = _mm512_cmp_pd_mask(magnitude, _mm512_set1_pd(__builtin_inf()), _CMP_LT_OQ);
  __m512d v[3][3];
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) v[i][j] = i == j ? _mm512_set1_pd(1.0) : zero;
  const __m512d ratio = _mm512_set1_pd(sweeps.settled_ratio);
  for (int sweep = 0; sweep < sweeps.max_sweeps; ++sweep) {
    const __m512d off = _mm512_add_pd(_mm512_add_pd(absolute(a[0][1]), absolute(a[0][2])), absolute(a[1][2]));
    const __m512d diagonal = _mm512_add_pd(_mm512_add_pd(absolute(a[0][0]), absolute(a[1][1])), absolute(a[2][2]));
    // Settled, or not a number (left to the caller's check of the result): no more sweeps.
    const __mmask8 open = _mm512_cmp_pd_mask(off, _mm512_mul_pd(ratio, diagonal), _CMP_GT_OQ);
    if (open == 0) break;
    rotate(a, v, 0, 1);
    rotate(a, v, 0, 2);
    rotate(a, v, 1, 2);
  }
  __m512d kept[3];
  for (int k = 0; k < 3; ++k) kept[k] = _mm512_max_pd(a[k][k], zero);
  alignas(64) double out[6][8];
  for (int k = 0; k < 6; ++k) {
    const int i = kVoigtRow[k];
    const int j = kVoigtColumn[k];
    __m512d sum = _mm512_mul_pd(_mm512_mul_pd(v[i][0], v[j][0]), kept[0]);
    sum = _mm512_fmadd_pd(_mm512_mul_pd(v[i][1], v[j][1]), kept[1], sum);
    sum = _mm512_fmadd_pd(_mm512_mul_pd(v[i][2], v[j][2]), kept[2], sum);
    _mm512_store_pd(out[k], _mm512_mask_mov_pd(_mm512_set1_pd(__builtin_nan("")), finite, sum));
  }
  for (int lane = 0; lane < count; ++lane)
    for (int k = 0; k < 6; ++k) tension[6 * lane + k] = out[k][lane];
}

}  // namespace cleave

#else

namespace cleave {

// Not compiled for AVX-512: never called (avx512_cell_pass_supported() is false).
void tensile_parts_avx512(const double*, double*, int, const JacobiSweeps&) {}

}  // namespace cleave

#endif
