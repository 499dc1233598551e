#include "core/compare/report_picture.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <string>

#include <Eigen/Geometry>

#include "core/base/bitmap_text.h"

namespace reconar {
namespace {

constexpr int kWidth = 1280;
constexpr int kTableTop = 610, kRow = 22, kMaxRows = 40;
using Colour = std::array<uint8_t, 3>;
constexpr Colour kInk = {20, 20, 20}, kFaint = {150, 150, 150};

void Fill(int x0, int y0, int x1, int y1, const Colour& colour, Image<uint8_t>* rgb) {
  for (int y = std::max(0, y0); y < std::min(rgb->height(), y1); ++y) {
    for (int x = std::max(0, x0); x < std::min(rgb->width(), x1); ++x) {
      for (int c = 0; c < 3; ++c) rgb->row(y)[3 * x + c] = colour[static_cast<size_t>(c)];
    }
  }
}

// The font has lower-case letters only.
std::string Lower(std::string text) {
  for (char& c : text) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return text;
}

void Text(const std::string& text, int x, int y, int scale, const Colour& colour, Image<uint8_t>* rgb) {
  DrawText(Lower(text), x, y, scale, colour, rgb);
}

std::string Format(const char* format, double a) {
  char text[64];
  std::snprintf(text, sizeof(text), format, a);
  return text;
}

Colour Rgb(const std::array<uint8_t, 4>& rgba) { return {rgba[0], rgba[1], rgba[2]}; }

Colour VerdictColour(const std::string& verdict) {
  if (verdict == "as_designed") return {30, 140, 60};
  if (verdict == "deviates") return {200, 40, 30};
  if (verdict == "missing") return {220, 120, 0};
  return kFaint;
}

// Signed deviations in 60 bins over +-3 tolerances, the outliers counted at the ends.
void DrawHistogram(const CompareReport& report, double full, int x0, int y0, int width, int height,
                   Image<uint8_t>* rgb) {
  constexpr int kBins = 60;
  std::vector<int> counts(kBins, 0);
  int below = 0, above = 0;
  const DeviationReport& deviation = report.deviation;
  for (size_t i = 0; i < deviation.signed_distance_m.size(); ++i) {
    if (deviation.element_of_point[i] < 0) continue;
    const double d = deviation.signed_distance_m[i];
    if (d < -full) {
      ++below;
    } else if (d >= full) {
      ++above;
    } else {
      ++counts[static_cast<size_t>(std::clamp(static_cast<int>((d + full) / (2.0 * full) * kBins), 0, kBins - 1))];
    }
  }
  Text("deviation of the as-built points (mm)", x0, y0 - 24, 2, kInk, rgb);
  const int tallest = std::max(1, *std::max_element(counts.begin(), counts.end()));
  const int bar = width / kBins;
  for (int b = 0; b < kBins; ++b) {
    const int h = static_cast<int>(std::lround(static_cast<double>(height) * counts[static_cast<size_t>(b)] / tallest));
    const double centre = -full + (b + 0.5) * 2.0 * full / kBins;
    Colour colour = Rgb(DeviationColour(centre, full));
    if (colour[0] > 235 && colour[1] > 235 && colour[2] > 235) colour = {200, 200, 200};  // white on white
    Fill(x0 + b * bar, y0 + height - h, x0 + (b + 1) * bar - 1, y0 + height, colour, rgb);
  }
  Fill(x0, y0 + height, x0 + kBins * bar, y0 + height + 1, kInk, rgb);
  // The tolerance, dashed.
  const double tolerance = full / 3.0;
  for (const double at : {-tolerance, tolerance}) {
    const int x = x0 + static_cast<int>(std::lround((at + full) / (2.0 * full) * kBins * bar));
    for (int y = y0; y < y0 + height; y += 8) Fill(x, y, x + 1, y + 4, kInk, rgb);
  }
  const int label_y = y0 + height + 8;
  Text(Format("%.0f", -1000.0 * full), x0, label_y, 2, kInk, rgb);
  Text("0", x0 + kBins * bar / 2 - 6, label_y, 2, kInk, rgb);
  const std::string right = Format("+%.0f", 1000.0 * full);
  Text(right, x0 + kBins * bar - TextWidthPx(right, 2), label_y, 2, kInk, rgb);
  Text(Format("tolerance +-%.0f mm dashed", 1000.0 * tolerance), x0 + 140, label_y + 22, 1, kFaint, rgb);
  Text("beyond: " + std::to_string(below) + " below, " + std::to_string(above) + " above", x0 + 140, label_y + 34, 1,
       kFaint, rgb);
}

// The points seen from above: each pixel shows its highest point, coloured by its deviation.
void DrawTopView(const CompareReport& report, const CompareOptions& options, const std::vector<Eigen::Vector3d>& points,
                 const Eigen::Vector3d& up, double full, int x0, int y0, int size, Image<uint8_t>* rgb) {
  (void)options;
  Text("top view", x0, y0 - 24, 2, kInk, rgb);
  Fill(x0, y0, x0 + size, y0 + size, {245, 245, 245}, rgb);
  if (points.empty()) return;
  const Eigen::Vector3d any = std::abs(up.x()) < 0.9 ? Eigen::Vector3d::UnitX() : Eigen::Vector3d::UnitY();
  const Eigen::Vector3d right = up.cross(any).normalized(), down = up.cross(right);
  Eigen::AlignedBox2d box;
  for (const Eigen::Vector3d& p : points) box.extend(Eigen::Vector2d(right.dot(p), down.dot(p)));
  const double extent = std::max(box.sizes().maxCoeff(), 1e-9);
  const double pixels_per_unit = (size - 20) / extent;
  const Eigen::Vector2d centre = box.center();
  const auto to_pixel = [&](const Eigen::Vector3d& p) {
    return Eigen::Vector2i(x0 + size / 2 + static_cast<int>(std::floor((right.dot(p) - centre.x()) * pixels_per_unit)),
                           y0 + size / 2 + static_cast<int>(std::floor((down.dot(p) - centre.y()) * pixels_per_unit)));
  };
  std::vector<double> height(static_cast<size_t>(size) * static_cast<size_t>(size), -INFINITY);
  for (size_t i = 0; i < points.size(); ++i) {
    const Eigen::Vector2i pixel = to_pixel(points[i]);
    const int u = pixel.x() - x0, v = pixel.y() - y0;
    if (u < 0 || v < 0 || u >= size || v >= size) continue;
    double& top = height[static_cast<size_t>(v) * static_cast<size_t>(size) + static_cast<size_t>(u)];
    const double h = up.dot(points[i]);
    if (h <= top) continue;
    top = h;
    const Colour colour = report.deviation.element_of_point[i] < 0
                              ? Colour{170, 170, 170}
                              : Rgb(DeviationColour(report.deviation.signed_distance_m[i], full));
    for (int c = 0; c < 3; ++c) rgb->row(pixel.y())[3 * pixel.x() + c] = colour[static_cast<size_t>(c)];
  }
  // Each element's name at its points' centre.
  const size_t num_elements = report.deviation.elements.size();
  std::vector<Eigen::Vector3d> sums(num_elements, Eigen::Vector3d::Zero());
  std::vector<int> counts(num_elements, 0);
  for (size_t i = 0; i < points.size(); ++i) {
    const int e = report.deviation.element_of_point[i];
    if (e < 0) continue;
    sums[static_cast<size_t>(e)] += points[i];
    ++counts[static_cast<size_t>(e)];
  }
  for (size_t e = 0; e < num_elements; ++e) {
    if (counts[e] == 0) continue;
    const Eigen::Vector2i at = to_pixel(sums[e] / counts[e]);
    const std::string name = report.deviation.elements[e].name;
    const int w = TextWidthPx(Lower(name), 1);
    Fill(at.x() - w / 2 - 2, at.y() - 2, at.x() + w / 2 + 3, at.y() + kGlyphHeight + 2, {255, 255, 255}, rgb);
    Text(name, at.x() - w / 2, at.y(), 1, kInk, rgb);
  }
  // A scale bar of a round length near a fifth of the view.
  const double metres = extent / 5.0;
  const double round = std::pow(10.0, std::floor(std::log10(metres)));
  const double bar_m = metres / round >= 5 ? 5 * round : metres / round >= 2 ? 2 * round : round;
  const int bar_px = static_cast<int>(std::lround(bar_m * pixels_per_unit));
  Fill(x0 + 10, y0 + size - 14, x0 + 10 + bar_px, y0 + size - 11, kInk, rgb);
  Text(bar_m >= 1.0 ? Format("%.0f m", bar_m) : Format("%.0f mm", 1000.0 * bar_m), x0 + 14 + bar_px, y0 + size - 18,
       1, kInk, rgb);
}

void DrawLegend(double full, int x0, int y0, int width, Image<uint8_t>* rgb) {
  for (int x = 0; x < width; ++x) {
    const double d = -full + 2.0 * full * (x + 0.5) / width;
    Fill(x0 + x, y0, x0 + x + 1, y0 + 14, Rgb(DeviationColour(d, full)), rgb);
  }
  Fill(x0, y0 + 14, x0 + width, y0 + 15, kFaint, rgb);
  Text(Format("%.0f mm inside", -1000.0 * full), x0, y0 + 20, 1, kInk, rgb);
  Text("on the design", x0 + width / 2 - TextWidthPx("on the design", 1) / 2, y0 + 20, 1, kInk, rgb);
  const std::string outside = Format("+%.0f mm outside", 1000.0 * full);
  Text(outside, x0 + width - TextWidthPx(outside, 1), y0 + 20, 1, kInk, rgb);
  Text("grey: on no element", x0, y0 + 34, 1, kFaint, rgb);
}

void DrawTable(const CompareReport& report, int x0, int y0, Image<uint8_t>* rgb) {
  const int columns[] = {0, 330, 440, 540, 640, 740, 830};
  const char* headers[] = {"element", "points", "mean mm", "rms mm", "p95 mm", "within", "verdict"};
  for (size_t k = 0; k < 7; ++k) Text(headers[k], x0 + columns[k], y0, 2, kInk, rgb);
  Fill(x0, y0 + 20, kWidth - 20, y0 + 21, kInk, rgb);
  const int max_rows = (rgb->height() - 20 - (y0 + 28)) / kRow;
  const std::vector<ElementDeviation>& elements = report.deviation.elements;
  for (size_t r = 0; r < elements.size(); ++r) {
    const int y = y0 + 28 + static_cast<int>(r) * kRow;
    if (static_cast<int>(r) == max_rows - 1 && elements.size() > static_cast<size_t>(max_rows)) {
      Text("... and " + std::to_string(elements.size() - r) + " more in report.json", x0, y, 2, kFaint, rgb);
      break;
    }
    const ElementDeviation& e = elements[r];
    if (r % 2 == 1) Fill(x0, y - 3, kWidth - 20, y + kRow - 5, {246, 246, 246}, rgb);
    std::string name = e.name.size() > 26 ? e.name.substr(0, 25) + "." : e.name;
    Text(name, x0 + columns[0], y, 2, kInk, rgb);
    Text(std::to_string(e.points), x0 + columns[1], y, 2, kInk, rgb);
    if (e.points > 0) {
      Text(Format("%.1f", 1000.0 * e.mean_m), x0 + columns[2], y, 2, kInk, rgb);
      Text(Format("%.1f", 1000.0 * e.rms_m), x0 + columns[3], y, 2, kInk, rgb);
      Text(Format("%.1f", 1000.0 * e.p95_m), x0 + columns[4], y, 2, kInk, rgb);
      Text(Format("%.0f%%", 100.0 * e.within_tolerance), x0 + columns[5], y, 2, kInk, rgb);
    }
    std::string verdict = e.verdict;
    if (e.verdict == "deviates") {
      verdict += Format(": moved %.0f mm", 1000.0 * e.shift_m.norm()) + Format(", %.1f deg", e.turn_deg);
    }
    Text(verdict, x0 + columns[6], y, 2, VerdictColour(e.verdict), rgb);
  }
}

}  // namespace

std::array<uint8_t, 4> DeviationColour(double signed_m, double full) {
  const double t = std::clamp(signed_m / full, -1.0, 1.0);
  const auto fade = [](double x) { return static_cast<uint8_t>(std::lround(255.0 * (1.0 - x))); };
  if (t >= 0.0) return {255, fade(t), fade(t), 255};
  return {fade(-t), fade(-t), 255, 255};
}

NamedMesh DeviationLegendStrip(double full, double world_units_per_metre, const Eigen::Vector3d& start,
                               const Eigen::Vector3d& along, const Eigen::Vector3d& across) {
  constexpr int kSteps = 60;
  NamedMesh legend;
  char name[200];
  std::snprintf(name, sizeof(name),
                "legend: blue %.0f mm inside the design, white on it, red %.0f mm outside; grey on no element; the "
                "strip is %.3g m long",
                -1000.0 * full, 1000.0 * full, along.norm() / world_units_per_metre);
  legend.name = name;
  Mesh& strip = legend.mesh;
  for (int k = 0; k <= kSteps; ++k) {
    const double t = static_cast<double>(k) / kSteps;
    const std::array<uint8_t, 4> colour = DeviationColour(-full + 2.0 * full * t, full);
    for (const double side : {0.0, 1.0}) {
      strip.positions.push_back((start + t * along + side * across).cast<float>());
      strip.colors.push_back(colour);
    }
    if (k == 0) continue;
    const uint32_t b = static_cast<uint32_t>(2 * k);
    strip.triangles.push_back({b - 2, b, b + 1});
    strip.triangles.push_back({b - 2, b + 1, b - 1});
  }
  return legend;
}

Image<uint8_t> DrawCompareReport(const CompareReport& report, const CompareOptions& options,
                                 const std::vector<Eigen::Vector3d>& points, const Eigen::Vector3d& up) {
  const int rows = std::min(kMaxRows, static_cast<int>(report.deviation.elements.size()));
  const int height = kTableTop + 28 + rows * kRow + 20;
  Image<uint8_t> rgb(kWidth, height, 3);
  Fill(0, 0, kWidth, height, {255, 255, 255}, &rgb);
  const double full = 3.0 * options.deviation.tolerance;
  const std::string design = report.design_path.substr(report.design_path.find_last_of('/') + 1);
  Text("as built against " + design, 20, 16, 3, kInk, &rgb);
  const DesignRegistration& r = report.registration;
  std::string line = "units " + r.units + (report.units_assumed ? " (assumed)" : "") + ", control " +
                     std::to_string(report.control_tags) + " tags " + std::to_string(report.control_points) +
                     " points, rms " + Format("%.1f mm", 1000.0 * r.control_rms_m);
  line += r.refined ? ", icp rms " + Format("%.1f mm", 1000.0 * r.icp_rms_m) + ", overlap " +
                          Format("%.0f%%", 100.0 * r.overlap)
                    : (r.icp_rejected.empty() ? ", no icp" : ", icp refused");
  line += ", " + std::to_string(report.as_built_points) + " points";
  Text(line, 20, 48, 2, kInk, &rgb);
  DrawHistogram(report, full, 20, 110, 600, 330, &rgb);
  DrawTopView(report, options, points, up, full, 680, 110, 420, &rgb);
  DrawLegend(full, 680, 540, 420, &rgb);
  DrawTable(report, 20, kTableTop, &rgb);
  return rgb;
}

}  // namespace reconar
