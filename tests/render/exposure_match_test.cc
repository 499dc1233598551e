// The AR view's exposure matching (render/ar/exposure_match.h) on images whose gains are known.
#include "render/ar/exposure_match.h"

#include <gtest/gtest.h>

#include <random>

#include "core/mesh/mesh.h"

namespace reconar {
namespace {

constexpr std::array<uint8_t, 3> kKey = {255, 0, 255};

// A model drawing of random colours with a key-coloured quarter, and the frame that sees it at
// `gain` where the model is, except where an occluder covers `occluded` of it.
void MakePair(const std::array<float, 3>& gain, double occluded, Image<uint8_t>* model, Image<uint8_t>* frame) {
  std::mt19937 random(11);
  std::uniform_int_distribution<int> colour(40, 180), any(0, 255);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  *model = Image<uint8_t>(80, 60, 3);
  *frame = Image<uint8_t>(80, 60, 3);
  for (int y = 0; y < 60; ++y) {
    for (int x = 0; x < 80; ++x) {
      uint8_t* m = model->row(y) + 3 * x;
      uint8_t* f = frame->row(y) + 3 * x;
      const bool background = x < 20;
      const bool hidden = unit(random) < occluded;
      for (int c = 0; c < 3; ++c) {
        m[c] = background ? kKey[static_cast<size_t>(c)] : static_cast<uint8_t>(colour(random));
        const float seen = std::min(255.0f, m[c] * gain[static_cast<size_t>(c)]);
        f[c] = background || hidden ? static_cast<uint8_t>(any(random)) : static_cast<uint8_t>(std::lround(seen));
      }
    }
  }
}

TEST(ExposureMatchTest, EstimatesTheGainWhereTheModelIsDespiteAnOccluder) {
  const std::array<float, 3> gain = {1.3f, 1.1f, 0.7f};
  Image<uint8_t> model, frame;
  MakePair(gain, 0.3, &model, &frame);
  ExposureMatcher matcher;
  const auto estimate = matcher.Estimate(model, frame, kKey);
  ASSERT_TRUE(estimate.has_value());
  for (size_t c = 0; c < 3; ++c) EXPECT_NEAR((*estimate)[c], gain[c], 0.03 * gain[c]) << c;

  // Too few pixels of the model (a 5 x 5 corner): no estimate.
  Image<uint8_t> hidden = model;
  for (int y = 0; y < 60; ++y) {
    for (int x = y < 5 ? 25 : 20; x < 80; ++x) std::copy(kKey.begin(), kKey.end(), hidden.row(y) + 3 * x);
  }
  EXPECT_FALSE(matcher.Estimate(hidden, frame, kKey).has_value());
  // Images of different sizes: none either.
  EXPECT_FALSE(matcher.Estimate(model, Image<uint8_t>(40, 30, 3), kKey).has_value());
}

TEST(ExposureMatchTest, SmoothsSmallChangesTakesJumpsAtOnceAndClamps) {
  ExposureMatcher matcher;
  EXPECT_EQ(matcher.gain(), (std::array<float, 3>{1.0f, 1.0f, 1.0f}));
  matcher.Update(std::nullopt);  // a frame without the model keeps the gain
  EXPECT_EQ(matcher.gain()[0], 1.0f);
  matcher.Update(std::array<float, 3>{1.5f, 1.0f, 1.0f});  // the first estimate is taken
  EXPECT_FLOAT_EQ(matcher.gain()[0], 1.5f);
  matcher.Update(std::array<float, 3>{1.6f, 1.1f, 0.95f});  // within 1.25: halfway in log
  EXPECT_NEAR(matcher.gain()[0], std::sqrt(1.5f * 1.6f), 1e-5);
  EXPECT_NEAR(matcher.gain()[1], std::sqrt(1.1f), 1e-5);
  matcher.Update(std::array<float, 3>{0.6f, 1.0f, 1.0f});  // a jump in one channel: all taken
  EXPECT_FLOAT_EQ(matcher.gain()[0], 0.6f);
  EXPECT_FLOAT_EQ(matcher.gain()[1], 1.0f);
  matcher.Update(std::array<float, 3>{20.0f, 0.01f, 1.0f});
  EXPECT_FLOAT_EQ(matcher.gain()[0], 4.0f);
  EXPECT_FLOAT_EQ(matcher.gain()[1], 0.25f);
}

TEST(ExposureMatchTest, BoxReduceAveragesEachBlock) {
  Image<uint8_t> frame(8, 4, 3);
  for (int y = 0; y < 4; ++y) {
    for (int x = 0; x < 8; ++x) {
      for (int c = 0; c < 3; ++c) frame.row(y)[3 * x + c] = static_cast<uint8_t>(x < 4 ? 10 * (y % 2) : 100 + c);
    }
  }
  Image<uint8_t> reduced(2, 1, 3);
  BoxReduce(frame.view(), 8, 4, &reduced);
  EXPECT_EQ(reduced.row(0)[0], 5);
  EXPECT_EQ(reduced.row(0)[3], 100);
  EXPECT_EQ(reduced.row(0)[5], 102);
}

// Two charts of one square, each on its own page, sharing an edge by position: the proxy welds
// the shared vertices and takes each chart's page colour.
TEST(ExposureMatchTest, ProxyTakesTheTextureColoursAndWeldsTheCharts) {
  Mesh textured;
  textured.positions = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 0, 0}, {1, 1, 0}, {0, 1, 0}};
  textured.texcoords.assign(6, Eigen::Vector2f(0.5f, 0.5f));
  textured.triangles = {{0, 1, 2}, {3, 4, 5}};
  auto plain = [](uint8_t r, uint8_t g, uint8_t b) {
    Image<uint8_t> image(4, 4, 3);
    for (int y = 0; y < 4; ++y) {
      for (int x = 0; x < 4; ++x) {
        image.row(y)[3 * x] = r;
        image.row(y)[3 * x + 1] = g;
        image.row(y)[3 * x + 2] = b;
      }
    }
    return image;
  };
  std::vector<TexturePage> pages;
  pages.push_back({0, plain(200, 0, 0)});
  pages.push_back({1, plain(0, 0, 100)});
  const Result<Mesh> proxy = ExposureProxy(textured, pages, 100);
  ASSERT_TRUE(proxy.ok()) << proxy.status().ToString();
  ASSERT_EQ(proxy->positions.size(), 4u);
  ASSERT_EQ(proxy->triangles.size(), 2u);
  for (size_t v = 0; v < 4; ++v) {
    const Eigen::Vector3f& p = proxy->positions[v];
    const std::array<uint8_t, 4>& c = proxy->colors[v];
    if (p == Eigen::Vector3f(1, 0, 0)) {
      EXPECT_EQ(c, (std::array<uint8_t, 4>{200, 0, 0, 255}));
    } else if (p == Eigen::Vector3f(0, 1, 0)) {
      EXPECT_EQ(c, (std::array<uint8_t, 4>{0, 0, 100, 255}));
    } else {
      EXPECT_EQ(c, (std::array<uint8_t, 4>{100, 0, 50, 255}));  // on both charts: their mean
    }
  }
  EXPECT_FALSE(ExposureProxy(textured, {}, 100).ok());
  textured.texcoords.clear();
  EXPECT_FALSE(ExposureProxy(textured, pages, 100).ok());
}

}  // namespace
}  // namespace reconar
