#pragma once
// Words on the capture's preview, the view's measurements and compare's report picture without a
// font library: a built-in 5 x 7 pixel font (a cell of 6 x 8 with the spacing), drawn on the CPU
// at an integer scale. It holds what they say: lower-case letters, digits, space and
// : , . % / - + ( ) ' _ = < >. Any other character is drawn as a hollow box, so that a missing
// glyph shows instead of vanishing.
#include <array>
#include <cstdint>
#include <string>

#include "core/base/image.h"

namespace reconar {

inline constexpr int kGlyphWidth = 5, kGlyphHeight = 7;
inline constexpr int kGlyphAdvance = 6;  // columns per character, the gap included

// The glyph's pixel (column 0..4, row 0..6, row 0 the top); false for a character outside the font
// except where its hollow box lies.
bool GlyphPixel(char c, int column, int row);
// Whether every character of `text` has its own glyph.
bool FontCovers(const std::string& text);

// Width in pixels of `text` at `scale` (0 for ""); the height is kGlyphHeight * scale.
int TextWidthPx(const std::string& text, int scale);

// Draws `text` with its top-left corner at (x, y), each font pixel a scale x scale square of
// `colour`; what falls outside the image is clipped.
void DrawText(const std::string& text, int x, int y, int scale, const std::array<uint8_t, 3>& colour,
              Image<uint8_t>* rgb);

}  // namespace reconar
