// Tag tracking speed: the 93 frames of ../shared/data/apriltag_ar_video_id12 (decoded once, gray),
// one thread each, in the same process, alternating runs:
//   (a) plain full-frame libapriltag with apriltag_detector_create() defaults (tag36h11, 1 thread),
//   (b) our TagTracker with its defaults (1 thread; a fresh tracker per run, so its first frame is
//       a full-frame search).
// At 640x480 (as recorded) and at 1280x960 (the frames upscaled bilinearly, corners scaled with
// them, K by ScaleIntrinsicsToFrame as the AR runtime scales a photo camera to its video). Reports
// median ms/frame over the runs, the ratio (b)/(a), and each side's mean corner error against
// corners.txt (upstream libapriltag, decimate 1).
//   bench_tracker [repeats=5]
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include <apriltag/apriltag.h>
#include <apriltag/tag36h11.h>

#include "bench/common/bench_images.h"
#include "core/io/image_io.h"
#include "render/ar/ar_project.h"
#include "tests/support/ar_video.h"
#include "tracker/tag_tracker.h"

namespace {

using reconar::Image;
using Clock = std::chrono::steady_clock;
using reconar::bench::Median;

struct Frame {
  Image<uint8_t> gray;
  Eigen::Vector2d corners[4];  // reference, the program's pixel convention (ReadArVideoFrames)
};

double MeanCornerError(const Eigen::Vector2d (&corners)[4], const Eigen::Vector2d (&ref)[4]) {
  double sum = 0.0;
  for (int k = 0; k < 4; ++k) sum += (corners[k] - ref[k]).norm();
  return sum / 4;
}

struct RunResult {
  double ms_per_frame = 0.0;
  double mean_corner_error = 0.0;
  int found = 0;
};

RunResult RunPlain(const std::vector<Frame>& frames) {
  apriltag_family_t* family = tag36h11_create();
  apriltag_detector_t* detector = apriltag_detector_create();
  apriltag_detector_add_family(detector, family);
  detector->nthreads = 1;
  RunResult result;
  double error_sum = 0.0;
  const Clock::time_point start = Clock::now();
  for (const Frame& frame : frames) {
    image_u8_t wrapped = {frame.gray.width(), frame.gray.height(), frame.gray.width(),
                          const_cast<uint8_t*>(frame.gray.data())};
    zarray_t* detections = apriltag_detector_detect(detector, &wrapped);
    for (int i = 0; i < zarray_size(detections); ++i) {
      apriltag_detection_t* det = nullptr;
      zarray_get(detections, i, &det);
      if (det->id != 12) continue;
      ++result.found;
      // libapriltag's pixel convention to ours, as TagDetector converts.
      Eigen::Vector2d corners[4];
      for (int k = 0; k < 4; ++k) corners[k] = Eigen::Vector2d(det->p[k][0], det->p[k][1]) - Eigen::Vector2d(0.5, 0.5);
      error_sum += MeanCornerError(corners, frame.corners);
    }
    apriltag_detections_destroy(detections);
  }
  result.ms_per_frame = std::chrono::duration<double, std::milli>(Clock::now() - start).count() / frames.size();
  result.mean_corner_error = error_sum / std::max(1, result.found);
  apriltag_detector_destroy(detector);
  tag36h11_destroy(family);
  return result;
}

struct TrackerBreakdown {
  int region_frames = 0, full_frames = 0, fallback_frames = 0;
  double detect_ms = 0.0, pose_ms = 0.0, total_ms = 0.0;
};

RunResult RunTracker(const std::vector<Frame>& frames, const reconar::CameraIntrinsics& camera,
                     TrackerBreakdown* breakdown) {
  reconar::TagTrackerOptions options;
  options.intrinsics = camera;
  options.tag_size = 0.14;
  auto tracker = reconar::TagTracker::Create(options);
  if (!tracker.ok()) {
    std::fprintf(stderr, "%s\n", tracker.status().ToString().c_str());
    std::exit(1);
  }
  reconar::TagTrackerFrameReport report;
  RunResult result;
  double error_sum = 0.0;
  *breakdown = TrackerBreakdown();
  const Clock::time_point start = Clock::now();
  for (const Frame& frame : frames) {
    if (!(*tracker)->Track(frame.gray.view(), &report).ok()) std::exit(1);
    for (const reconar::TrackedTag& t : report.tags) {
      if (t.id != 12 || !t.measured) continue;
      ++result.found;
      error_sum += MeanCornerError(t.detection.corners, frame.corners);
    }
    using Search = reconar::TagTrackerFrameReport::Search;
    breakdown->region_frames += report.search == Search::kRegions;
    breakdown->full_frames += report.search == Search::kFullFrame;
    breakdown->fallback_frames += report.search == Search::kRegionsThenFullFrame;
    breakdown->detect_ms += report.detect_ms / frames.size();
    breakdown->pose_ms += report.pose_ms / frames.size();
    breakdown->total_ms += report.total_ms / frames.size();
  }
  result.ms_per_frame = std::chrono::duration<double, std::milli>(Clock::now() - start).count() / frames.size();
  result.mean_corner_error = error_sum / std::max(1, result.found);
  return result;
}

}  // namespace

