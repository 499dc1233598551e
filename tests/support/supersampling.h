#pragma once
// Supersampled rendering for the synthetic captures (corridor_walk.h, object_capture.h): a view is
// rendered at `supersampling` samples per pixel along each axis into a fine image, fine pixel
// (X, Y) = (supersampling * x + sx, supersampling * y + sy) holding sample (sx, sy) of pixel (x, y),
// then each pixel becomes the mean of its samples (a box filter, as a sensor integrates over its
// pixel). Pixel centres are at integer coordinates. Test support only.
#include <cstdint>

#include "core/base/image.h"

namespace reconar::testing {

// Where sample `sample` of pixel `pixel` lies along one axis: evenly spread over the pixel's square.
inline double SampleCoordinate(int pixel, int sample, int supersampling) {
  return pixel - 0.5 + (sample + 0.5) / supersampling;
}

// The fine image's position X along one axis, in the pixels of the image it is averaged into.
inline double FineSampleCoordinate(int fine, int supersampling) {
  return SampleCoordinate(fine / supersampling, fine % supersampling, supersampling);
}

// Each pixel the mean of its supersampling^2 samples in `fine` (any channel count; width and height
// multiples of supersampling).
Image<float> AverageSamples(const Image<float>& fine, int supersampling);

// Rounded to the nearest grey level and clipped to 0..255.
Image<uint8_t> ToBytes(const Image<float>& image);

}  // namespace reconar::testing
