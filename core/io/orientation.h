#pragma once
// EXIF orientation: how the stored pixels must be transformed to appear upright.
#include <cstdint>

#include "core/base/image.h"

namespace reconar {

// Returns the upright image for EXIF orientation 1..8 (any channel count):
//   1 as stored            2 mirrored left-right     3 rotated 180°        4 mirrored top-bottom
//   5 transposed           6 rotated 90° clockwise   7 transversed         8 rotated 90° counter-clockwise
// Orientations 5..8 swap width and height. Values outside 1..8 are treated as 1.
Image<uint8_t> ApplyOrientation(const Image<uint8_t>& image, int orientation);

// Whether the orientation swaps width and height (5..8).
inline bool OrientationSwapsAxes(int orientation) { return orientation >= 5 && orientation <= 8; }

}  // namespace reconar
