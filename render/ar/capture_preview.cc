#include "render/ar/capture_preview.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <string>
#include <vector>

#include "core/base/bitmap_text.h"

namespace reconar {
namespace {

using Colour = std::array<uint8_t, 3>;

constexpr Colour kGreen = {40, 200, 60};
constexpr Colour kBlue = {60, 140, 255};
constexpr Colour kRed = {230, 40, 40};
constexpr Colour kGrey = {170, 170, 170};
constexpr Colour kDark = {50, 50, 50};
constexpr Colour kYellow = {255, 220, 0};
constexpr Colour kWhite = {255, 255, 255};
constexpr Colour kBlack = {0, 0, 0};

// `alpha` of `colour` over the pixel.
void Blend(Image<uint8_t>* rgb, int x, int y, const Colour& colour, double alpha) {
  if (x < 0 || y < 0 || x >= rgb->width() || y >= rgb->height()) return;
  uint8_t* pixel = rgb->row(y) + 3 * x;
  for (int c = 0; c < 3; ++c)
    pixel[c] = static_cast<uint8_t>(std::lround((1.0 - alpha) * pixel[c] + alpha * colour[static_cast<size_t>(c)]));
}

void FillRect(Image<uint8_t>* rgb, int x0, int y0, int x1, int y1, const Colour& colour, double alpha) {
  for (int y = y0; y < y1; ++y)
    for (int x = x0; x < x1; ++x) Blend(rgb, x, y, colour, alpha);
}

// A line `thickness` pixels wide (a square brush stepped along it).
void DrawLine(Image<uint8_t>* rgb, const Eigen::Vector2d& a, const Eigen::Vector2d& b, int thickness,
              const Colour& colour) {
  const int steps = std::max(1, static_cast<int>(std::ceil((b - a).norm())));
  for (int i = 0; i <= steps; ++i) {
    const Eigen::Vector2d p = a + (b - a) * (static_cast<double>(i) / steps);
    const int x = static_cast<int>(std::lround(p.x())), y = static_cast<int>(std::lround(p.y()));
    FillRect(rgb, x - thickness / 2, y - thickness / 2, x - thickness / 2 + thickness, y - thickness / 2 + thickness,
             colour, 1.0);
  }
}

// `text` cut at spaces into lines of at most `width` characters (a longer word is cut).
std::vector<std::string> WrapWords(const std::string& text, size_t width) {
  std::vector<std::string> lines;
  if (width == 0) return lines;
  std::string rest = text;
  while (rest.size() > width) {
    size_t cut = rest.rfind(' ', width);
    if (cut == std::string::npos || cut == 0) cut = width;
    lines.push_back(rest.substr(0, cut));
    rest = rest.substr(cut + (rest[cut] == ' ' ? 1 : 0));
  }
  if (!rest.empty()) lines.push_back(rest);
  return lines;
}

}  // namespace

void DrawCapturePreview(const CapturePreviewState& state, Image<uint8_t>* rgb) {
  const int w = rgb->width(), h = rgb->height();
  const int unit = std::max(2, std::min(w, h) / 60);  // 8 px at 480 lines

  const Colour border = state.verdict == GateVerdict::kKeyframe   ? kGreen
                        : state.verdict == GateVerdict::kTooClose ? kBlue
                                                                  : kRed;
  FillRect(rgb, 0, 0, w, unit, border, 1.0);
  FillRect(rgb, 0, h - unit, w, h, border, 1.0);
  FillRect(rgb, 0, unit, unit, h - unit, border, 1.0);
  FillRect(rgb, w - unit, unit, w, h - unit, border, 1.0);

  for (const std::array<Eigen::Vector2d, 4>& tag : state.tags) {
    for (int c = 0; c < 4; ++c)
      DrawLine(rgb, tag[static_cast<size_t>(c)], tag[static_cast<size_t>((c + 1) % 4)], 3, kYellow);
  }

  // Keyframes: squares along the bottom, as many as fit.
  const int step = 2 * unit;
  const int y0 = h - 4 * unit, y1 = y0 + step - unit / 2;
  for (size_t k = 0; k < state.keyframe_registered.size(); ++k) {
    const int x0 = 2 * unit + static_cast<int>(k) * step;
    if (x0 + step > w - 2 * unit) break;
    FillRect(rgb, x0, y0, x0 + step - unit / 2, y1, state.keyframe_registered[k] ? kGreen : kGrey, 0.9);
  }

  // The words, top left, clear of the coverage ring, wrapped at spaces to fit.
  const int registered =
      static_cast<int>(std::count(state.keyframe_registered.begin(), state.keyframe_registered.end(), true));
  const std::string counts =
      std::to_string(state.keyframe_registered.size()) + " keyframes, " + std::to_string(registered) + " registered";
  const int scale = std::max(1, unit / 4);
  const int line_height = (kGlyphHeight + 3) * scale;
  const int text_x = 2 * unit, text_y = 2 * unit;
  const int max_chars = std::max(0, (w - 2 * unit - 14 * unit - text_x) / (kGlyphAdvance * scale));
  std::vector<std::string> lines = WrapWords(state.advice, static_cast<size_t>(max_chars));
  for (std::string& line : WrapWords(counts, static_cast<size_t>(max_chars))) lines.push_back(std::move(line));
  int line_y = text_y;
  for (const std::string& line : lines) {
    FillRect(rgb, text_x - scale, line_y - scale, text_x + TextWidthPx(line, scale) + scale,
             line_y + (kGlyphHeight + 1) * scale, kBlack, 0.55);
    DrawText(line, text_x, line_y, scale, kWhite, rgb);
    line_y += line_height;
  }

  // Coverage ring, counter-clockwise from the right as ViewCoverage's azimuths.
  if (state.coverage.empty()) return;
  const double outer = 6.0 * unit, inner = 3.5 * unit;
  const double cx = w - 2 * unit - outer, cy = 2 * unit + outer;
  constexpr double kTwoPi = 6.283185307179586;
  const int sectors = static_cast<int>(state.coverage.size());
  for (int y = static_cast<int>(cy - outer); y <= static_cast<int>(cy + outer); ++y) {
    for (int x = static_cast<int>(cx - outer); x <= static_cast<int>(cx + outer); ++x) {
      const double dx = x - cx, dy = cy - y;  // image y points down
      const double r = std::hypot(dx, dy);
      if (r < inner || r > outer) continue;
      double azimuth = std::atan2(dy, dx) + 0.5 * kTwoPi / sectors;  // sector 0 centred on the right
      if (azimuth < 0.0) azimuth += kTwoPi;
      if (azimuth >= kTwoPi) azimuth -= kTwoPi;
      const int sector = std::min(sectors - 1, static_cast<int>(azimuth / kTwoPi * sectors));
      Blend(rgb, x, y, state.coverage[static_cast<size_t>(sector)] ? kGreen : kDark, 0.8);
    }
  }
}

}  // namespace reconar
