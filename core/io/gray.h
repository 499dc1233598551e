#pragma once
// Colour to luma with Rec.601 weights (0.299 R + 0.587 G + 0.114 B).
#include <cstdint>

#include "core/base/image.h"

namespace reconar {

// 1-channel float in [0, 1]. Input has 3 (RGB) or 4 (RGBA, alpha ignored) channels, or 1 (copied).
Image<float> ToGrayFloat(const Image<uint8_t>& rgb);

// 8-bit grey to float in [0, 1] (what SIFT takes) into `out`, of the same size; no allocation.
void Gray8ToFloat(ImageView<const uint8_t> gray, ImageView<float> out);

// 1-channel 8-bit, rounded to nearest. Same inputs as ToGrayFloat.
Image<uint8_t> ToGray8(const Image<uint8_t>& rgb);

}  // namespace reconar
