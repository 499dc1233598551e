#pragma once
// SIFT keypoints and descriptors after Lowe, "Distinctive Image Features from Scale-Invariant
// Keypoints", IJCV 2004. Conventions: pixel (x, y) = column, row of the input image with (0, 0)
// at the centre of the top-left pixel; orientation in radians in [0, 2*pi), counter-clockwise in
// the image's y-down frame (atan2(dy, dx)); scale = sigma of the keypoint in input pixels.
//
// Memory: one Arena reserved at construction holds the working set of one octave at a time
// (four Gaussian levels; DoG rows are rolled, never stored as planes). An image whose working set
// does not fit is refused with kResourceExhausted before any work: the arena size is the bound.
#include <cstddef>
#include <cstdint>
#include <vector>

#include "core/base/arena.h"
#include "core/base/image.h"
#include "core/base/status.h"

namespace reconar {

struct SiftOptions {
  int first_octave = -1;            // -1 doubles the image first (Lowe 2004, sec. 3.3), 0 starts at input size
  int levels_per_octave = 3;        // S: scales sampled per octave
  int max_octaves = 0;              // 0: as many as fit until the smaller side drops below 16 px
  double sigma = 1.6;               // blur of the first level of every octave
  double input_blur = 0.5;          // blur assumed already present in the input (camera)
  double contrast_threshold = 0.04; // on |D(x)| after interpolation, divided by levels_per_octave
  double edge_threshold = 10.0;     // r in tr(H)^2/det(H) < (r+1)^2/r
  int max_orientations = 4;         // peaks >= 0.8 of the highest each give a keypoint
  int max_features = 16384;         // keep the strongest |D| responses; 0 = unlimited
  size_t arena_bytes = 512u << 20;  // working-set bound; see RequiredArenaBytes()

  Status Check() const;
};

struct SiftKeypoint {
  float x = 0;
  float y = 0;
  float scale = 0;
  float orientation = 0;
  float response = 0;  // |D| at the interpolated extremum
  int octave = 0;
};

struct SiftFeatures {
  std::vector<SiftKeypoint> keypoints;
  std::vector<uint8_t> descriptors;  // keypoints.size() rows of 128 bytes
  const uint8_t* descriptor(size_t i) const { return descriptors.data() + 128 * i; }
};

struct SiftReport {
  double seconds_pyramid = 0;      // upsampling, Gaussian blurs, downsampling
  double seconds_detection = 0;    // DoG, extrema, sub-pixel refinement, contrast/edge tests
  double seconds_orientation = 0;
  double seconds_descriptor = 0;
  int num_octaves = 0;
  int num_candidates = 0;          // discrete DoG extrema
  int num_keypoints_before_cap = 0;
  bool truncated = false;          // max_features dropped some keypoints
  size_t arena_peak_bytes = 0;
  const char* kernels = "";
};

class SiftExtractor {
 public:
  // Reserves options.arena_bytes once; reuse one extractor for many images.
  explicit SiftExtractor(const SiftOptions& options);

  // `gray` holds intensities in [0, 1].
  Result<SiftFeatures> Extract(ImageView<const float> gray, SiftReport* report = nullptr);

  // Arena bytes needed for an image of this size.
  static size_t RequiredArenaBytes(int width, int height, const SiftOptions& options);

  const SiftOptions& options() const { return options_; }

 private:
  SiftOptions options_;
  Arena arena_;
};

}  // namespace reconar
