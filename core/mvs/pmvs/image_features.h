#pragma once
// Seed features of PMVS (Furukawa & Ponce 2010, sec. 3.1): Harris corners and difference-of-
// Gaussian blobs, at most `per_block` of each (the strongest local maxima of the response) in every
// block x block pixel block, so features cover the image evenly (PMVS: 32 x 32 blocks, 4 each).
#include <cstdint>
#include <vector>

#include "core/base/image.h"

namespace reconar {

struct SeedFeature {
  enum Type : uint8_t { kHarris = 0, kDog = 1 };
  float x = 0.0f, y = 0.0f;  // pixels, integer centres
  float response = 0.0f;
  Type type = kHarris;
};

struct SeedFeatureOptions {
  int block_size = 32;
  int per_block = 4;
  double harris_sigma = 1.0;  // Gaussian of the derivatives and the structure tensor
  double harris_k = 0.06;
  double dog_sigma = 1.0;     // DoG = G(dog_sigma) - G(dog_sigma * sqrt(2))
};

// Features of a grey image, Harris ones first; positive responses only.
std::vector<SeedFeature> DetectSeedFeatures(ImageView<const uint8_t> gray, const SeedFeatureOptions& options);

}  // namespace reconar
