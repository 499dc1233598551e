#include "tracker/tag_detector.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>

#include <apriltag/apriltag.h>
#include <apriltag/tag16h5.h>
#include <apriltag/tag25h9.h>
#include <apriltag/tag36h11.h>
#include <apriltag/tagCircle21h7.h>
#include <apriltag/tagStandard41h12.h>

namespace reconar {
namespace {

struct FamilyEntry {
  TagFamily family;
  const char* name;
  apriltag_family_t* (*create)();
  void (*destroy)(apriltag_family_t*);
};

const FamilyEntry kFamilies[] = {
    {TagFamily::kTag36h11, "tag36h11", tag36h11_create, tag36h11_destroy},
    {TagFamily::kTag25h9, "tag25h9", tag25h9_create, tag25h9_destroy},
    {TagFamily::kTag16h5, "tag16h5", tag16h5_create, tag16h5_destroy},
    {TagFamily::kTagStandard41h12, "tagStandard41h12", tagStandard41h12_create, tagStandard41h12_destroy},
    {TagFamily::kTagCircle21h7, "tagCircle21h7", tagCircle21h7_create, tagCircle21h7_destroy},
};

const FamilyEntry& Entry(TagFamily family) {
  for (const FamilyEntry& entry : kFamilies) {
    if (entry.family == family) return entry;
  }
  return kFamilies[0];
}

}  // namespace

const char* TagFamilyName(TagFamily family) { return Entry(family).name; }

Result<TagFamily> ParseTagFamily(const std::string& name) {
  std::string known;
  for (const FamilyEntry& entry : kFamilies) {
    if (name == entry.name) return entry.family;
    known += known.empty() ? "" : ", ";
    known += entry.name;
  }
  return InvalidArgument("unknown tag family '" + name + "' (known: " + known + ")");
}

Result<TagBitmap> RenderTagBitmap(TagFamily family, int id) {
  const FamilyEntry& entry = Entry(family);
  apriltag_family_t* f = entry.create();
  if (f == nullptr) return Internal(std::string("libapriltag could not create family ") + entry.name);
  if (id < 0 || static_cast<uint32_t>(id) >= f->ncodes) {
    const uint32_t codes = f->ncodes;
    entry.destroy(f);
    return InvalidArgument(std::string(entry.name) + " has ids 0.." + std::to_string(codes - 1) + ", not " +
                           std::to_string(id));
  }
  image_u8_t* image = apriltag_to_image(f, static_cast<uint32_t>(id));
  TagBitmap bitmap;
  bitmap.width_at_border = static_cast<int>(f->width_at_border);
  entry.destroy(f);
  if (image == nullptr) return Internal(std::string("libapriltag could not render ") + entry.name);
  bitmap.pixels = Image<uint8_t>(image->width, image->height, 1);
  for (int y = 0; y < image->height; ++y) {
    std::copy(image->buf + y * image->stride, image->buf + y * image->stride + image->width, bitmap.pixels.row(y));
  }
  image_u8_destroy(image);
  return bitmap;
}

Status TagDetectorOptions::Check() const {
  if (!(quad_decimate >= 1.0f) || !std::isfinite(quad_decimate)) {
    return InvalidArgument("TagDetectorOptions.quad_decimate must be >= 1, got " + std::to_string(quad_decimate));
  }
  if (!(quad_sigma >= 0.0f) || !std::isfinite(quad_sigma)) {
    return InvalidArgument("TagDetectorOptions.quad_sigma must be >= 0, got " + std::to_string(quad_sigma));
  }
  if (!(decode_sharpening >= 0.0) || !std::isfinite(decode_sharpening)) {
    return InvalidArgument("TagDetectorOptions.decode_sharpening must be >= 0, got " +
                           std::to_string(decode_sharpening));
  }
  if (threads < 1) return InvalidArgument("TagDetectorOptions.threads must be >= 1, got " + std::to_string(threads));
  if (max_hamming < 0 || max_hamming > 3) {
    return InvalidArgument("TagDetectorOptions.max_hamming must be in 0..3, got " + std::to_string(max_hamming));
  }
  return Status::Ok();
}

struct TagDetector::Impl {
  apriltag_family_t* family = nullptr;
  void (*destroy_family)(apriltag_family_t*) = nullptr;
  apriltag_detector_t* detector = nullptr;

