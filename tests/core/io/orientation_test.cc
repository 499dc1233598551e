#include "core/io/orientation.h"

#include <gtest/gtest.h>

#include <string>
#include <vector>

namespace reconar {
namespace {

// A 3x2 image whose pixels are the letters
//   a b c
//   d e f
// in every channel (channel k holds letter + k, so channel order is checked too).
Image<uint8_t> Letters(int channels) {
  Image<uint8_t> image(3, 2, channels);
  const std::string letters = "abcdef";
  for (int i = 0; i < 6; ++i) {
    for (int k = 0; k < channels; ++k) image.data()[i * channels + k] = static_cast<uint8_t>(letters[i] + k);
  }
  return image;
}

// Rows joined by '/', from channel 0.
std::string Render(const Image<uint8_t>& image) {
  std::string s;
  for (int y = 0; y < image.height(); ++y) {
    if (y > 0) s += '/';
    for (int x = 0; x < image.width(); ++x) s += static_cast<char>(image.row(y)[x * image.channels()]);
  }
  return s;
}

TEST(OrientationTest, AllEightOrientationsOnA3x2Image) {
  // Expected upright images, from the EXIF definitions of where stored row 0 / column 0 go.
  const std::vector<std::string> expected = {
      "",           // unused
      "abc/def",    // 1: as stored
      "cba/fed",    // 2: mirrored left-right
      "fed/cba",    // 3: rotated 180°
      "def/abc",    // 4: mirrored top-bottom
      "ad/be/cf",   // 5: transposed (row 0 -> left column, column 0 -> top row)
      "da/eb/fc",   // 6: rotated 90° clockwise (row 0 -> right column)
      "fc/eb/da",   // 7: transversed (row 0 -> right column, column 0 -> bottom row)
      "cf/be/ad",   // 8: rotated 90° counter-clockwise (row 0 -> left column, bottom to top)
  };
  for (int channels : {1, 3}) {
    const Image<uint8_t> stored = Letters(channels);
    for (int orientation = 1; orientation <= 8; ++orientation) {
      SCOPED_TRACE("orientation " + std::to_string(orientation) + ", channels " + std::to_string(channels));
      const Image<uint8_t> upright = ApplyOrientation(stored, orientation);
      EXPECT_EQ(upright.channels(), channels);
      EXPECT_EQ(upright.width(), orientation >= 5 ? 2 : 3);
      EXPECT_EQ(upright.height(), orientation >= 5 ? 3 : 2);
      EXPECT_EQ(Render(upright), expected[orientation]);
      for (int i = 0; i < upright.width() * upright.height(); ++i) {
        for (int k = 1; k < channels; ++k) {
          EXPECT_EQ(upright.data()[i * channels + k], upright.data()[i * channels] + k);
        }
      }
    }
  }
}

TEST(OrientationTest, InverseOrientationsRestoreTheImage) {
  const int inverse[9] = {0, 1, 2, 3, 4, 5, 8, 7, 6};
  const Image<uint8_t> stored = Letters(3);
  for (int orientation = 1; orientation <= 8; ++orientation) {
    const Image<uint8_t> back = ApplyOrientation(ApplyOrientation(stored, orientation), inverse[orientation]);
    EXPECT_EQ(Render(back), "abc/def") << orientation;
  }
}

TEST(OrientationTest, InvalidOrientationIsIdentity) {
  const Image<uint8_t> stored = Letters(3);
  EXPECT_EQ(Render(ApplyOrientation(stored, 0)), "abc/def");
  EXPECT_EQ(Render(ApplyOrientation(stored, 9)), "abc/def");
  EXPECT_TRUE(ApplyOrientation(Image<uint8_t>(), 6).empty());
}

}  // namespace
}  // namespace reconar
