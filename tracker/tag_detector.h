#pragma once
// TagDetector: AprilTag detection (libapriltag 3.3, Olson 2011 / Wang & Olson 2016) over an
// ImageView<const uint8_t> the caller owns. The view is wrapped in an image_u8_t on the stack
// (width, height, stride, buf): nothing is copied, and libapriltag only reads the pixels.
//
// Pixel convention of every corner, centre and homography reported here: the program's one
// convention (CameraIntrinsics, RadialCamera): the CENTRE of the top-left pixel is (0, 0), i.e.
// pixel (i, j) covers [i - 0.5, i + 0.5] x [j - 0.5, j + 0.5]. libapriltag itself puts that centre
// at (0.5, 0.5); DetectView is the one place that reads its detections and subtracts 0.5 there, so
// no other code converts. Checked in tests/tracker/tag_detector_test.cc on tags rendered with
// exact area coverage: whole frame and region, full-resolution and decimated quad search.
//
// Corner order (libapriltag's): p[0..3] wrap counter-clockwise in the image around the tag, and
// are the bottom-left, bottom-right, top-right, top-left corners of the upright tag, i.e. the tag
// frame points (-s/2,-s/2,0), (s/2,-s/2,0), (s/2,s/2,0), (-s/2,s/2,0) (tag frame: origin at the
// centre, x right, y up, z out of the printed tag toward the viewer).
//
// Memory: the detector, its family and its decode table are allocated once at construction
// (Create). Each Detect call writes into a TagDetectionList whose capacity the caller fixed; our
// code allocates nothing per call. libapriltag itself malloc()s and free()s its working images,
// union-find, clusters and the detection array inside every apriltag_detector_detect call (C
// malloc, not operator new); that is libapriltag's design and is not hidden here.
#include <memory>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "core/base/image.h"
#include "core/base/status.h"

namespace reconar {

// The families libapriltag 3.3 ships that we expose, by their libapriltag names.
enum class TagFamily { kTag36h11, kTag25h9, kTag16h5, kTagStandard41h12, kTagCircle21h7 };

const char* TagFamilyName(TagFamily family);  // "tag36h11", ...
// InvalidArgument listing the known names.
Result<TagFamily> ParseTagFamily(const std::string& name);

// A tag's printable bitmap (libapriltag's apriltag_to_image): one pixel per module, the white
// outer border included; the black square spans the central width_at_border modules. For tag
// sheets and synthetic test frames.
struct TagBitmap {
  Image<uint8_t> pixels;  // total_width x total_width, 0 = black, 255 = white
  int width_at_border = 0;
};
// InvalidArgument when id is not a code of the family.
Result<TagBitmap> RenderTagBitmap(TagFamily family, int id);

struct TagDetectorOptions {
  TagFamily family = TagFamily::kTag36h11;
  // Quads are found on the image decimated by this factor (libapriltag quad_decimate, >= 1);
  // decoding and edge refinement use full resolution. 2 is libapriltag's default.
  float quad_decimate = 2.0f;
  // Gaussian blur sigma (pixels) of the image used for quad finding; 0 = none (libapriltag default).
  float quad_sigma = 0.0f;
  // Snap quad edges to strong gradients at full resolution (libapriltag default on).
  bool refine_edges = true;
  double decode_sharpening = 0.25;
  int threads = 1;
  // Bit errors corrected when decoding (libapriltag bits_corrected, 0..3). 1 rather than
  // libapriltag's 2: tag36h11 codes are at least 11 bits apart, so an accepted decode with 1 error
  // still lies 10 bits from every other code, and the chance that a random non-tag quad decodes
  // grows with the number of code words within the radius (1 + 36 vs 1 + 36 + 630 per tag for
  // radius 1 vs 2, so about 18x fewer random accepts). The decode table shrinks by the same factor
  // (about 22 k instead of 390 k entries for tag36h11). Measured on the real datasets
  // (tests/tracker, e2e) with 1: no instance lost against 2, no false id.
  int max_hamming = 1;

  // InvalidArgument naming the first offending field.
  Status Check() const;
};

struct TagDetection {
  int id = -1;
  int hamming = 0;               // bit errors corrected
  float decision_margin = 0.0f;  // libapriltag's mean |bit intensity - threshold|
  Eigen::Vector2d corners[4];    // libapriltag order, our pixel convention (see the header comment)
  Eigen::Vector2d center = Eigen::Vector2d::Zero();
  // Maps the ideal tag square (-1,-1)..(1,1) (libapriltag's tag coordinates: x right, y DOWN on
  // the upright tag) to full-frame pixels (our convention): pixel ~ H (x, y, 1).
  Eigen::Matrix3d homography = Eigen::Matrix3d::Identity();
};

// A fixed-capacity list of detections, reserved once; Add beyond the capacity drops the
// detection and counts it (dropped()), never reallocates.
class TagDetectionList {
 public:
  TagDetectionList() = default;
  explicit TagDetectionList(int capacity) { items_.reserve(static_cast<size_t>(capacity)); }

  int capacity() const { return static_cast<int>(items_.capacity()); }
  int size() const { return static_cast<int>(items_.size()); }
  bool empty() const { return items_.empty(); }
  int dropped() const { return dropped_; }
  const TagDetection& operator[](int i) const { return items_[static_cast<size_t>(i)]; }
  TagDetection& operator[](int i) { return items_[static_cast<size_t>(i)]; }
  const TagDetection* begin() const { return items_.data(); }
  const TagDetection* end() const { return items_.data() + items_.size(); }

  void Clear() {
    items_.clear();
    dropped_ = 0;
  }
  // False (and counted as dropped) when full.
  bool Add(const TagDetection& detection) {
    if (items_.size() >= items_.capacity()) {
      ++dropped_;
      return false;
    }
    items_.push_back(detection);
    return true;
  }

 private:
  std::vector<TagDetection> items_;
  int dropped_ = 0;
};

// One detector per thread (libapriltag's detector state is reused across calls); `threads` > 1
// makes libapriltag itself use a worker pool inside each call.
class TagDetector {
 public:
  // InvalidArgument for bad options; Internal when libapriltag fails to create the detector.
  static Result<std::unique_ptr<TagDetector>> Create(const TagDetectorOptions& options);
  ~TagDetector();
  TagDetector(const TagDetector&) = delete;
  TagDetector& operator=(const TagDetector&) = delete;

  const TagDetectorOptions& options() const { return options_; }
  // Changes quad_decimate for the following calls (>= 1; other values are clamped to 1). The
  // tracker picks it per region from the tag's predicted size.
  void SetQuadDecimate(float quad_decimate);

  // Detects tags in the whole view; *detections is cleared first. InvalidArgument for an empty
  // view, a stride < width or a size above libapriltag's int32 image limits.
  Status Detect(ImageView<const uint8_t> image, TagDetectionList* detections);

  // Detects tags in the sub-rectangle [x0, x0 + width) x [y0, y0 + height) of `image` only (the
  // rectangle is clipped to the image; an empty intersection gives no detections). Corners,
  // centres and homographies are in full-frame pixels. The pixel data are not copied.
  Status DetectInRegion(ImageView<const uint8_t> image, int x0, int y0, int width, int height,
                        TagDetectionList* detections);

 private:
  struct Impl;
  explicit TagDetector(const TagDetectorOptions& options);
  Status DetectView(ImageView<const uint8_t> view, int x_offset, int y_offset, TagDetectionList* detections);

  TagDetectorOptions options_;
  std::unique_ptr<Impl> impl_;
};

}  // namespace reconar