  ~Impl() {
    if (detector != nullptr) apriltag_detector_destroy(detector);
    if (family != nullptr) destroy_family(family);
  }
};

TagDetector::TagDetector(const TagDetectorOptions& options) : options_(options), impl_(std::make_unique<Impl>()) {}

TagDetector::~TagDetector() = default;

Result<std::unique_ptr<TagDetector>> TagDetector::Create(const TagDetectorOptions& options) {
  RECONAR_RETURN_IF_ERROR(options.Check());
  std::unique_ptr<TagDetector> detector(new TagDetector(options));
  Impl& impl = *detector->impl_;
  const FamilyEntry& entry = Entry(options.family);
  impl.destroy_family = entry.destroy;
  impl.family = entry.create();
  if (impl.family == nullptr) return Internal(std::string("libapriltag could not create family ") + entry.name);
  impl.detector = apriltag_detector_create();
  if (impl.detector == nullptr) return Internal("libapriltag could not create a detector");
  apriltag_detector_add_family_bits(impl.detector, impl.family, options.max_hamming);
  impl.detector->quad_decimate = options.quad_decimate;
  impl.detector->quad_sigma = options.quad_sigma;
  impl.detector->refine_edges = options.refine_edges;
  impl.detector->decode_sharpening = options.decode_sharpening;
  impl.detector->nthreads = options.threads;
  return detector;
}

Status TagDetector::Detect(ImageView<const uint8_t> image, TagDetectionList* detections) {
  return DetectView(image, 0, 0, detections);
}

void TagDetector::SetQuadDecimate(float quad_decimate) {
  options_.quad_decimate = std::isfinite(quad_decimate) ? std::max(1.0f, quad_decimate) : 1.0f;
  impl_->detector->quad_decimate = options_.quad_decimate;
}

Status TagDetector::DetectInRegion(ImageView<const uint8_t> image, int x0, int y0, int width, int height,
                                   TagDetectionList* detections) {
  const int x_begin = std::max(0, x0);
  const int y_begin = std::max(0, y0);
  const int x_end = std::min(image.width, x0 + std::max(0, width));
  const int y_end = std::min(image.height, y0 + std::max(0, height));
  if (x_end <= x_begin || y_end <= y_begin) {
    detections->Clear();
    return Status::Ok();
  }
  return DetectView(image.sub(x_begin, y_begin, x_end - x_begin, y_end - y_begin), x_begin, y_begin, detections);
}

Status TagDetector::DetectView(ImageView<const uint8_t> view, int x_offset, int y_offset,
                               TagDetectionList* detections) {
  detections->Clear();
  if (view.empty()) {
    return InvalidArgument("TagDetector: empty image (" + std::to_string(view.width) + "x" +
                           std::to_string(view.height) + ")");
  }
  if (view.stride < view.width || view.stride > std::numeric_limits<int32_t>::max()) {
    return InvalidArgument("TagDetector: image stride " + std::to_string(view.stride) + " is below its width " +
                           std::to_string(view.width) + " or above the int32 range");
  }
  // libapriltag reads but never writes the input image (it filters and decimates into copies);
  // image_u8_t has no const-pixel variant, hence the cast.
  image_u8_t wrapped = {view.width, view.height, static_cast<int32_t>(view.stride), const_cast<uint8_t*>(view.data)};
  zarray_t* found = apriltag_detector_detect(impl_->detector, &wrapped);
  if (found == nullptr) return Internal("libapriltag returned no detection array");
  const Eigen::Vector2d offset(x_offset, y_offset);
  // libapriltag's pixel (i, j) covers [i, i+1] x [j, j+1] of the view it was given (decimation is
  // undone inside libapriltag: corners and H are in that view's full-resolution pixels). The view
  // starts at (x_offset, y_offset) of the frame, and our convention puts pixel centres on
  // integers, hence + offset - 0.5 (subtracting 0.5 is exact for any coordinate in [0.25, 2^52)).
  const Eigen::Vector2d to_centre(0.5, 0.5);
  const int count = zarray_size(found);
  for (int i = 0; i < count; ++i) {
    apriltag_detection_t* det = nullptr;
    zarray_get(found, i, &det);
    TagDetection out;
    out.id = det->id;
    out.hamming = det->hamming;
    out.decision_margin = det->decision_margin;
    for (int k = 0; k < 4; ++k) out.corners[k] = (Eigen::Vector2d(det->p[k][0], det->p[k][1]) + offset) - to_centre;
    out.center = (Eigen::Vector2d(det->c[0], det->c[1]) + offset) - to_centre;
    Eigen::Matrix3d H;
    for (int r = 0; r < 3; ++r) {
      for (int c = 0; c < 3; ++c) H(r, c) = MATD_EL(det->H, r, c);
    }
    // Full frame, our convention = translate(offset - 0.5) * sub-view homography.
    Eigen::Matrix3d shift = Eigen::Matrix3d::Identity();
    shift(0, 2) = x_offset - 0.5;
    shift(1, 2) = y_offset - 0.5;
    out.homography = shift * H;
    detections->Add(out);
  }
  apriltag_detections_destroy(found);
  return Status::Ok();
}

}  // namespace reconar
