#include "core/features/sift/sift.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <random>

namespace reconar {
namespace {

// Sum of isotropic Gaussian blobs on a flat background: their centres and sigmas are ground truth.
struct Blob {
  double x, y, sigma, amplitude;
};

Image<float> RenderBlobs(int width, int height, const std::vector<Blob>& blobs) {
  Image<float> image(width, height);
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      double v = 0.2;
      for (const Blob& b : blobs) {
        const double d2 = (x - b.x) * (x - b.x) + (y - b.y) * (y - b.y);
        v += b.amplitude * std::exp(-0.5 * d2 / (b.sigma * b.sigma));
      }
      image.row(y)[x] = static_cast<float>(v);
    }
  }
  return image;
}

// Random smooth texture: sum of blobs with random position, size and sign.
Image<float> RandomTexture(int width, int height, uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> ux(0, width), uy(0, height), us(1.5, 6.0), ua(-0.3, 0.3);
  std::vector<Blob> blobs;
  for (int i = 0; i < width * height / 300; ++i) blobs.push_back({ux(rng), uy(rng), us(rng), ua(rng)});
  return RenderBlobs(width, height, blobs);
}

ImageView<const float> View(const Image<float>& image) { return image.view(); }

TEST(Sift, FindsBlobCentreAndScale) {
  // For a Gaussian blob of sigma b, the scale-normalised Laplacian peaks at sigma = b
  // (Lindeberg 1998); DoG approximates it.
  for (int first_octave : {-1, 0}) {
    const Blob blob{101.3, 77.6, 5.0, 0.6};
    const Image<float> image = RenderBlobs(220, 180, {blob});
    SiftOptions options;
    options.first_octave = first_octave;
    SiftExtractor sift(options);
    auto result = sift.Extract(View(image));
    ASSERT_TRUE(result.ok()) << result.status().ToString();
    ASSERT_FALSE(result->keypoints.empty());
    const SiftKeypoint* best = &result->keypoints[0];
    for (const auto& kp : result->keypoints) {
      if (kp.response > best->response) best = &kp;
    }
    EXPECT_NEAR(best->x, blob.x, 0.3) << "first octave " << first_octave;
    EXPECT_NEAR(best->y, blob.y, 0.3);
    EXPECT_NEAR(best->scale / blob.sigma, 1.0, 0.15);
  }
}

TEST(Sift, BlobPositionsTrackSubpixelShifts) {
  SiftExtractor sift(SiftOptions{});
  for (double shift : {0.0, 0.25, 0.5, 0.75}) {
    const Image<float> image = RenderBlobs(128, 128, {{60.0 + shift, 64.0 - shift, 3.0, 0.5}});
    auto result = sift.Extract(View(image));
    ASSERT_TRUE(result.ok());
    ASSERT_FALSE(result->keypoints.empty());
    const SiftKeypoint* best = &result->keypoints[0];
    for (const auto& kp : result->keypoints) {
      if (kp.response > best->response) best = &kp;
    }
    EXPECT_NEAR(best->x, 60.0 + shift, 0.15);
    EXPECT_NEAR(best->y, 64.0 - shift, 0.15);
  }
}

// Rotating the image by 90 degrees (an exact resampling) must rotate keypoints and leave descriptors
// nearly unchanged: this checks orientation assignment and descriptor rotation together.
TEST(Sift, RotationBy90DegreesPreservesKeypointsAndDescriptors) {
  const Image<float> image = RandomTexture(240, 200, 3);
  Image<float> rotated(200, 240);
  // rotated(x', y') = image(x = y', y = W-1-x'): a 90 degree counter-clockwise turn on screen.
  for (int yr = 0; yr < 240; ++yr) {
    for (int xr = 0; xr < 200; ++xr) rotated.row(yr)[xr] = image.row(xr)[239 - yr];
  }
  SiftExtractor sift(SiftOptions{});
  auto a = sift.Extract(View(image));
  auto b = sift.Extract(View(rotated));
  ASSERT_TRUE(a.ok() && b.ok());
  ASSERT_GT(a->keypoints.size(), 50u);
  int matched = 0, consistent = 0;
  for (size_t i = 0; i < a->keypoints.size(); ++i) {
    const SiftKeypoint& ka = a->keypoints[i];
    // Expected position in the rotated image.
    const double xr = ka.y, yr = 239 - ka.x;
    for (size_t j = 0; j < b->keypoints.size(); ++j) {
      const SiftKeypoint& kb = b->keypoints[j];
      if (std::hypot(kb.x - xr, kb.y - yr) > 0.5 || std::fabs(kb.scale / ka.scale - 1) > 0.1) continue;
      double dtheta = std::fabs(std::remainder(kb.orientation - (ka.orientation - M_PI / 2), 2 * M_PI));
      if (dtheta > 0.1) continue;
      ++matched;
      double dist2 = 0, norm2 = 0;
      for (int k = 0; k < 128; ++k) {
        const double d = double(a->descriptor(i)[k]) - b->descriptor(j)[k];
        dist2 += d * d;
        norm2 += double(a->descriptor(i)[k]) * a->descriptor(i)[k];
      }
      if (std::sqrt(dist2) < 0.1 * std::sqrt(norm2)) ++consistent;
      break;
    }
  }
  EXPECT_GT(matched, static_cast<int>(0.8 * a->keypoints.size()));
  EXPECT_GT(consistent, static_cast<int>(0.95 * matched));
}

