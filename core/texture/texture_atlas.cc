#include "core/texture/texture_atlas.h"

#include <algorithm>
#include <cmath>
#include <functional>
#include <numeric>
#include <optional>
#include <unordered_map>

#include "core/base/image_sampling.h"
#include "core/base/thread_pool.h"

namespace reconar {
namespace {

constexpr int kMinAtlasSide = 64;
constexpr int kBisectionSteps = 24;
// A chart whose faces cover less than this of its box, and larger than kMinSplitSidePixels, is cut.
constexpr double kMinChartFill = 0.5;
constexpr double kMinSplitSidePixels = 96.0;
// A face no photo sees, on a mesh without colours.
constexpr std::array<uint8_t, 4> kNoPhotoColour = {128, 128, 128, 255};

int NextPowerOfTwo(int value) {
  int power = 1;
  while (power < value) power *= 2;
  return power;
}

// The rows [low, high] a triangle spans over the vertical slab [x0, x1]; false when it misses it.
bool TriangleRowsOverSlab(const std::array<Eigen::Vector2d, 3>& corner, double x0, double x1, double* low, double* high) {
  *low = INFINITY;
  *high = -INFINITY;
  for (size_t i = 0; i < 3; ++i) {
    const Eigen::Vector2d& a = corner[i];
    const Eigen::Vector2d& b = corner[(i + 1) % 3];
    if (a.x() >= x0 && a.x() <= x1) {
      *low = std::min(*low, a.y());
      *high = std::max(*high, a.y());
    }
    for (const double x : {x0, x1}) {  // where the edge crosses the slab's sides
      if ((a.x() - x) * (b.x() - x) < 0.0) {
        const double y = a.y() + (b.y() - a.y()) * (x - a.x()) / (b.x() - a.x());
        *low = std::min(*low, y);
        *high = std::max(*high, y);
      }
    }
  }
  return *low <= *high;
}

// The rows each column of the chart's rectangle may take: a texel is filled when its centre lies
// in a face, then the filled texels grow by padding + 1 rings (DilateChart); so per column, the
// rows of its faces over the column widened by those rings, widened by them again.
void ProfileChart(double scale, int padding, TextureChart* chart) {
  const size_t columns = static_cast<size_t>((chart->width + kChartColumnWidth - 1) / kChartColumnWidth);
  if (chart->patch < 0) {
    chart->profile.assign(columns, {0, chart->height});
    return;
  }
  chart->profile.assign(columns, {chart->height, 0});
  const int grow = padding + 1;
  std::array<Eigen::Vector2d, 3> corner;
  for (const std::array<uint32_t, 3>& triangle : chart->triangles) {
    double x_low = INFINITY, x_high = -INFINITY;
    for (size_t i = 0; i < 3; ++i) {
      corner[i] = (chart->pixels[triangle[i]].array() + 0.5 - chart->pixel_min.array()).matrix() * scale +
                  Eigen::Vector2d::Constant(padding);
      x_low = std::min(x_low, corner[i].x());
      x_high = std::max(x_high, corner[i].x());
    }
    const int first_column = std::max(0, static_cast<int>(std::floor(x_low)) - grow) / kChartColumnWidth;
    const int last_column = std::min(chart->width - 1, static_cast<int>(std::floor(x_high)) + grow) / kChartColumnWidth;
    for (int column = first_column; column <= last_column; ++column) {
      double low, high;
      const double x0 = column * kChartColumnWidth - grow, x1 = (column + 1) * kChartColumnWidth + grow;
      if (!TriangleRowsOverSlab(corner, x0, x1, &low, &high)) continue;
      std::array<int, 2>& rows = chart->profile[static_cast<size_t>(column)];
      rows[0] = std::min(rows[0], std::max(0, static_cast<int>(std::floor(low)) - grow));
      rows[1] = std::max(rows[1], std::min(chart->height, static_cast<int>(std::floor(high)) + grow + 1));
    }
  }
}

void SizeCharts(double scale, int padding, std::vector<TextureChart>* charts) {
  for (TextureChart& chart : *charts) {
    if (chart.patch < 0) {
      chart.width = chart.height = 2 * padding + 2;
    } else {
      const Eigen::Vector2d extent = (chart.pixel_max - chart.pixel_min) * scale;
      chart.width = static_cast<int>(std::ceil(extent.x())) + 2 * padding + 1;
      chart.height = static_cast<int>(std::ceil(extent.y())) + 2 * padding + 1;
    }
    ProfileChart(scale, padding, &chart);
  }
}

// Texels the charts' profiles take.
double ProfileArea(const std::vector<TextureChart>& charts) {
  double area = 0.0;
  for (const TextureChart& chart : charts) {
    for (const std::array<int, 2>& rows : chart.profile) area += kChartColumnWidth * std::max(0, rows[1] - rows[0]);
  }
  return area;
}

// Skyline packing by profile into pages `width` wide and at most `max_height` high: the skyline
// is a height per column of kChartColumnWidth texels; each chart, in `order`, rests on it by its
// lower profile where its upper profile's top is lowest (leftmost among equals), on the first page
// where its rectangle fits; a new page when none holds it. Its upper profile becomes the skyline
// under it. The height each page's rectangles reach, or nothing when a chart is wider than `width`
// or higher than `max_height`.
std::optional<std::vector<int>> PackSkyline(int width, int max_height, const std::vector<size_t>& order,
                                            std::vector<TextureChart>* charts) {
  const size_t columns = static_cast<size_t>(width / kChartColumnWidth);
  std::vector<std::vector<int>> skylines;
  std::vector<int> used;
  for (const size_t index : order) {
    TextureChart& chart = (*charts)[index];
    if (chart.width > width || chart.height > max_height) return std::nullopt;
    int profile_end = 0;  // the lowest row under the chart's profile, from its rectangle's top
    for (const std::array<int, 2>& rows : chart.profile) profile_end = std::max(profile_end, rows[1]);
    int best_top = INT32_MAX, best_column = -1, best_y = 0;
    size_t page = 0;
    for (; page < skylines.size(); ++page) {
      const std::vector<int>& skyline = skylines[page];
      for (size_t x0 = 0; static_cast<int>(x0) * kChartColumnWidth + chart.width <= width; ++x0) {
        int y = 0;
        for (size_t c = 0; c < chart.profile.size(); ++c) {
          const std::array<int, 2>& rows = chart.profile[c];
          if (rows[1] > rows[0]) y = std::max(y, skyline[x0 + c] - rows[0]);
        }
        if (y + profile_end < best_top && y + chart.height <= max_height) {
          best_top = y + profile_end;
          best_column = static_cast<int>(x0);
          best_y = y;
        }
      }
      if (best_column >= 0) break;
    }
    if (page == skylines.size()) {
      skylines.emplace_back(columns, 0);
      used.push_back(0);
      best_column = 0;
      best_y = 0;
    }
    std::vector<int>& skyline = skylines[page];
    chart.page = static_cast<int>(page);
    chart.x = best_column * kChartColumnWidth;
    chart.y = best_y;
    used[page] = std::max(used[page], best_y + chart.height);
    for (size_t c = 0; c < chart.profile.size(); ++c) {
      const std::array<int, 2>& rows = chart.profile[c];
      if (rows[1] > rows[0]) skyline[static_cast<size_t>(best_column) + c] = best_y + rows[1];
    }
  }
  return used;
}

// Tallest first; ties by width, then index, so that the packing is deterministic.
std::vector<size_t> PackingOrder(const std::vector<TextureChart>& charts) {
  std::vector<size_t> order(charts.size());
  std::iota(order.begin(), order.end(), 0);
  std::sort(order.begin(), order.end(), [&](size_t a, size_t b) {
    if (charts[a].height != charts[b].height) return charts[a].height > charts[b].height;
    if (charts[a].width != charts[b].width) return charts[a].width > charts[b].width;
    return a < b;
  });
  return order;
}

// Fills one face's texels; marks them covered.
void FillTriangle(const Mesh& mesh, const AtlasLayout& layout, const TextureChart& chart,
                  const std::array<uint32_t, 3>& local, const PhotoProjector& projector, const Image<uint8_t>& photo,
                  const Eigen::Vector3f& gain, const PatchColourCorrection& correction, Image<uint8_t>* atlas, std::vector<uint8_t>* covered) {
  std::array<Eigen::Vector2d, 3> texel;
  std::array<Eigen::Vector3d, 3> corner;
  std::array<Eigen::Vector3f, 3> offset;
  for (size_t k = 0; k < 3; ++k) {
    texel[k] = layout.Texel(chart, local[k]);
    const uint32_t vertex = chart.vertices[local[k]];
    corner[k] = mesh.positions[vertex].cast<double>();
    offset[k] = correction.At(chart.patch, vertex);
  }
  const double area = (texel[1].x() - texel[0].x()) * (texel[2].y() - texel[0].y()) -
                      (texel[1].y() - texel[0].y()) * (texel[2].x() - texel[0].x());
  if (!(std::abs(area) > 1e-12)) return;
  const int x0 = std::max(chart.x, static_cast<int>(std::floor(std::min({texel[0].x(), texel[1].x(), texel[2].x()}))));
  const int x1 = std::min(chart.x + chart.width - 1,
                          static_cast<int>(std::floor(std::max({texel[0].x(), texel[1].x(), texel[2].x()}))));
  const int y0 = std::max(chart.y, static_cast<int>(std::floor(std::min({texel[0].y(), texel[1].y(), texel[2].y()}))));
  const int y1 = std::min(chart.y + chart.height - 1,
                          static_cast<int>(std::floor(std::max({texel[0].y(), texel[1].y(), texel[2].y()}))));
  const double inverse_area = 1.0 / area;
  constexpr double kInside = -1e-9;
  for (int y = y0; y <= y1; ++y) {
    const double qy = y + 0.5;
    for (int x = x0; x <= x1; ++x) {
      const double qx = x + 0.5;
      const double w0 = ((texel[1].x() - qx) * (texel[2].y() - qy) - (texel[1].y() - qy) * (texel[2].x() - qx)) *
                        inverse_area;
      const double w1 = ((texel[2].x() - qx) * (texel[0].y() - qy) - (texel[2].y() - qy) * (texel[0].x() - qx)) *
                        inverse_area;
      const double w2 = 1.0 - w0 - w1;
      if (w0 < kInside || w1 < kInside || w2 < kInside) continue;
      const Eigen::Vector3d point = w0 * corner[0] + w1 * corner[1] + w2 * corner[2];
      Eigen::Vector2d pixel;
      double depth;
      float rgb[3];
      if (!projector.Project(point, &pixel, &depth) || !SampleBilinear(photo, pixel.x(), pixel.y(), rgb)) continue;
      const Eigen::Vector3f shift = static_cast<float>(w0) * offset[0] + static_cast<float>(w1) * offset[1] +
                                    static_cast<float>(w2) * offset[2];
      uint8_t* out = atlas->row(y) + 3 * x;
      for (int c = 0; c < 3; ++c) {
        out[c] = static_cast<uint8_t>(std::clamp(std::lround(rgb[c] * gain[c] + shift[c]), 0L, 255L));
      }
      (*covered)[static_cast<size_t>(y) * atlas->width() + x] = 1;
    }
  }
}

// Grows the chart's covered texels into the rest of its profile, `rings` texels far: each pass
// gives an uncovered texel the mean of its covered 8-neighbours. It reads and writes only texels
// of its own profile, which no other chart's overlaps: charts are grown in parallel.
void DilateChart(const TextureChart& chart, int rings, Image<uint8_t>* atlas, std::vector<uint8_t>* covered) {
  const int width = atlas->width();
  std::vector<std::pair<int, std::array<uint8_t, 3>>> grown;
  for (int ring = 0; ring < rings; ++ring) {
    grown.clear();
    for (int y = chart.y; y < chart.y + chart.height; ++y) {
      for (int x = chart.x; x < chart.x + chart.width; ++x) {
        if (!chart.Owns(x, y) || (*covered)[static_cast<size_t>(y) * width + x]) continue;
        int sum[3] = {0, 0, 0}, count = 0;
        for (int dy = -1; dy <= 1; ++dy) {
          for (int dx = -1; dx <= 1; ++dx) {
            const int nx = x + dx, ny = y + dy;
            if (!chart.Owns(nx, ny) || !(*covered)[static_cast<size_t>(ny) * width + nx]) continue;
            const uint8_t* in = atlas->row(ny) + 3 * nx;
            for (int c = 0; c < 3; ++c) sum[c] += in[c];
            ++count;
          }
        }
        if (count == 0) continue;
        std::array<uint8_t, 3> mean;
        for (int c = 0; c < 3; ++c) mean[static_cast<size_t>(c)] = static_cast<uint8_t>((sum[c] + count / 2) / count);
        grown.emplace_back(y * width + x, mean);
      }
    }
    if (grown.empty()) return;
    for (const auto& [index, colour] : grown) {
      uint8_t* out = atlas->data() + 3 * static_cast<size_t>(index);
      for (int c = 0; c < 3; ++c) out[c] = colour[static_cast<size_t>(c)];
      (*covered)[static_cast<size_t>(index)] = 2;
    }
  }
}

}  // namespace

bool TextureChart::Owns(int page_x, int page_y) const {
  const int local_x = page_x - x, local_y = page_y - y;
  if (local_x < 0 || local_x >= width) return false;
  const std::array<int, 2>& rows = profile[static_cast<size_t>(local_x / kChartColumnWidth)];
  return local_y >= rows[0] && local_y < rows[1];
}

Eigen::Vector2d AtlasLayout::Texel(const TextureChart& chart, size_t local_vertex) const {
  if (chart.patch < 0) return Eigen::Vector2d(chart.x + 0.5 * chart.width, chart.y + 0.5 * chart.height);
  return (chart.pixels[local_vertex].array() + 0.5 - chart.pixel_min.array()).matrix() * scale +
         Eigen::Vector2d(chart.x + padding, chart.y + padding);
}

std::vector<TextureChart> MakeCharts(const Mesh& mesh, const TexturePatches& patches,
                                     const std::vector<PhotoProjector>& projectors) {
  std::vector<TextureChart> charts;
  std::unordered_map<uint32_t, uint32_t> local_of;
  std::vector<Eigen::Vector2d> pixel_of_vertex(mesh.positions.size());  // in the current patch's photo
  auto add_chart = [&](int patch, int photo, const std::vector<int>& faces) {
    TextureChart chart;
    chart.patch = patch;
    chart.photo = photo;
    local_of.clear();
    for (const int f : faces) {
      std::array<uint32_t, 3> local;
      for (size_t k = 0; k < 3; ++k) {
        const uint32_t vertex = mesh.triangles[static_cast<size_t>(f)][k];
        const auto inserted = local_of.emplace(vertex, static_cast<uint32_t>(chart.vertices.size()));
        if (inserted.second) chart.vertices.push_back(vertex);
        local[k] = inserted.first->second;
      }
      chart.triangles.push_back(local);
      chart.faces.push_back(f);
    }
    if (photo >= 0) {
      chart.pixels.resize(chart.vertices.size());
      chart.pixel_min = Eigen::Vector2d::Constant(INFINITY);
      chart.pixel_max = Eigen::Vector2d::Constant(-INFINITY);
      for (size_t k = 0; k < chart.vertices.size(); ++k) {
        chart.pixels[k] = pixel_of_vertex[chart.vertices[k]];
        chart.pixel_min = chart.pixel_min.cwiseMin(chart.pixels[k] + Eigen::Vector2d::Constant(0.5));
        chart.pixel_max = chart.pixel_max.cwiseMax(chart.pixels[k] + Eigen::Vector2d::Constant(0.5));
      }
    }
    charts.push_back(std::move(chart));
  };
  // A patch whose faces fill little of their bounding box (an L, a ring) is cut in two at the
  // median of its faces along the box's longer side, again while that helps.
  std::vector<std::array<Eigen::Vector2d, 3>> face_pixels;
  std::function<void(int, int, std::vector<int>)> add_pieces = [&](int patch, int photo, std::vector<int> faces) {
    Eigen::Vector2d low = Eigen::Vector2d::Constant(INFINITY), high = Eigen::Vector2d::Constant(-INFINITY);
    double content = 0.0;
    face_pixels.resize(faces.size());
    for (size_t k = 0; k < faces.size(); ++k) {
      for (size_t i = 0; i < 3; ++i) {
        face_pixels[k][i] = pixel_of_vertex[mesh.triangles[static_cast<size_t>(faces[k])][i]];
        low = low.cwiseMin(face_pixels[k][i]);
        high = high.cwiseMax(face_pixels[k][i]);
      }
      const Eigen::Vector2d ab = face_pixels[k][1] - face_pixels[k][0], ac = face_pixels[k][2] - face_pixels[k][0];
      content += 0.5 * std::abs(ab.x() * ac.y() - ab.y() * ac.x());
    }
    const Eigen::Vector2d extent = high - low;
    if (faces.size() < 2 || extent.maxCoeff() < kMinSplitSidePixels ||
        content >= kMinChartFill * (extent.x() + 1.0) * (extent.y() + 1.0)) {
      add_chart(patch, photo, faces);
      return;
    }
    const int axis = extent.x() >= extent.y() ? 0 : 1;
    std::vector<std::pair<double, int>> keyed(faces.size());
    for (size_t k = 0; k < faces.size(); ++k) {
      keyed[k] = {face_pixels[k][0][axis] + face_pixels[k][1][axis] + face_pixels[k][2][axis], faces[k]};
    }
    const size_t half = keyed.size() / 2;
    std::nth_element(keyed.begin(), keyed.begin() + static_cast<ptrdiff_t>(half), keyed.end());
    std::vector<int> first, second;
    for (size_t k = 0; k < keyed.size(); ++k) (k < half ? first : second).push_back(keyed[k].second);
    std::sort(first.begin(), first.end());
    std::sort(second.begin(), second.end());
    add_pieces(patch, photo, std::move(first));
    add_pieces(patch, photo, std::move(second));
  };
  for (size_t p = 0; p < patches.photo.size(); ++p) {
    // Every vertex of a candidate face projected when the face was found.
    const PhotoProjector& projector = projectors[static_cast<size_t>(patches.photo[p])];
    for (const int f : patches.faces[p]) {
      for (const uint32_t v : mesh.triangles[static_cast<size_t>(f)]) {
        double depth;
        projector.Project(mesh.positions[v].cast<double>(), &pixel_of_vertex[v], &depth);
      }
    }
    add_pieces(static_cast<int>(p), patches.photo[p], patches.faces[p]);
  }
  std::vector<int> untextured;
  for (size_t f = 0; f < patches.patch_of_face.size(); ++f) {
    if (patches.patch_of_face[f] < 0) untextured.push_back(static_cast<int>(f));
  }
  if (!untextured.empty()) add_chart(-1, -1, untextured);
  return charts;
}

Result<AtlasLayout> PackCharts(std::vector<TextureChart> charts, int atlas_size, int padding, int max_pages) {
  AtlasLayout layout;
  layout.padding = padding;
  auto try_scale = [&](double scale, int width, int max_height) {
    SizeCharts(scale, padding, &charts);
    return PackSkyline(width, max_height, PackingOrder(charts), &charts);
  };
  // At full resolution, the narrowest power-of-two square-ish page that holds the charts.
  SizeCharts(1.0, padding, &charts);
  const double area = ProfileArea(charts);
  int width = std::min(atlas_size, NextPowerOfTwo(std::max(kMinAtlasSide, static_cast<int>(std::sqrt(area)))));
  double scale = 1.0;
  std::optional<std::vector<int>> heights;
  for (; width <= atlas_size; width *= 2) {
    heights = try_scale(1.0, width, width);
    if (heights && heights->size() == 1) break;
  }
  if (width > atlas_size) {
    // Full pages at full resolution, as many as max_pages; the largest scale that fits them else.
    width = atlas_size;
    heights = try_scale(1.0, width, atlas_size);
    if (!heights || heights->size() > static_cast<size_t>(max_pages)) {
      double low = 0.0, high = 1.0;
      for (int step = 0; step < kBisectionSteps; ++step) {
        const double middle = 0.5 * (low + high);
        const auto used = try_scale(middle, width, atlas_size);
        if (used && used->size() <= static_cast<size_t>(max_pages)) {
          low = middle;
        } else {
          high = middle;
        }
      }
      if (!(low > 0.0)) {
        return Status(StatusCode::kResourceExhausted,
                      "texture: " + std::to_string(charts.size()) + " charts do not fit in " +
                          std::to_string(max_pages) + " page(s) of " + std::to_string(atlas_size) + " x " +
                          std::to_string(atlas_size) + " texels with their padding");
      }
      scale = low;
      heights = try_scale(scale, width, atlas_size);
    }
  }
  for (const int height : *heights) layout.pages.push_back({width, std::max(kMinAtlasSide, NextPowerOfTwo(height))});
  if (layout.pages.empty()) layout.pages.push_back({kMinAtlasSide, kMinAtlasSide});
  layout.scale = scale;
  layout.charts = std::move(charts);
  return layout;
}

Result<AtlasFill> FillAtlas(const Mesh& mesh, const AtlasLayout& layout, const std::vector<PhotoProjector>& projectors,
                            const std::vector<Eigen::Vector3f>& gains, const PatchColourCorrection& correction,
                            const PhotoAccess& access, int num_threads) {
  AtlasFill fill;
  std::vector<std::vector<uint8_t>> covered;
  for (const AtlasPage& page : layout.pages) {
    fill.pages.emplace_back(page.width, page.height, 3);
    covered.emplace_back(static_cast<size_t>(page.width) * page.height, 0);
  }
  std::vector<std::vector<size_t>> charts_of_photo(projectors.size());
  for (size_t k = 0; k < layout.charts.size(); ++k) {
    const TextureChart& chart = layout.charts[k];
    if (chart.photo >= 0) {
      charts_of_photo[static_cast<size_t>(chart.photo)].push_back(k);
      continue;
    }
    Image<uint8_t>& atlas = fill.pages[static_cast<size_t>(chart.page)];
    std::vector<uint8_t>& page_covered = covered[static_cast<size_t>(chart.page)];
    for (int y = chart.y; y < chart.y + chart.height; ++y) {
      std::fill(atlas.row(y) + 3 * chart.x, atlas.row(y) + 3 * (chart.x + chart.width), uint8_t{255});
      std::fill(page_covered.begin() + static_cast<ptrdiff_t>(y) * atlas.width() + chart.x,
                page_covered.begin() + static_cast<ptrdiff_t>(y) * atlas.width() + chart.x + chart.width, uint8_t{1});
    }
  }
  std::vector<Status> errors(projectors.size());
  ThreadPool pool(num_threads);
  pool.ParallelFor(0, projectors.size(), [&](size_t photo, int) {
    if (charts_of_photo[photo].empty()) return;
    Image<uint8_t> storage;
    const Image<uint8_t>* pixels = nullptr;
    errors[photo] = access(photo, &storage, &pixels);
    if (!errors[photo].ok()) return;
    for (const size_t k : charts_of_photo[photo]) {
      const TextureChart& chart = layout.charts[k];
      for (const auto& triangle : chart.triangles) {
        FillTriangle(mesh, layout, chart, triangle, projectors[photo], *pixels, gains[photo], correction,
                     &fill.pages[static_cast<size_t>(chart.page)], &covered[static_cast<size_t>(chart.page)]);
      }
    }
  });
  for (const Status& status : errors) RECONAR_RETURN_IF_ERROR(status);
  size_t covered_texels = 0, texels = 0;
  for (const std::vector<uint8_t>& page_covered : covered) {
    for (const uint8_t c : page_covered) covered_texels += c != 0;
    texels += page_covered.size();
  }
  fill.covered_fraction = static_cast<double>(covered_texels) / static_cast<double>(texels);
  pool.ParallelFor(0, layout.charts.size(), [&](size_t k, int) {
    const TextureChart& chart = layout.charts[k];
    if (chart.photo >= 0) {
      const size_t page = static_cast<size_t>(chart.page);
      DilateChart(chart, layout.padding + 1, &fill.pages[page], &covered[page]);
    }
  });
  return fill;
}

SeamSteps MeasureSeamSteps(const Mesh& mesh, const AtlasLayout& layout, const std::vector<Image<uint8_t>>& pages,
                           const std::vector<Eigen::Vector3f>& gains, const PatchColourCorrection& correction,
                           const std::vector<SeamEdge>& edges) {
  std::vector<std::pair<int, int>> place_of_face(mesh.triangles.size(), {-1, -1});  // chart, triangle
  for (size_t c = 0; c < layout.charts.size(); ++c) {
    for (size_t k = 0; k < layout.charts[c].faces.size(); ++k) {
      place_of_face[static_cast<size_t>(layout.charts[c].faces[k])] = {static_cast<int>(c), static_cast<int>(k)};
    }
  }
  // The corrected and uncorrected colour of `face` at barycentric `weights`.
  auto colour_at = [&](int face, const Eigen::Vector3d& weights, Eigen::Vector3f* corrected,
                       Eigen::Vector3f* uncorrected) {
    const auto [chart_index, k] = place_of_face[static_cast<size_t>(face)];
    if (chart_index < 0) return false;
    const TextureChart& chart = layout.charts[static_cast<size_t>(chart_index)];
    Eigen::Vector2d texel = Eigen::Vector2d::Zero();
    Eigen::Vector3f offset = Eigen::Vector3f::Zero();
    for (size_t i = 0; i < 3; ++i) {
      const uint32_t local = chart.triangles[static_cast<size_t>(k)][i];
      texel += weights[static_cast<int>(i)] * layout.Texel(chart, local);
      offset += static_cast<float>(weights[static_cast<int>(i)]) * correction.At(chart.patch, chart.vertices[local]);
    }
    float rgb[3];
    if (!SampleBilinear(pages[static_cast<size_t>(chart.page)], texel.x() - 0.5, texel.y() - 0.5, rgb)) return false;
    *corrected = Eigen::Vector3f(rgb[0], rgb[1], rgb[2]);
    *uncorrected = (*corrected - offset).cwiseQuotient(gains[static_cast<size_t>(chart.photo)]);
    return true;
  };
  // Barycentric weights of the edge (a, b)'s midpoint in `face`.
  auto weights_of = [&](int face, uint32_t a, uint32_t b) {
    const auto& t = mesh.triangles[static_cast<size_t>(face)];
    Eigen::Vector3d weights = Eigen::Vector3d::Zero();
    for (int i = 0; i < 3; ++i) {
      if (t[static_cast<size_t>(i)] == a || t[static_cast<size_t>(i)] == b) weights[i] = 0.5;
    }
    return weights;
  };
  SeamSteps steps;
  for (const SeamEdge& edge : edges) {
    Eigen::Vector3f after_a, before_a, after_b, before_b;
    if (!colour_at(edge.face_a, weights_of(edge.face_a, edge.a, edge.b), &after_a, &before_a) ||
        !colour_at(edge.face_b, weights_of(edge.face_b, edge.a, edge.b), &after_b, &before_b)) {
      continue;
    }
    steps.after += (after_a - after_b).cwiseAbs().mean();
    steps.before += (before_a - before_b).cwiseAbs().mean();
    ++steps.edges;
  }
  if (steps.edges > 0) {
    steps.after /= static_cast<double>(steps.edges);
    steps.before /= static_cast<double>(steps.edges);
  }
  return steps;
}

Mesh TexturedChartsMesh(const Mesh& mesh, const AtlasLayout& layout, std::vector<size_t>* page_first_triangle) {
  Mesh out;
  const bool untextured =
      std::any_of(layout.charts.begin(), layout.charts.end(), [](const TextureChart& c) { return c.patch < 0; });
  page_first_triangle->clear();
  for (size_t page = 0; page < layout.pages.size(); ++page) {
    page_first_triangle->push_back(out.triangles.size());
    const Eigen::Vector2d size(layout.pages[page].width, layout.pages[page].height);
    for (const TextureChart& chart : layout.charts) {
      if (chart.page != static_cast<int>(page)) continue;
      const uint32_t first = static_cast<uint32_t>(out.positions.size());
      for (size_t k = 0; k < chart.vertices.size(); ++k) {
        const uint32_t vertex = chart.vertices[k];
        out.positions.push_back(mesh.positions[vertex]);
        if (!mesh.normals.empty()) out.normals.push_back(mesh.normals[vertex]);
        out.texcoords.push_back(layout.Texel(chart, k).cwiseQuotient(size).cast<float>());
        if (untextured) {
          if (chart.patch >= 0) {
            out.colors.push_back({255, 255, 255, 255});
          } else {
            out.colors.push_back(mesh.colors.empty() ? kNoPhotoColour : mesh.colors[vertex]);
          }
        }
      }
      for (const auto& t : chart.triangles) out.triangles.push_back({first + t[0], first + t[1], first + t[2]});
    }
  }
  return out;
}

}  // namespace reconar
