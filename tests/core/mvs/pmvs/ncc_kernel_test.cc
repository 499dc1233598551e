#include "core/mvs/pmvs/ncc.h"

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <vector>

#include "core/base/prng.h"

namespace reconar {
namespace {

// A padded pair: a normalised reference and raw samples, count values each, zero padding.
struct NccPair {
  std::vector<float> reference, samples;
};

NccPair RandomPair(int count, SplitMix64* rng, double correlation, double offset) {
  const int padded = PaddedNccCount(count);
  NccPair pair{std::vector<float>(padded + 1, 0.0f), std::vector<float>(padded + 1, 0.0f)};
  for (int i = 0; i < count; ++i) {
    const double base = 255.0 * rng->Uniform01();
    pair.reference[i] = static_cast<float>(base);
    pair.samples[i] = static_cast<float>(offset + correlation * base + (1.0 - std::abs(correlation)) * 100.0 * rng->Uniform01());
  }
  EXPECT_TRUE(NormalizeNccReference(pair.reference.data(), count, padded, 0.0f));
  return pair;
}

TEST(NccKernelTest, ScalarReferenceKnownValues) {
  const int count = 25;
  std::vector<float> reference(PaddedNccCount(count), 0.0f), same(PaddedNccCount(count), 0.0f),
      negated(PaddedNccCount(count), 0.0f), flat(PaddedNccCount(count), 0.0f);
  for (int i = 0; i < count; ++i) {
    reference[i] = static_cast<float>((i * 37) % 11);
    same[i] = 2.0f * reference[i] + 30.0f;  // NCC is invariant to gain and offset
    negated[i] = 200.0f - reference[i];
    flat[i] = 80.0f;
  }
  ASSERT_TRUE(NormalizeNccReference(reference.data(), count, PaddedNccCount(count), 0.0f));
  const NccKernel& scalar = ScalarNccKernel();
  EXPECT_NEAR(Ncc(scalar, reference.data(), same.data(), count), 1.0f, 1e-5f);
  EXPECT_NEAR(Ncc(scalar, reference.data(), negated.data(), count), -1.0f, 1e-5f);
  EXPECT_EQ(Ncc(scalar, reference.data(), flat.data(), count), -1.0f);  // nothing to correlate
  EXPECT_FALSE(NormalizeNccReference(flat.data(), count, PaddedNccCount(count), 0.0f));
}

TEST(NccKernelTest, TextureFloorRefusesWeakReferences) {
  // Alternating 100 / 102 over 24 samples: mean 101, standard deviation exactly 1 grey level.
  constexpr int count = 24;
  std::vector<float> values(PaddedNccCount(count));
  auto fill = [&] {
    for (int i = 0; i < count; ++i) values[i] = (i % 2) ? 102.0f : 100.0f;
  };
  fill();
  EXPECT_FALSE(NormalizeNccReference(values.data(), count, PaddedNccCount(count), 1.01f));
  EXPECT_EQ(values[1], 102.0f);  // untouched when refused
  fill();
  EXPECT_TRUE(NormalizeNccReference(values.data(), count, PaddedNccCount(count), 0.99f));
  EXPECT_NEAR(values[1], 1.0f / std::sqrt(static_cast<float>(count)), 1e-6f);
}

TEST(NccKernelTest, EveryKernelMatchesScalarReference) {
  const std::vector<NccKernel> kernels = AvailableNccKernels();
  ASSERT_FALSE(kernels.empty());
  EXPECT_STREQ(kernels.front().name, "scalar");
  const NccKernel& scalar = ScalarNccKernel();
  SplitMix64 rng(11);
  for (const NccKernel& kernel : kernels) {
    SCOPED_TRACE(kernel.name);
    for (int size : {3, 5, 7, 9, 15}) {
      const int count = size * size;
      for (int trial = 0; trial < 50; ++trial) {
        const double correlation = -1.0 + 2.0 * (trial % 11) / 10.0;
        NccPair pair = RandomPair(count, &rng, correlation, 50.0 * (trial % 3));
        for (int offset = 0; offset <= 1; ++offset) {  // aligned and unaligned sample arrays
          std::vector<float> shifted(pair.samples.size() + 1, 0.0f);
          std::copy(pair.samples.begin(), pair.samples.end(), shifted.begin() + offset);
          const NccSums a = scalar.sums(pair.reference.data(), pair.samples.data(), PaddedNccCount(count));
          const NccSums b = kernel.sums(pair.reference.data(), shifted.data() + offset, PaddedNccCount(count));
          // Float sums of up to 232 terms of up to 255^2 in another order: relative 1e-5.
          EXPECT_NEAR(b.sum, a.sum, 1e-5f * std::abs(a.sum) + 1e-3f);
          EXPECT_NEAR(b.sum_squares, a.sum_squares, 1e-5f * a.sum_squares + 1e-3f);
          EXPECT_NEAR(b.sum_products, a.sum_products, 1e-4f + 1e-5f * std::abs(a.sum_products));
          EXPECT_NEAR(NccFromSums(b, count), NccFromSums(a, count), 2e-4f);
        }
      }
    }
  }
}

TEST(NccKernelTest, ActiveKernelIsAvailable) {
  const NccKernel& active = ActiveNccKernel();
  bool found = false;
  for (const NccKernel& k : AvailableNccKernels()) found = found || k.sums == active.sums;
  EXPECT_TRUE(found) << active.name;
}

}  // namespace
}  // namespace reconar