TEST(Sift, DescriptorsAreNormalisedAndQuantised) {
  const Image<float> image = RandomTexture(160, 160, 9);
  SiftExtractor sift(SiftOptions{});
  auto result = sift.Extract(View(image));
  ASSERT_TRUE(result.ok());
  ASSERT_FALSE(result->keypoints.empty());
  for (size_t i = 0; i < result->keypoints.size(); ++i) {
    double norm2 = 0;
    int max_value = 0;
    for (int k = 0; k < 128; ++k) {
      norm2 += double(result->descriptor(i)[k]) * result->descriptor(i)[k];
      max_value = std::max<int>(max_value, result->descriptor(i)[k]);
    }
    // Unit vector scaled by 512 (Lowe's quantisation), so no entry saturates at 255.
    EXPECT_NEAR(std::sqrt(norm2), 512.0, 12.0);
    EXPECT_LT(max_value, 255);
    const auto& kp = result->keypoints[i];
    EXPECT_GE(kp.orientation, 0.0f);
    EXPECT_LT(kp.orientation, 2 * M_PI);
  }
}

TEST(Sift, MaxFeaturesKeepsTheStrongest) {
  const Image<float> image = RandomTexture(200, 200, 4);
  SiftOptions options;
  options.max_features = 0;
  SiftExtractor all(options);
  auto full = all.Extract(View(image));
  ASSERT_TRUE(full.ok());
  ASSERT_GT(full->keypoints.size(), 40u);
  options.max_features = 20;
  SiftExtractor capped(options);
  SiftReport report;
  auto few = capped.Extract(View(image), &report);
  ASSERT_TRUE(few.ok());
  EXPECT_EQ(few->keypoints.size(), 20u);
  EXPECT_TRUE(report.truncated);
  std::vector<float> responses;
  for (const auto& kp : full->keypoints) responses.push_back(kp.response);
  std::sort(responses.rbegin(), responses.rend());
  for (const auto& kp : few->keypoints) EXPECT_GE(kp.response, responses[19]);
}

TEST(Sift, IsDeterministic) {
  const Image<float> image = RandomTexture(150, 130, 8);
  SiftExtractor sift(SiftOptions{});
  auto a = sift.Extract(View(image));
  auto b = sift.Extract(View(image));
  ASSERT_TRUE(a.ok() && b.ok());
  EXPECT_EQ(a->descriptors, b->descriptors);
  ASSERT_EQ(a->keypoints.size(), b->keypoints.size());
}

TEST(Sift, WorkingMemoryStaysInsideTheArena) {
  const Image<float> image = RandomTexture(300, 200, 2);
  SiftOptions options;
  options.arena_bytes = SiftExtractor::RequiredArenaBytes(300, 200, options);
  SiftExtractor sift(options);
  SiftReport report;
  auto result = sift.Extract(View(image), &report);
  ASSERT_TRUE(result.ok()) << result.status().ToString();
  EXPECT_LE(report.arena_peak_bytes, options.arena_bytes);
  EXPECT_GT(report.arena_peak_bytes, 4u * 600 * 400 * sizeof(float));  // four doubled planes

  options.arena_bytes /= 2;
  SiftExtractor small(options);
  auto refused = small.Extract(View(image));
  ASSERT_FALSE(refused.ok());
  EXPECT_EQ(refused.status().code(), StatusCode::kResourceExhausted);
  EXPECT_NE(refused.status().message().find("first-octave 0"), std::string::npos);
}

TEST(Sift, RejectsBadInput) {
  SiftExtractor sift(SiftOptions{});
  Image<float> tiny(8, 8);
  auto result = sift.Extract(View(tiny));
  ASSERT_FALSE(result.ok());
  EXPECT_EQ(result.status().code(), StatusCode::kInvalidArgument);

  SiftOptions bad;
  bad.first_octave = 2;
  EXPECT_FALSE(bad.Check().ok());
  SiftExtractor bad_sift(bad);
  Image<float> image(64, 64);
  EXPECT_FALSE(bad_sift.Extract(View(image)).ok());
}

TEST(Sift, FlatImageHasNoKeypoints) {
  Image<float> flat(128, 96);
  for (int y = 0; y < 96; ++y) std::fill(flat.row(y), flat.row(y) + 128, 0.5f);
  SiftExtractor sift(SiftOptions{});
  auto result = sift.Extract(View(flat));
  ASSERT_TRUE(result.ok());
  EXPECT_TRUE(result->keypoints.empty());
}

}  // namespace
}  // namespace reconar
