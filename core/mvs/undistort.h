#pragma once
// Undistortion for dense reconstruction: a registered photo (Bundler radial camera, see
// core/sfm/reconstruction.h) becomes a DenseView (core/mvs/dense_view.h), a pinhole image at a
// resolution level L (0 full, 1 half, 2 quarter).
//
// 1. Area average down to level L: level pixel (i, j) is the mean of the 2^L x 2^L block of
//    full-resolution pixels [i 2^L, (i+1) 2^L) x [j 2^L, (j+1) 2^L); a partial block at the right
//    or bottom edge is dropped (width_L = width >> L). With pixel centres at integers this is
//    x_L = (x_0 + 0.5) / 2^L - 0.5, so f_L = f / 2^L and c_L = (c + 0.5) / 2^L - 0.5.
// 2. Resample through the radial model onto the pinhole camera fx = f_L, fy = aspect f_L, same
//    principal point c_L, same size: each output pixel is the bilinear sample at the distorted
//    position of its ray. Rays that land outside the photo are black.
#include "core/base/image.h"
#include "core/base/status.h"
#include "core/mvs/dense_view.h"
#include "core/sfm/reconstruction.h"

namespace reconar {

constexpr int kMaxDenseLevel = 2;

// The camera of `camera`'s images at level L (focal, principal point and size scaled as above).
SfmCamera CameraAtLevel(const SfmCamera& camera, int level);

// Mean of each 2^level x 2^level block (rounded to nearest); any channel count.
Image<uint8_t> AreaAverageDown(const Image<uint8_t>& image, int level);

// `rgb` is the decoded photo (3 channels, camera.width x camera.height). The result has name ""
// and image_id -1 for the caller to fill. InvalidArgument when the sizes disagree, the image is
// not RGB, the level is outside 0..kMaxDenseLevel or the camera has no positive focal.
Result<DenseView> UndistortView(const Image<uint8_t>& rgb, const SfmCamera& camera, const Rigid3& pose, int level);

}  // namespace reconar
