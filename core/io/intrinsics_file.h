#pragma once
// The intrinsics text file: written by `reconar calibrate`, read by every command that takes
// `--intrinsics FILE` (track, view, capture, localize). '#' comment lines, then one line
// "fx fy cx cy k1 k2 width height" (pixels in the CameraIntrinsics convention,
// core/math/camera_intrinsics.h; width and height integers, 0 when unknown).
#include <string>

#include "core/base/status.h"
#include "core/math/camera_intrinsics.h"

namespace reconar {

// Written atomically with shortest round-trip doubles. InvalidArgument for non-finite values,
// fx, fy <= 0 or a negative size.
Status WriteIntrinsics(const std::string& path, const CameraIntrinsics& intrinsics);

// NotFound / IoError for the file, CorruptData (naming the file and line) when the data line is
// missing, malformed, has extra fields, or gives fx, fy <= 0 or a negative size.
Result<CameraIntrinsics> ReadIntrinsics(const std::string& path);

}  // namespace reconar
