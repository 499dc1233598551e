#include "core/base/cpu_features.h"

#include <gtest/gtest.h>

namespace reconar {
namespace {

TEST(CpuFeatures, DetectedOnceAndConsistent) {
  const CpuFeatures& features = HostCpuFeatures();
  EXPECT_EQ(&features, &HostCpuFeatures());
#if defined(__x86_64__)
  EXPECT_TRUE(features.sse2);  // part of the x86-64 baseline
  EXPECT_FALSE(features.neon);
#elif defined(__aarch64__)
  EXPECT_TRUE(features.neon);
  EXPECT_FALSE(features.avx2);
#endif
  // Every AVX-512 CPU has AVX2 and FMA.
  if (features.avx512f) {
    EXPECT_TRUE(features.avx2 && features.fma);
  }
}

TEST(CpuFeatures, Names) {
  EXPECT_EQ(CpuFeatureNames(CpuFeatures{}), "none");
  CpuFeatures features;
  features.sse2 = features.avx2 = features.fma = true;
  EXPECT_EQ(CpuFeatureNames(features), "sse2 avx2 fma");
}

}  // namespace
}  // namespace reconar
