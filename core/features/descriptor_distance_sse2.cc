// SSE2 descriptor distance kernels (baseline on x86-64). |a-b| per byte via two saturating
// subtractions, widened to 16 bit and squared-and-summed with _mm_madd_epi16.
#include <emmintrin.h>

#include "core/features/descriptor_distance_kernels.h"

namespace reconar::internal {
namespace {

inline __m128i SquaredDiffStep(__m128i a, __m128i b, __m128i acc) {
  const __m128i zero = _mm_setzero_si128();
  const __m128i d = _mm_or_si128(_mm_subs_epu8(a, b), _mm_subs_epu8(b, a));
  const __m128i lo = _mm_unpacklo_epi8(d, zero);
  const __m128i hi = _mm_unpackhi_epi8(d, zero);
  acc = _mm_add_epi32(acc, _mm_madd_epi16(lo, lo));
  return _mm_add_epi32(acc, _mm_madd_epi16(hi, hi));
}

inline int32_t HorizontalSum(__m128i v) {
  v = _mm_add_epi32(v, _mm_shuffle_epi32(v, _MM_SHUFFLE(1, 0, 3, 2)));
  v = _mm_add_epi32(v, _mm_shuffle_epi32(v, _MM_SHUFFLE(2, 3, 0, 1)));
  return _mm_cvtsi128_si32(v);
}

}  // namespace

int32_t DescriptorDistanceSse2(const uint8_t* a, const uint8_t* b) {
  __m128i acc0 = _mm_setzero_si128();
  __m128i acc1 = _mm_setzero_si128();
  for (int i = 0; i < 128; i += 32) {
    acc0 = SquaredDiffStep(_mm_loadu_si128(reinterpret_cast<const __m128i*>(a + i)),
                           _mm_loadu_si128(reinterpret_cast<const __m128i*>(b + i)), acc0);
    acc1 = SquaredDiffStep(_mm_loadu_si128(reinterpret_cast<const __m128i*>(a + i + 16)),
                           _mm_loadu_si128(reinterpret_cast<const __m128i*>(b + i + 16)), acc1);
  }
  return HorizontalSum(_mm_add_epi32(acc0, acc1));
}

void DescriptorDistanceBatchSse2(const uint8_t* query, const uint8_t* base, const int32_t* ids,
                                 int count, int32_t* out) {
  __m128i q[8];
  for (int j = 0; j < 8; ++j) q[j] = _mm_loadu_si128(reinterpret_cast<const __m128i*>(query + 16 * j));
  for (int i = 0; i < count; ++i) {
    const uint8_t* p = base + static_cast<int64_t>(ids[i]) * 128;
    __m128i acc0 = _mm_setzero_si128();
    __m128i acc1 = _mm_setzero_si128();
    for (int j = 0; j < 8; j += 2) {
      acc0 = SquaredDiffStep(q[j], _mm_loadu_si128(reinterpret_cast<const __m128i*>(p + 16 * j)), acc0);
      acc1 = SquaredDiffStep(q[j + 1], _mm_loadu_si128(reinterpret_cast<const __m128i*>(p + 16 * j + 16)),
                             acc1);
    }
    out[i] = HorizontalSum(_mm_add_epi32(acc0, acc1));
  }
}

}  // namespace reconar::internal
