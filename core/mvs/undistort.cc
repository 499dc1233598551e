#include "core/mvs/undistort.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "core/base/image_sampling.h"
#include "core/io/gray.h"

namespace reconar {

SfmCamera CameraAtLevel(const SfmCamera& camera, int level) {
  const double scale = 1.0 / static_cast<double>(1 << level);
  SfmCamera scaled = camera;
  scaled.width = camera.width >> level;
  scaled.height = camera.height >> level;
  scaled.focal = camera.focal * scale;
  scaled.cx = (camera.cx + 0.5) * scale - 0.5;
  scaled.cy = (camera.cy + 0.5) * scale - 0.5;
  return scaled;
}

Image<uint8_t> AreaAverageDown(const Image<uint8_t>& image, int level) {
  if (level <= 0) return image;
  const int block = 1 << level;
  const int channels = image.channels();
  const int width = image.width() >> level, height = image.height() >> level;
  Image<uint8_t> out(width, height, channels);
  const int area = block * block;
  std::vector<int> sums(static_cast<size_t>(width) * channels);
  for (int y = 0; y < height; ++y) {
    std::fill(sums.begin(), sums.end(), 0);
    for (int dy = 0; dy < block; ++dy) {
      const uint8_t* in = image.row(y * block + dy);
      for (int x = 0; x < width; ++x) {
        int* sum = &sums[static_cast<size_t>(x) * channels];
        for (int dx = 0; dx < block; ++dx) {
          const uint8_t* pixel = in + static_cast<ptrdiff_t>(x * block + dx) * channels;
          for (int c = 0; c < channels; ++c) sum[c] += pixel[c];
        }
      }
    }
    uint8_t* row = out.row(y);
    for (size_t i = 0; i < sums.size(); ++i) row[i] = static_cast<uint8_t>((sums[i] + area / 2) / area);
  }
  return out;
}

Result<DenseView> UndistortView(const Image<uint8_t>& rgb, const SfmCamera& camera, const Rigid3& pose, int level) {
  if (level < 0 || level > kMaxDenseLevel) {
    return InvalidArgument("undistort: level must be 0.." + std::to_string(kMaxDenseLevel) + ", got " +
                           std::to_string(level));
  }
  if (rgb.channels() != 3) return InvalidArgument("undistort: expected an RGB image, got " +
                                                  std::to_string(rgb.channels()) + " channels");
  if (rgb.width() != camera.width || rgb.height() != camera.height) {
    return InvalidArgument("undistort: image is " + std::to_string(rgb.width()) + "x" + std::to_string(rgb.height()) +
                           " but its camera is " + std::to_string(camera.width) + "x" +
                           std::to_string(camera.height));
  }
  if (!(camera.focal > 0.0) || !(camera.aspect > 0.0)) {
    return InvalidArgument("undistort: camera focal and aspect must be positive");
  }
  const SfmCamera scaled = CameraAtLevel(camera, level);
  if (scaled.width < 1 || scaled.height < 1) return InvalidArgument("undistort: image too small for the level");
  const Image<uint8_t> source = AreaAverageDown(rgb, level);

  DenseView view;
  view.level = level;
  view.cam_from_world = pose;
  view.fx = scaled.focal;
  view.fy = scaled.aspect * scaled.focal;
  view.cx = scaled.cx;
  view.cy = scaled.cy;
  const int width = scaled.width, height = scaled.height;
  view.rgb = Image<uint8_t>(width, height, 3);
  const bool distorted = scaled.k1 != 0.0 || scaled.k2 != 0.0;
  for (int v = 0; v < height; ++v) {
    uint8_t* out = view.rgb.row(v);
    const double py = (v - view.cy) / view.fy;
    for (int u = 0; u < width; ++u, out += 3) {
      double x = u, y = v;
      if (distorted) {
        const Eigen::Vector2d pixel = scaled.Project(Eigen::Vector3d((u - view.cx) / view.fx, py, 1.0));
        x = pixel.x();
        y = pixel.y();
      }
      float sample[3];
      if (!SampleBilinear(source, x, y, sample)) {
        out[0] = out[1] = out[2] = 0;
        continue;
      }
      for (int c = 0; c < 3; ++c) out[c] = static_cast<uint8_t>(std::lround(sample[c]));
    }
  }
  view.gray = ToGray8(view.rgb);
  return view;
}

}  // namespace reconar
