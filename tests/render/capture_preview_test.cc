// The capture's preview words (core/base/bitmap_text.h, render/ar/capture_preview.h): the built-in
// font holds every advice the gate gives, its glyphs tell apart, and the words land where drawn.
#include "render/ar/capture_preview.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <set>
#include <string>
#include <vector>

#include "core/base/bitmap_text.h"
#include "tracker/keyframe_gate.h"

namespace reconar {
namespace {

const std::string kCharacters = "abcdefghijklmnopqrstuvwxyz0123456789 :,.%/-()'";

std::vector<bool> Bitmap(char c) {
  std::vector<bool> bits;
  for (int row = 0; row < kGlyphHeight; ++row) {
    for (int column = 0; column < kGlyphWidth; ++column) bits.push_back(GlyphPixel(c, column, row));
  }
  return bits;
}

TEST(BitmapText, TheFontHoldsEveryAdviceAndTheCounts) {
  for (const char* advice : GateAdvice::kAll) EXPECT_TRUE(FontCovers(advice)) << advice;
  EXPECT_TRUE(FontCovers("1234567890 keyframes, 99 registered"));
  EXPECT_FALSE(FontCovers("Too fast"));  // no capitals
}

TEST(BitmapText, EveryGlyphIsItsOwnAndOnlySpaceIsBlank) {
  std::set<std::vector<bool>> seen;
  for (const char c : kCharacters) {
    ASSERT_TRUE(FontCovers(std::string(1, c))) << c;
    const std::vector<bool> bits = Bitmap(c);
    EXPECT_TRUE(seen.insert(bits).second) << "'" << c << "' looks like another glyph";
    const bool blank = std::count(bits.begin(), bits.end(), true) == 0;
    EXPECT_EQ(blank, c == ' ') << c;
  }
  // Outside the font: a hollow box, unlike every glyph.
  const std::vector<bool> box = Bitmap('Q');
  EXPECT_EQ(seen.count(box), 0u);
  EXPECT_TRUE(GlyphPixel('Q', 0, 0) && GlyphPixel('Q', 4, 6));
  EXPECT_FALSE(GlyphPixel('Q', 2, 3));
  EXPECT_FALSE(GlyphPixel('a', 5, 0));  // outside the cell
}

TEST(BitmapText, DrawsEachFontPixelAsAScaledSquareAndClips) {
  Image<uint8_t> image(40, 20, 3);
  std::fill(image.row(0), image.row(0) + 3 * 40 * 20, uint8_t{0});
  DrawText("i.", 4, 2, 2, {255, 255, 255}, &image);
  EXPECT_EQ(TextWidthPx("i.", 2), 22);
  const auto lit = [&](int x, int y) { return image.row(y)[3 * x] == 255; };
  for (int row = 0; row < kGlyphHeight; ++row) {
    for (int column = 0; column < kGlyphWidth; ++column) {
      for (int d = 0; d < 4; ++d) {
        const int x = 4 + 2 * column + d % 2, y = 2 + 2 * row + d / 2;
        EXPECT_EQ(lit(x, y), GlyphPixel('i', column, row)) << column << "," << row;
        EXPECT_EQ(lit(x + 12, y), GlyphPixel('.', column, row)) << column << "," << row;
      }
    }
  }
  int lit_outside = 0;
  for (int y = 0; y < 20; ++y) {
    for (int x = 0; x < 40; ++x) lit_outside += lit(x, y) && (x < 4 || x >= 26 || y < 2 || y >= 16);
  }
  EXPECT_EQ(lit_outside, 0);
  DrawText("clipped at every edge", -7, -5, 3, {255, 255, 255}, &image);  // no write outside the image
  DrawText("clipped", 30, 15, 3, {255, 255, 255}, &image);
}

TEST(CapturePreview, TheAdviceAndTheCountsAreWrittenTopLeft) {
  const auto draw = [](const std::string& advice) {
    Image<uint8_t> image(640, 480, 3);
    std::fill(image.row(0), image.row(0) + 3 * 640 * 480, uint8_t{128});
    CapturePreviewState state;
    state.advice = advice;
    state.keyframe_registered = {true, true, false};
    DrawCapturePreview(state, &image);
    return image;
  };
  const Image<uint8_t> fast = draw(GateAdvice::kTooFast), sideways = draw(GateAdvice::kMoveSideways);
  // White font pixels in the top-left band: the two advices differ there, and nowhere else.
  int white = 0, differing = 0, differing_elsewhere = 0;
  for (int y = 0; y < 480; ++y) {
    for (int x = 0; x < 640; ++x) {
      const bool in_band = x < 400 && y < 60;
      white += in_band && fast.row(y)[3 * x] == 255 && fast.row(y)[3 * x + 1] == 255;
      const bool differs = std::equal(fast.row(y) + 3 * x, fast.row(y) + 3 * x + 3, sideways.row(y) + 3 * x) == false;
      differing += differs;
      differing_elsewhere += differs && !in_band;
    }
  }
  EXPECT_GT(white, 200) << "the words are drawn";
  EXPECT_GT(differing, 100) << "the advice is drawn";
  EXPECT_EQ(differing_elsewhere, 0);
}

TEST(CapturePreview, LongAdviceIsWrappedAtSpacesInsideThePicture) {
  Image<uint8_t> image(320, 240, 3);
  std::fill(image.row(0), image.row(0) + 3 * 320 * 240, uint8_t{0});
  CapturePreviewState state;
  state.advice = GateAdvice::kRestarted;
  state.coverage.assign(12, false);
  DrawCapturePreview(state, &image);
  // White text rows: the advice takes several lines, all left of the coverage ring.
  int lines = 0, rightmost = 0;
  bool in_line = false;
  for (int y = 0; y < 240; ++y) {
    bool white_row = false;
    for (int x = 0; x < 320; ++x) {
      if (image.row(y)[3 * x] == 255 && image.row(y)[3 * x + 1] == 255 && image.row(y)[3 * x + 2] == 255) {
        white_row = true;
        rightmost = std::max(rightmost, x);
      }
    }
    if (white_row && !in_line) ++lines;
    in_line = white_row;
  }
  EXPECT_GE(lines, 3) << "the advice (49 characters) and the counts on separate lines";
  EXPECT_LT(rightmost, 320 - 14 * 5) << "the words run into the coverage ring";
}

}  // namespace
}  // namespace reconar
