// AVX2 descriptor distance kernels; this translation unit alone is compiled with
// RECONAR_AVX2_FLAGS and is only called once the CPU reports AVX2 and FMA (descriptor_distance.cc).
// |a-b| per byte via two saturating subtractions, widened to 16 bit by interleaving with zero,
// then squared and pairwise summed into 32 bit with _mm256_madd_epi16.
#include <immintrin.h>

#include "core/features/descriptor_distance_kernels.h"

namespace reconar::internal {
namespace {

inline __m256i SquaredDiffStep(__m256i a, __m256i b, __m256i acc) {
  const __m256i zero = _mm256_setzero_si256();
  const __m256i d = _mm256_or_si256(_mm256_subs_epu8(a, b), _mm256_subs_epu8(b, a));
  const __m256i lo = _mm256_unpacklo_epi8(d, zero);
  const __m256i hi = _mm256_unpackhi_epi8(d, zero);
  acc = _mm256_add_epi32(acc, _mm256_madd_epi16(lo, lo));
  return _mm256_add_epi32(acc, _mm256_madd_epi16(hi, hi));
}

inline __m256i Load(const uint8_t* p) { return _mm256_loadu_si256(reinterpret_cast<const __m256i*>(p)); }

// 8 partial sums of one descriptor pair, query held in registers.
inline __m256i PartialSums(const __m256i q[4], const uint8_t* p) {
  __m256i acc0 = SquaredDiffStep(q[0], Load(p), _mm256_setzero_si256());
  __m256i acc1 = SquaredDiffStep(q[1], Load(p + 32), _mm256_setzero_si256());
  acc0 = SquaredDiffStep(q[2], Load(p + 64), acc0);
  acc1 = SquaredDiffStep(q[3], Load(p + 96), acc1);
  return _mm256_add_epi32(acc0, acc1);
}

inline int32_t HorizontalSum(__m256i v) {
  __m128i s = _mm_add_epi32(_mm256_castsi256_si128(v), _mm256_extracti128_si256(v, 1));
  s = _mm_add_epi32(s, _mm_shuffle_epi32(s, _MM_SHUFFLE(1, 0, 3, 2)));
  s = _mm_add_epi32(s, _mm_shuffle_epi32(s, _MM_SHUFFLE(2, 3, 0, 1)));
  return _mm_cvtsi128_si32(s);
}

}  // namespace

int32_t DescriptorDistanceAvx2(const uint8_t* a, const uint8_t* b) {
  const __m256i q[4] = {Load(a), Load(a + 32), Load(a + 64), Load(a + 96)};
  return HorizontalSum(PartialSums(q, b));
}

void DescriptorDistanceBatchAvx2(const uint8_t* query, const uint8_t* base, const int32_t* ids,
                                 int count, int32_t* out) {
  const __m256i q[4] = {Load(query), Load(query + 32), Load(query + 64), Load(query + 96)};
  int i = 0;
  // Four candidates at a time: their reductions share two rounds of horizontal adds.
  for (; i + 4 <= count; i += 4) {
    const __m256i s0 = PartialSums(q, base + static_cast<int64_t>(ids[i]) * 128);
    const __m256i s1 = PartialSums(q, base + static_cast<int64_t>(ids[i + 1]) * 128);
    const __m256i s2 = PartialSums(q, base + static_cast<int64_t>(ids[i + 2]) * 128);
    const __m256i s3 = PartialSums(q, base + static_cast<int64_t>(ids[i + 3]) * 128);
    // hadd works per 128-bit lane: h = [s0 s1 s2 s3 (lanes 0-3) | s0 s1 s2 s3 (lanes 4-7)].
    const __m256i h = _mm256_hadd_epi32(_mm256_hadd_epi32(s0, s1), _mm256_hadd_epi32(s2, s3));
    const __m128i sums = _mm_add_epi32(_mm256_castsi256_si128(h), _mm256_extracti128_si256(h, 1));
    _mm_storeu_si128(reinterpret_cast<__m128i*>(out + i), sums);
  }
  for (; i < count; ++i) out[i] = HorizontalSum(PartialSums(q, base + static_cast<int64_t>(ids[i]) * 128));
}

}  // namespace reconar::internal
