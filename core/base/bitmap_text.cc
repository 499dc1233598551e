#include "core/base/bitmap_text.h"

#include <cstring>

namespace reconar {
namespace {

struct Glyph {
  char c;
  // Seven rows of five pixels, top row first, separated by spaces: '#' drawn, '.' not.
  const char* rows;
};

constexpr Glyph kFont[] = {
    {'a', "..... ..... .###. ....# .#### #...# .####"}, {'b', "#.... #.... ####. #...# #...# #...# ####."},
    {'c', "..... ..... .###. #.... #.... #...# .###."}, {'d', "....# ....# .#### #...# #...# #...# .####"},
    {'e', "..... ..... .###. #...# ##### #.... .###."}, {'f', "..##. .#..# .#... ###.. .#... .#... .#..."},
    {'g', "..... .#### #...# #...# .#### ....# .###."}, {'h', "#.... #.... #.##. ##..# #...# #...# #...#"},
    {'i', "..#.. ..... .##.. ..#.. ..#.. ..#.. .###."}, {'j', "...#. ..... ..##. ...#. ...#. #..#. .##.."},
    {'k', "#.... #.... #..#. #.#.. ##... #.#.. #..#."}, {'l', ".##.. ..#.. ..#.. ..#.. ..#.. ..#.. .###."},
    {'m', "..... ..... ##.#. #.#.# #.#.# #...# #...#"}, {'n', "..... ..... #.##. ##..# #...# #...# #...#"},
    {'o', "..... ..... .###. #...# #...# #...# .###."}, {'p', "..... ####. #...# #...# ####. #.... #...."},
    {'q', "..... .#### #...# #...# .#### ....# ....#"}, {'r', "..... ..... #.##. ##..# #.... #.... #...."},
    {'s', "..... ..... .#### #.... .###. ....# ####."}, {'t', ".#... .#... ###.. .#... .#... .#..# ..##."},
    {'u', "..... ..... #...# #...# #...# #..## .##.#"}, {'v', "..... ..... #...# #...# #...# .#.#. ..#.."},
    {'w', "..... ..... #...# #...# #.#.# #.#.# .#.#."}, {'x', "..... ..... #...# .#.#. ..#.. .#.#. #...#"},
    {'y', "..... #...# #...# #...# .#### ....# .###."}, {'z', "..... ..... ##### ...#. ..#.. .#... #####"},
    {'0', ".###. #...# #..## #.#.# ##..# #...# .###."}, {'1', "..#.. .##.. ..#.. ..#.. ..#.. ..#.. .###."},
    {'2', ".###. #...# ....# ...#. ..#.. .#... #####"}, {'3', "##### ...#. ..#.. ...#. ....# #...# .###."},
    {'4', "...#. ..##. .#.#. #..#. ##### ...#. ...#."}, {'5', "##### #.... ####. ....# ....# #...# .###."},
    {'6', "..##. .#... #.... ####. #...# #...# .###."}, {'7', "##### ....# ...#. ..#.. .#... .#... .#..."},
    {'8', ".###. #...# #...# .###. #...# #...# .###."}, {'9', ".###. #...# #...# .#### ....# ...#. .##.."},
    {' ', "..... ..... ..... ..... ..... ..... ....."}, {':', "..... .##.. .##.. ..... .##.. .##.. ....."},
    {',', "..... ..... ..... ..... .##.. ..#.. .#..."}, {'.', "..... ..... ..... ..... ..... .##.. .##.."},
    {'%', "##... ##..# ...#. ..#.. .#... #..## ...##"}, {'/', "..... ....# ...#. ..#.. .#... #.... ....."},
    {'-', "..... ..... ..... ##### ..... ..... ....."}, {'(', "...#. ..#.. .#... .#... .#... ..#.. ...#."},
    {')', ".#... ..#.. ...#. ...#. ...#. ..#.. .#..."}, {'\'', "..#.. ..#.. .#... ..... ..... ..... ....."},
    {'+', "..... ..#.. ..#.. ##### ..#.. ..#.. ....."}, {'_', "..... ..... ..... ..... ..... ..... #####"},
    {'=', "..... ..... ##### ..... ##### ..... ....."}, {'<', "...#. ..#.. .#... #.... .#... ..#.. ...#."},
    {'>', ".#... ..#.. ...#. ....# ...#. ..#.. .#..."},
};

// Every glyph: seven rows of five '#' or '.' with one space between rows.
constexpr bool FontIsWellFormed() {
  for (const Glyph& glyph : kFont) {
    for (int i = 0; i < kGlyphHeight * (kGlyphWidth + 1) - 1; ++i) {
      const char pixel = glyph.rows[i];
      const bool gap = i % (kGlyphWidth + 1) == kGlyphWidth;
      if (gap ? pixel != ' ' : (pixel != '#' && pixel != '.')) return false;
    }
    if (glyph.rows[kGlyphHeight * (kGlyphWidth + 1) - 1] != '\0') return false;
  }
  return true;
}
static_assert(FontIsWellFormed(), "a glyph of kFont is not 7 rows of 5 pixels");

const Glyph* Find(char c) {
  for (const Glyph& glyph : kFont) {
    if (glyph.c == c) return &glyph;
  }
  return nullptr;
}

}  // namespace

bool GlyphPixel(char c, int column, int row) {
  if (column < 0 || column >= kGlyphWidth || row < 0 || row >= kGlyphHeight) return false;
  const Glyph* glyph = Find(c);
  if (glyph == nullptr) return row == 0 || row == kGlyphHeight - 1 || column == 0 || column == kGlyphWidth - 1;
  return glyph->rows[row * (kGlyphWidth + 1) + column] == '#';
}

bool FontCovers(const std::string& text) {
  for (const char c : text) {
    if (Find(c) == nullptr) return false;
  }
  return true;
}

int TextWidthPx(const std::string& text, int scale) {
  if (text.empty()) return 0;
  return (static_cast<int>(text.size()) * kGlyphAdvance - (kGlyphAdvance - kGlyphWidth)) * scale;
}

void DrawText(const std::string& text, int x, int y, int scale, const std::array<uint8_t, 3>& colour,
              Image<uint8_t>* rgb) {
  for (size_t i = 0; i < text.size(); ++i) {
    const int left = x + static_cast<int>(i) * kGlyphAdvance * scale;
    for (int row = 0; row < kGlyphHeight; ++row) {
      for (int column = 0; column < kGlyphWidth; ++column) {
        if (!GlyphPixel(text[i], column, row)) continue;
        for (int dy = 0; dy < scale; ++dy) {
          const int py = y + row * scale + dy;
          if (py < 0 || py >= rgb->height()) continue;
          uint8_t* line = rgb->row(py);
          for (int dx = 0; dx < scale; ++dx) {
            const int px = left + column * scale + dx;
            if (px < 0 || px >= rgb->width()) continue;
            std::memcpy(line + 3 * px, colour.data(), 3);
          }
        }
      }
    }
  }
}

}  // namespace reconar