int main(int argc, char** argv) {
  const int repeats = argc > 1 ? std::max(1, std::atoi(argv[1])) : 5;
  const std::vector<reconar::testing::ArVideoFrame> reference = reconar::testing::ReadArVideoFrames();
  if (reference.empty()) {
    std::fprintf(stderr, "%s/corners.txt: cannot open\n", reconar::testing::ArVideoDir().c_str());
    return 2;
  }
  std::vector<Frame> frames;
  for (const reconar::testing::ArVideoFrame& entry : reference) {
    Frame frame;
    std::copy(entry.corners, entry.corners + 4, frame.corners);
    auto decoded = reconar::ReadImage(reconar::testing::ArVideoDir() + "/frames/" + entry.name);
    if (!decoded.ok()) {
      std::fprintf(stderr, "%s\n", decoded.status().ToString().c_str());
      return 2;
    }
    frame.gray = reconar::ToGray8(decoded->rgb);
    frames.push_back(std::move(frame));
  }
  const reconar::CameraIntrinsics camera = reconar::testing::ArVideoCamera();

  for (const int width : {640, 1280}) {
    std::vector<Frame> sized;
    const int height = width * 3 / 4;
    const auto sized_camera = reconar::ScaleIntrinsicsToFrame(camera, width, height);
    if (!sized_camera.ok()) {
      std::fprintf(stderr, "%s\n", sized_camera.status().ToString().c_str());
      return 2;
    }
    const double sx = width / 640.0, sy = height / 480.0;
    if (width == 640) {
      for (const Frame& f : frames) {
        Frame copy;
        copy.gray = f.gray;
        std::copy(f.corners, f.corners + 4, copy.corners);
        sized.push_back(std::move(copy));
      }
    } else {
      for (const Frame& f : frames) {
        Frame scaled;
        scaled.gray = reconar::bench::ResizeBilinear(f.gray, width, height);
        // Pixel edges map to pixel edges: u' = (u + 0.5) * sx - 0.5 (pixel centres on integers).
        for (int k = 0; k < 4; ++k) {
          scaled.corners[k] = Eigen::Vector2d((f.corners[k].x() + 0.5) * sx - 0.5, (f.corners[k].y() + 0.5) * sy - 0.5);
        }
        sized.push_back(std::move(scaled));
      }
    }
    std::vector<double> plain_ms, tracker_ms, ratios;
    RunResult plain, tracked;
    TrackerBreakdown breakdown;
    for (int r = 0; r < repeats; ++r) {
      plain = RunPlain(sized);
      tracked = RunTracker(sized, *sized_camera, &breakdown);
      plain_ms.push_back(plain.ms_per_frame);
      tracker_ms.push_back(tracked.ms_per_frame);
      ratios.push_back(tracked.ms_per_frame / plain.ms_per_frame);
    }
    std::printf("%dx%d, %zu frames, %d runs (median):\n", width, height, sized.size(), repeats);
    std::printf("  (a) libapriltag defaults, full frame : %7.3f ms/frame, tag 12 in %d frames, mean corner error %.3f px\n",
                Median(plain_ms), plain.found, plain.mean_corner_error);
    std::printf("  (b) TagTracker defaults              : %7.3f ms/frame, tag 12 in %d frames, mean corner error %.3f px\n",
                Median(tracker_ms), tracked.found, tracked.mean_corner_error);
    std::printf("  ratio (b)/(a): %.3f (median of per-run ratios %.3f)\n", Median(tracker_ms) / Median(plain_ms),
                Median(ratios));
    std::printf("  tracker, last run: %d region-only frames, %d full-frame, %d region then full frame; per frame "
                "detect %.3f ms, pose %.3f ms, Track() total %.3f ms\n",
                breakdown.region_frames, breakdown.full_frames, breakdown.fallback_frames, breakdown.detect_ms,
                breakdown.pose_ms, breakdown.total_ms);
  }
  return 0;
}
