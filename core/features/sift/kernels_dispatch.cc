#include "core/features/sift/kernels.h"

namespace reconar {

std::vector<const SiftKernels*> AvailableSiftKernels() {
  std::vector<const SiftKernels*> tables{&ReferenceSiftKernels()};
  if (const SiftKernels* avx2 = sift_internal::Avx2SiftKernels()) tables.push_back(avx2);
  if (const SiftKernels* avx512 = sift_internal::Avx512SiftKernels()) tables.push_back(avx512);
  if (const SiftKernels* neon = sift_internal::NeonSiftKernels()) tables.push_back(neon);
  return tables;
}

const SiftKernels& BestSiftKernels() {
  static const SiftKernels* best = [] {
    if (const SiftKernels* avx512 = sift_internal::Avx512SiftKernels()) return avx512;
    if (const SiftKernels* avx2 = sift_internal::Avx2SiftKernels()) return avx2;
    if (const SiftKernels* neon = sift_internal::NeonSiftKernels()) return neon;
    return &ReferenceSiftKernels();
  }();
  return *best;
}

#if !defined(RECONAR_HAVE_AVX2)
const SiftKernels* sift_internal::Avx2SiftKernels() { return nullptr; }
const SiftKernels* sift_internal::Avx512SiftKernels() { return nullptr; }
#endif
#if !defined(RECONAR_HAVE_NEON)
const SiftKernels* sift_internal::NeonSiftKernels() { return nullptr; }
#endif

}  // namespace reconar
