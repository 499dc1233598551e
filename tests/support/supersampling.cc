#include "tests/support/supersampling.h"

#include <algorithm>

namespace reconar::testing {

Image<float> AverageSamples(const Image<float>& fine, int supersampling) {
  const int s = supersampling, channels = fine.channels();
  Image<float> out(fine.width() / s, fine.height() / s, channels);
  const float norm = 1.0f / static_cast<float>(s * s);
  for (int y = 0; y < out.height(); ++y) {
    float* row = out.row(y);
    for (int x = 0; x < out.width(); ++x) {
      for (int c = 0; c < channels; ++c) {
        float sum = 0.0f;
        for (int sy = 0; sy < s; ++sy) {
          const float* fine_row = fine.row(s * y + sy) + channels * s * x + c;
          for (int sx = 0; sx < s; ++sx) sum += fine_row[channels * sx];
        }
        row[channels * x + c] = sum * norm;
      }
    }
  }
  return out;
}

Image<uint8_t> ToBytes(const Image<float>& image) {
  Image<uint8_t> out(image.width(), image.height(), image.channels());
  const int samples = image.width() * image.channels();
  for (int y = 0; y < image.height(); ++y) {
    const float* in = image.row(y);
    uint8_t* row = out.row(y);
    for (int i = 0; i < samples; ++i) row[i] = static_cast<uint8_t>(std::clamp(in[i] + 0.5f, 0.0f, 255.0f));
  }
  return out;
}

}  // namespace reconar::testing
