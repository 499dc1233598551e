#include "core/features/descriptor_distance.h"

#include <gtest/gtest.h>

#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <random>
#include <string>
#include <vector>

namespace reconar {
namespace {

// Random rows plus the extremes (all 0 against all 255: the largest distance; identical rows).
std::vector<uint8_t> TestRows(int rows, uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_int_distribution<int> byte(0, 255);
  std::vector<uint8_t> data(static_cast<size_t>(rows) * kDescriptorSize + 1);  // +1: unaligned views
  for (auto& v : data) v = static_cast<uint8_t>(byte(rng));
  for (int i = 0; i < kDescriptorSize; ++i) {
    data[i] = 0;
    data[kDescriptorSize + i] = 255;
    data[2 * kDescriptorSize + i] = 255;
  }
  return data;
}

TEST(DescriptorDistanceTest, ScalarReferenceKnownValues) {
  std::vector<uint8_t> a(kDescriptorSize, 0), b(kDescriptorSize, 255);
  const DescriptorDistanceKernel& scalar = ScalarDescriptorDistanceKernel();
  EXPECT_EQ(scalar.distance(a.data(), b.data()), 128 * 255 * 255);
  EXPECT_EQ(scalar.distance(a.data(), a.data()), 0);
  b.assign(kDescriptorSize, 0);
  b[5] = 3;
  b[127] = 4;
  EXPECT_EQ(scalar.distance(a.data(), b.data()), 25);
}

TEST(DescriptorDistanceTest, EveryKernelMatchesScalarReference) {
  const int rows = 301;
  const std::vector<uint8_t> data = TestRows(rows, 7);
  const DescriptorDistanceKernel& scalar = ScalarDescriptorDistanceKernel();
  const std::vector<DescriptorDistanceKernel> kernels = AvailableDescriptorDistanceKernels();
  ASSERT_FALSE(kernels.empty());
  EXPECT_STREQ(kernels.front().name, "scalar");
  for (const DescriptorDistanceKernel& kernel : kernels) {
    SCOPED_TRACE(kernel.name);
    for (int offset = 0; offset <= 1; ++offset) {  // aligned and unaligned rows
      const uint8_t* base = data.data() + offset;
      for (int i = 0; i < rows; ++i) {
        for (int j : {0, 1, 2, i, (i * 7 + 3) % rows}) {
          const uint8_t* a = base + static_cast<size_t>(i) * kDescriptorSize;
          const uint8_t* b = base + static_cast<size_t>(j) * kDescriptorSize;
          ASSERT_EQ(kernel.distance(a, b), scalar.distance(a, b)) << i << " " << j << " offset " << offset;
        }
      }
      // Batches of every length 0..17 (covers the 4-wide AVX2 blocks and their tails).
      std::vector<int32_t> ids(rows);
      for (int i = 0; i < rows; ++i) ids[i] = (i * 37 + 11) % rows;
      for (int count = 0; count <= 17; ++count) {
        for (int q : {0, 1, 2, 50}) {
          const uint8_t* query = base + static_cast<size_t>(q) * kDescriptorSize;
          std::vector<int32_t> got(count + 1, -7), want(count + 1, -7);
          kernel.batch(query, base, ids.data() + q, count, got.data());
          scalar.batch(query, base, ids.data() + q, count, want.data());
          ASSERT_EQ(got, want) << "count " << count << " query " << q;
        }
      }
    }
  }
}

TEST(DescriptorDistanceTest, ActiveKernelIsTheWidestAvailable) {
  const std::vector<DescriptorDistanceKernel> kernels = AvailableDescriptorDistanceKernels();
  const DescriptorDistanceKernel& active = ActiveDescriptorDistanceKernel();
  std::printf("descriptor distance kernels:");
  for (const auto& k : kernels) std::printf(" %s", k.name);
  std::printf("; active: %s\n", active.name);
  if (std::getenv("RECONAR_DESCRIPTOR_KERNEL") == nullptr) {
    EXPECT_STREQ(active.name, kernels.back().name);
  }
#if defined(__x86_64__)
  EXPECT_GE(kernels.size(), 2u);  // scalar + sse2 at least
#elif defined(__aarch64__)
  EXPECT_EQ(std::string(kernels.back().name), "neon");
#endif
}

}  // namespace
}  // namespace reconar
