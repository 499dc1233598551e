#include "core/io/orientation.h"

#include <cstring>

namespace reconar {

Image<uint8_t> ApplyOrientation(const Image<uint8_t>& image, int orientation) {
  if (orientation < 2 || orientation > 8) return image;
  const int w = image.width();
  const int h = image.height();
  const int c = image.channels();
  const bool swap = OrientationSwapsAxes(orientation);
  Image<uint8_t> out(swap ? h : w, swap ? w : h, c);
  const int out_w = out.width();
  const int out_h = out.height();
  for (int v = 0; v < out_h; ++v) {
    uint8_t* dst = out.row(v);
    for (int u = 0; u < out_w; ++u) {
      // Source pixel (x, y) of output pixel (u, v).
      int x = u;
      int y = v;
      switch (orientation) {
        case 2: x = w - 1 - u; y = v; break;
        case 3: x = w - 1 - u; y = h - 1 - v; break;
        case 4: x = u; y = h - 1 - v; break;
        case 5: x = v; y = u; break;
        case 6: x = v; y = h - 1 - u; break;
        case 7: x = w - 1 - v; y = h - 1 - u; break;
        case 8: x = w - 1 - v; y = u; break;
        default: break;
      }
      std::memcpy(dst + static_cast<size_t>(u) * c, image.row(y) + static_cast<size_t>(x) * c, c);
    }
  }
  return out;
}

}  // namespace reconar
