#pragma once
// What a hand-held camera does to a frame, put on frames a test chooses so that which frames
// suffer is known: horizontal motion blur and an exposure change. Interleaved channels are treated
// alike. Header-only test support.
#include <algorithm>
#include <cstdint>

#include "core/base/image.h"

namespace reconar::testing {

// Each sample the mean of `length` samples of its channel along the row.
inline Image<uint8_t> MotionBlurred(const Image<uint8_t>& frame, int length) {
  const int channels = frame.channels();
  Image<uint8_t> out(frame.width(), frame.height(), channels);
  for (int y = 0; y < frame.height(); ++y) {
    for (int x = 0; x < frame.width(); ++x) {
      for (int c = 0; c < channels; ++c) {
        int sum = 0;
        for (int k = 0; k < length; ++k)
          sum += frame.row(y)[std::clamp(x + k - length / 2, 0, frame.width() - 1) * channels + c];
        out.row(y)[x * channels + c] = static_cast<uint8_t>(sum / length);
      }
    }
  }
  return out;
}

// Every sample times `gain`, clipped to 255.
inline Image<uint8_t> ExposureScaled(const Image<uint8_t>& frame, double gain) {
  Image<uint8_t> out(frame.width(), frame.height(), frame.channels());
  const int samples = frame.width() * frame.channels();
  for (int y = 0; y < frame.height(); ++y)
    for (int x = 0; x < samples; ++x) out.row(y)[x] = static_cast<uint8_t>(std::min(255.0, frame.row(y)[x] * gain));
  return out;
}

}  // namespace reconar::testing
