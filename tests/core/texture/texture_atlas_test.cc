// Packing charts by their shape (core/texture/texture_atlas.h).
#include "core/texture/texture_atlas.h"

#include <gtest/gtest.h>

#include <random>

namespace reconar {
namespace {

constexpr int kPadding = 4;

// A chart of one right triangle with legs of `size` pixels: with its right angle at the top left
// (its face fills the upper-left half of its rectangle), or at the bottom right.
TextureChart TriangleChart(int patch, double size, bool top_left) {
  TextureChart chart;
  chart.patch = patch;
  chart.photo = 0;
  chart.vertices = {0, 1, 2};
  chart.faces = {patch};
  chart.triangles = {{0, 1, 2}};
  if (top_left) {
    chart.pixels = {{0.0, 0.0}, {size, 0.0}, {0.0, size}};
  } else {
    chart.pixels = {{size, 0.0}, {size, size}, {0.0, size}};
  }
  chart.pixel_min = Eigen::Vector2d::Constant(0.5);
  chart.pixel_max = Eigen::Vector2d::Constant(size + 0.5);
  return chart;
}

// Triangles of both kinds, 30 to 110 pixels, whose rectangles (padding included) add up to
// `rectangle_share` of a `side` x `side` page.
std::vector<TextureChart> TriangleCharts(int side, double rectangle_share, unsigned seed) {
  std::mt19937 random(seed);
  std::uniform_real_distribution<double> size(30.0, 110.0);
  std::vector<TextureChart> charts;
  double area = 0.0;
  while (area < rectangle_share * side * side) {
    const double legs = size(random);
    charts.push_back(TriangleChart(static_cast<int>(charts.size()), legs, charts.size() % 2 == 0));
    const double rectangle = std::ceil(legs) + 2 * kPadding + 1;
    area += rectangle * rectangle;
  }
  return charts;
}

TEST(TextureAtlasTest, ChartsNestByTheirShapeAndNeverShareATexel) {
  // The rectangles add up to more than the page: packed as rectangles they could not be held at
  // full resolution; by their shapes the triangles fit two to a rectangle's room.
  constexpr int kSide = 1024;
  const Result<AtlasLayout> layout = PackCharts(TriangleCharts(kSide, 1.1, 3), kSide, kPadding, 1);
  ASSERT_TRUE(layout.ok()) << layout.status().ToString();
  ASSERT_EQ(layout->pages.size(), 1u);
  EXPECT_EQ(layout->scale, 1.0);
  const AtlasPage& page = layout->pages[0];
  std::vector<int> owner(static_cast<size_t>(page.width) * page.height, -1);
  for (size_t k = 0; k < layout->charts.size(); ++k) {
    const TextureChart& chart = layout->charts[k];
    ASSERT_GE(chart.x, 0);
    ASSERT_GE(chart.y, 0);
    ASSERT_LE(chart.x + chart.width, page.width);
    ASSERT_LE(chart.y + chart.height, page.height);
    for (int y = chart.y; y < chart.y + chart.height; ++y) {
      for (int x = chart.x; x < chart.x + chart.width; ++x) {
        if (!chart.Owns(x, y)) continue;
        int& texel = owner[static_cast<size_t>(y) * page.width + x];
        ASSERT_EQ(texel, -1) << "charts " << texel << " and " << k << " share texel " << x << ", " << y;
        texel = static_cast<int>(k);
      }
    }
    // The face and every texel within padding + 1 of it are the chart's own.
    std::array<Eigen::Vector2d, 3> corner;
    for (size_t i = 0; i < 3; ++i) corner[i] = layout->Texel(chart, i);
    auto inside = [&](double px, double py) {
      auto side_of = [&](const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
        return (b.x() - a.x()) * (py - a.y()) - (b.y() - a.y()) * (px - a.x());
      };
      const double s0 = side_of(corner[0], corner[1]), s1 = side_of(corner[1], corner[2]), s2 = side_of(corner[2], corner[0]);
      return (s0 >= 0 && s1 >= 0 && s2 >= 0) || (s0 <= 0 && s1 <= 0 && s2 <= 0);
    };
    for (int y = chart.y; y < chart.y + chart.height; ++y) {
      for (int x = chart.x; x < chart.x + chart.width; ++x) {
        if (!inside(x + 0.5, y + 0.5)) continue;
        for (int dy = -kPadding - 1; dy <= kPadding + 1; ++dy) {
          for (int dx = -kPadding - 1; dx <= kPadding + 1; ++dx) {
            const int nx = x + dx, ny = y + dy;
            if (nx < chart.x || ny < chart.y || nx >= chart.x + chart.width || ny >= chart.y + chart.height) continue;
            ASSERT_TRUE(chart.Owns(nx, ny)) << "chart " << k << " texel " << nx << ", " << ny;
          }
        }
      }
    }
  }
}

TEST(TextureAtlasTest, TheChartOfFacesWithoutAPhotoOwnsItsRectangle) {
  TextureChart white;
  white.patch = -1;
  white.faces = {0};
  const Result<AtlasLayout> layout = PackCharts({white}, 256, kPadding, 1);
  ASSERT_TRUE(layout.ok()) << layout.status().ToString();
  const TextureChart& chart = layout->charts[0];
  for (int y = chart.y; y < chart.y + chart.height; ++y) {
    for (int x = chart.x; x < chart.x + chart.width; ++x) EXPECT_TRUE(chart.Owns(x, y));
  }
  EXPECT_FALSE(chart.Owns(chart.x + chart.width, chart.y));
  EXPECT_FALSE(chart.Owns(chart.x, chart.y + chart.height));
}

}  // namespace
}  // namespace reconar
