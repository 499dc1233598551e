// Relocalisation speed and accuracy at 1 thread on 640-pixel-wide queries, against a project's
// localisation map (PROJECT/map/map.rmap), side by side in the same process with the textbook
// baseline a user would otherwise write with OpenCV (when OpenCV is found at build time).
//   bench_localize PROJECT IMAGE|DIR... [--json]
// Each query is decoded (EXIF orientation applied), box-filtered (area) to 640 pixels wide with
// its aspect ratio kept (4:3 -> 640x480, 3:2 -> 640x427) and converted to 8-bit grey; both
// methods get that same frame.
//  - ours: SIFT with the project's feature settings (LocalizePhotosOptions().sift), the camera from
//    ResolveQueryCamera (the map's camera scaled to the frame), then Localizer::Localize with
//    LocalizePhotosOptions().localizer: retrieval + kd-forest matching + P3P LO-RANSAC + LM;
//  - OpenCV: cv::SIFT::create() defaults on the frame; cv::FlannBasedMatcher (KD-tree index, 4
//    trees; search 32 checks, OpenCV's default) trained once, outside the timing, on ALL map
//    points' descriptors (LocalizationMap::point_descriptors as float rows, orientation bins
//    permuted to OpenCV's order, see OpenCvBaseline); knnMatch k = 2, Lowe
//    ratio 0.8; cv::solvePnPRansac with SOLVEPNP_P3P (10000 iterations, 4 px, confidence 0.999),
//    cv::solvePnPRefineLM on the inliers; the same camera matrix and distortion (k1, k2, 0, 0: the
//    same radial model). cv::setNumThreads(1).
// Both count a pose as registered under the localizer's gates (at least min_inliers inliers, at
// least min_inlier_ratio of the 2D-3D matches). Times are per query: the pose part (ours:
// Localize(); OpenCV: knnMatch + ratio + solvePnPRansac + refinement) and SIFT apart, as wall
// time and as the thread's CPU time (robust on a shared machine); median and 95th percentile
// over all queries, the set repeated 3 times when it has fewer than 30. Queries that are photos
// of the project itself (same file name as a keyframe) are compared with that keyframe's pose:
// median camera-centre distance (map units) and rotation angle. Memory: the map file's size and
// LocalizationMap::memory_bytes(), in total and per keyframe.
// Tracked frames (MapTracker, tracker/map_tracker.h): each query our localizer registers becomes
// a short video with exact ground truth, a camera rotating about its localised centre (yaw and
// pitch sweeps of a few degrees: every frame is a homography of the query frame,
// tests/tracker/rotation_video.h); the tracker relocalises on its first frame and tracks the rest
// against the same map. Median and 95th percentile of the tracked frames' time (wall and thread
// CPU, 1 thread), and their rotation / centre error against the rendered truth. Beside it, the
// textbook OpenCV tracker on the same frames: the map inliers of our first (relocalised) frame
// followed by cv::calcOpticalFlowPyrLK (21x21 window, 3 levels, the defaults) from the previous
// frame, and cv::solvePnP (iterative LM from the previous pose, the same pinhole camera) on the
// points it keeps; no new points are added (a user would add a detector and matching for that).
#include <time.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "bench/common/thread_cpu_time.h"
#include "core/base/json_writer.h"
#include "core/features/kdtree.h"
#include "core/io/gray.h"
#include "core/io/image_io.h"
#include "core/pipeline/localize_photos.h"
#include "core/sfm/localization_map.h"
#include "core/sfm/localizer.h"
#include "tests/tracker/rotation_video.h"
#include "tracker/map_tracker.h"

#ifdef RECONAR_BENCH_WITH_OPENCV
#include <opencv2/calib3d.hpp>
#include <opencv2/core.hpp>
#include <opencv2/features2d.hpp>
#include <opencv2/flann.hpp>
#include <opencv2/video/tracking.hpp>
#endif

namespace reconar {
namespace {

using Clock = std::chrono::steady_clock;

constexpr int kFrameWidth = 640;

using reconar::bench::ThreadCpuSeconds;

// Wall and thread-CPU milliseconds of one timed section.
struct Stopwatch {
  Clock::time_point wall = Clock::now();
  double cpu = ThreadCpuSeconds();
  void Stop(double* wall_ms, double* cpu_ms) const {
    *wall_ms = std::chrono::duration<double, std::milli>(Clock::now() - wall).count();
    *cpu_ms = (ThreadCpuSeconds() - cpu) * 1000.0;
  }
};

// The q-quantile (nearest rank) of the values; 0 when there are none.
double Quantile(std::vector<double> values, double q) {
  if (values.empty()) return 0.0;
  std::sort(values.begin(), values.end());
  const size_t rank = static_cast<size_t>(std::ceil(q * static_cast<double>(values.size())));
  return values[std::min(values.size() - 1, rank > 0 ? rank - 1 : 0)];
}
double Median(const std::vector<double>& values) { return Quantile(values, 0.5); }

// Box-filter (area) resampling of interleaved 8-bit pixels: output pixel i covers the input span
// [i * s, (i + 1) * s) with s = in / out, edge pixels weighted by their covered fraction, so a point
// x (pixel centres on integers) maps to (x + 0.5) / s - 0.5, as ScaledIntrinsics scales a camera.
struct SpanWeights {
  std::vector<int> first;             // per output pixel, the first input pixel
  std::vector<std::vector<float>> w;  // per output pixel, the weights from `first` on (sum 1)
};

SpanWeights AreaWeights(int in, int out) {
  SpanWeights spans;
  const double s = static_cast<double>(in) / out;
  for (int i = 0; i < out; ++i) {
    const double begin = i * s, end = std::min<double>(in, (i + 1) * s);
    const int first = static_cast<int>(std::floor(begin));
    std::vector<float> weights;
    for (int k = first; k < in && k < end; ++k) {
      const double covered = std::min<double>(k + 1, end) - std::max<double>(k, begin);
      weights.push_back(static_cast<float>(covered / (end - begin)));
    }
    spans.first.push_back(first);
    spans.w.push_back(std::move(weights));
  }
  return spans;
}

Image<uint8_t> ResizeArea(const Image<uint8_t>& in, int width, int height) {
  const int channels = in.channels();
  const SpanWeights xs = AreaWeights(in.width(), width), ys = AreaWeights(in.height(), height);
  // Columns first, into float rows of the input's height.
  std::vector<float> columns(static_cast<size_t>(in.height()) * width * channels);
  for (int y = 0; y < in.height(); ++y) {
    const uint8_t* row = in.row(y);
    float* out = columns.data() + static_cast<size_t>(y) * width * channels;
    for (int x = 0; x < width; ++x) {
      for (int c = 0; c < channels; ++c) {
        float sum = 0.0f;
        for (size_t k = 0; k < xs.w[x].size(); ++k)
          sum += xs.w[x][k] * row[(xs.first[x] + static_cast<int>(k)) * channels + c];
        out[x * channels + c] = sum;
      }
    }
  }
  Image<uint8_t> out(width, height, channels);
  for (int y = 0; y < height; ++y) {
    for (int i = 0; i < width * channels; ++i) {
      float sum = 0.0f;
      for (size_t k = 0; k < ys.w[y].size(); ++k) {
        sum += ys.w[y][k] * columns[static_cast<size_t>(ys.first[y] + static_cast<int>(k)) * width * channels + i];
      }
      out.row(y)[i] = static_cast<uint8_t>(std::clamp(std::lround(sum), 0L, 255L));
    }
  }
  return out;
}

struct Query {
  std::string name;
  int source_width = 0, source_height = 0;
  Image<uint8_t> gray;              // kFrameWidth wide
  std::optional<Rigid3> reference;  // the keyframe of the same name
};

// One method's outcome on one query, one run.
struct Outcome {
  bool registered = false;
  int features = 0, matches = 0, inliers = 0;
  Rigid3 cam_from_world;
  double sift_ms = 0, sift_cpu_ms = 0, pose_ms = 0, pose_cpu_ms = 0;
  // Ours only: the localizer's own split.
  double retrieval_ms = 0, matching_ms = 0, ransac_ms = 0;
};

struct Summary {
  std::vector<double> sift_ms, sift_cpu_ms, pose_ms, pose_cpu_ms, retrieval_ms, matching_ms, ransac_ms;
  std::vector<double> features, matches, inliers;
  std::vector<double> centre_error, rotation_error_deg;  // last run, queries with a reference
  int registered = 0;                                    // last run
  int registered_with_reference = 0;
};

void AccumulatePoseError(const Rigid3& estimate, const Rigid3& truth, std::vector<double>* rotation_error_deg,
                         std::vector<double>* centre_error) {
  const Eigen::AngleAxisd delta(Eigen::Matrix3d(estimate.rotation * truth.rotation.transpose()));
  rotation_error_deg->push_back(std::abs(delta.angle()) * 180.0 / M_PI);
  centre_error->push_back((CameraCenterInWorld(estimate) - CameraCenterInWorld(truth)).norm());
}

void Accumulate(const Outcome& o, const Query& query, bool last_run, Summary* s) {
  s->sift_ms.push_back(o.sift_ms);
  s->sift_cpu_ms.push_back(o.sift_cpu_ms);
  s->pose_ms.push_back(o.pose_ms);
  s->pose_cpu_ms.push_back(o.pose_cpu_ms);
  s->retrieval_ms.push_back(o.retrieval_ms);
  s->matching_ms.push_back(o.matching_ms);
  s->ransac_ms.push_back(o.ransac_ms);
  if (!last_run) return;
  s->features.push_back(o.features);
  s->matches.push_back(o.matches);
  s->inliers.push_back(o.inliers);
  if (!o.registered) return;
  ++s->registered;
  if (!query.reference) return;
  ++s->registered_with_reference;
  AccumulatePoseError(o.cam_from_world, *query.reference, &s->rotation_error_deg, &s->centre_error);
}

Result<Outcome> RunOurs(const Query& query, SiftExtractor* extractor, const Localizer& localizer,
                        const QueryCamera& camera) {
  Outcome o;
  const Stopwatch sift_clock;
  Image<float> gray(query.gray.width(), query.gray.height());
  Gray8ToFloat(query.gray.view(), gray.view());
  RECONAR_ASSIGN_OR_RETURN(const SiftFeatures features, extractor->Extract(gray.view()));
  sift_clock.Stop(&o.sift_ms, &o.sift_cpu_ms);
  const Stopwatch pose_clock;
  RECONAR_ASSIGN_OR_RETURN(const LocalizationResult result, localizer.Localize(features, camera));
  pose_clock.Stop(&o.pose_ms, &o.pose_cpu_ms);
  o.registered = result.registered;
  o.features = result.num_features;
  o.matches = result.num_matches;
  o.inliers = result.num_inliers;
  o.cam_from_world = result.cam_from_world;
  o.retrieval_ms = result.seconds_retrieval * 1000.0;
  o.matching_ms = result.seconds_matching * 1000.0;
  o.ransac_ms = result.seconds_pose * 1000.0;
  return o;
}

#ifdef RECONAR_BENCH_WITH_OPENCV
struct OpenCvBaseline {
  cv::Ptr<cv::SIFT> sift = cv::SIFT::create();
  cv::FlannBasedMatcher matcher{cv::makePtr<cv::flann::KDTreeIndexParams>(4), cv::makePtr<cv::flann::SearchParams>(32)};
  std::vector<cv::Point3f> points;
  double train_ms = 0.0;

  explicit OpenCvBaseline(const LocalizationMap& map) {
    cv::Mat descriptors(map.num_points(), 128, CV_32F);
    for (int i = 0; i < map.num_points(); ++i) {
      // Our orientation bin k is OpenCV's bin (8 - k) % 8 (its gradient angles are y-up): the same
      // 4x4 cells in the same order otherwise (measured: matched keypoints' descriptors differ by
      // ~45 of ~512 in L2 after this permutation, ~475 without).
      const uint8_t* ours = map.point_descriptors.data() + static_cast<size_t>(i) * 128;
      for (int cell = 0; cell < 16; ++cell) {
        for (int k = 0; k < 8; ++k) descriptors.at<float>(i, cell * 8 + (8 - k) % 8) = ours[cell * 8 + k];
      }
      const Eigen::Vector3d& p = map.points[static_cast<size_t>(i)];
      points.emplace_back(static_cast<float>(p.x()), static_cast<float>(p.y()), static_cast<float>(p.z()));
    }
    const auto start = Clock::now();
    matcher.add(std::vector<cv::Mat>{descriptors});
    matcher.train();
    train_ms = std::chrono::duration<double, std::milli>(Clock::now() - start).count();
  }

  Outcome Run(const Query& query, const RadialCamera& camera, const LocalizerOptions& gates) {
    Outcome o;
    const cv::Mat frame(query.gray.height(), query.gray.width(), CV_8U, const_cast<uint8_t*>(query.gray.data()));
    const Stopwatch sift_clock;
    std::vector<cv::KeyPoint> keypoints;
    cv::Mat descriptors;
    sift->detectAndCompute(frame, cv::noArray(), keypoints, descriptors);
    sift_clock.Stop(&o.sift_ms, &o.sift_cpu_ms);
    o.features = static_cast<int>(keypoints.size());
    const Stopwatch pose_clock;
    std::vector<cv::Point2f> image_points;
    std::vector<cv::Point3f> object_points;
    if (!keypoints.empty()) {
      std::vector<std::vector<cv::DMatch>> knn;
      matcher.knnMatch(descriptors, knn, 2);
      for (const std::vector<cv::DMatch>& m : knn) {
        if (m.size() < 2 || !(m[0].distance < 0.8f * m[1].distance)) continue;
        image_points.push_back(keypoints[static_cast<size_t>(m[0].queryIdx)].pt);
        object_points.push_back(points[static_cast<size_t>(m[0].trainIdx)]);
      }
    }
    o.matches = static_cast<int>(image_points.size());
    const cv::Matx33d k(camera.focal, 0, camera.cx, 0, camera.fy(), camera.cy, 0, 0, 1);
    const cv::Vec4d distortion(camera.k1, camera.k2, 0, 0);
    cv::Mat rvec, tvec;
    std::vector<int> inliers;
    if (o.matches >= 4 && cv::solvePnPRansac(object_points, image_points, k, distortion, rvec, tvec, false, 10000, 4.0f,
                                             0.999, inliers, cv::SOLVEPNP_P3P)) {
      std::vector<cv::Point3f> inlier_object;
      std::vector<cv::Point2f> inlier_image;
      for (int i : inliers) {
        inlier_object.push_back(object_points[static_cast<size_t>(i)]);
        inlier_image.push_back(image_points[static_cast<size_t>(i)]);
      }
      if (inliers.size() >= 4) cv::solvePnPRefineLM(inlier_object, inlier_image, k, distortion, rvec, tvec);
      o.inliers = static_cast<int>(inliers.size());
    }
    pose_clock.Stop(&o.pose_ms, &o.pose_cpu_ms);
    o.registered = o.inliers >= gates.min_inliers && o.inliers >= gates.min_inlier_ratio * o.matches;
    if (o.inliers > 0) {
      cv::Matx33d r;
      cv::Rodrigues(rvec, r);
      for (int row = 0; row < 3; ++row) {
        for (int col = 0; col < 3; ++col) o.cam_from_world.rotation(row, col) = r(row, col);
        o.cam_from_world.translation(row) = tvec.at<double>(row);
      }
    }
    return o;
  }
};
#endif

constexpr int kTrackedVideoFrames = 40;

struct TrackingSummary {
  int videos = 0;
  int lost_frames = 0;  // frames after the first without a pose
  int max_tracked_points = 0;
  std::vector<double> ms, cpu_ms, inliers, rotation_error_deg, centre_error;
  // The OpenCV tracker on the same frames (when built with OpenCV).
  int opencv_lost_frames = 0;
  std::vector<double> opencv_ms, opencv_cpu_ms, opencv_points, opencv_rotation_error_deg, opencv_centre_error;
};

#ifdef RECONAR_BENCH_WITH_OPENCV
// The textbook tracker: points followed by pyramidal LK from the previous frame, pose by
// iterative PnP from the previous one. Started from our first frame's map inliers and pose.
class OpenCvFlowTracker {
 public:
  OpenCvFlowTracker(const CameraIntrinsics& camera, const MapTrackerFrameReport& first, const cv::Mat& first_frame)
      : k_(camera.fx, 0, camera.cx, 0, camera.fy, camera.cy, 0, 0, 1), previous_(first_frame.clone()) {
    for (size_t i = 0; i < first.inlier_pixels.size(); ++i) {
      pixels_.emplace_back(static_cast<float>(first.inlier_pixels[i].x()), static_cast<float>(first.inlier_pixels[i].y()));
      const Eigen::Vector3d& X = first.inlier_world_points[i];
      points_.emplace_back(static_cast<float>(X.x()), static_cast<float>(X.y()), static_cast<float>(X.z()));
    }
    cv::Matx33d r;
    for (int i = 0; i < 3; ++i) {
      for (int j = 0; j < 3; ++j) r(i, j) = first.cam_from_world.rotation(i, j);
    }
    cv::Rodrigues(r, rvec_);
    tvec_ = (cv::Mat_<double>(3, 1) << first.cam_from_world.translation.x(), first.cam_from_world.translation.y(),
             first.cam_from_world.translation.z());
  }

  // The next frame's pose; false when fewer than 6 points are left.
  bool Track(const cv::Mat& frame, Rigid3* cam_from_world) {
    if (pixels_.size() < 6) return false;
    std::vector<cv::Point2f> next;
    std::vector<uint8_t> status;
    std::vector<float> error;
    cv::calcOpticalFlowPyrLK(previous_, frame, pixels_, next, status, error);
    size_t kept = 0;
    for (size_t i = 0; i < next.size(); ++i) {
      if (!status[i]) continue;
      pixels_[kept] = next[i];
      points_[kept] = points_[i];
      ++kept;
    }
    pixels_.resize(kept);
    points_.resize(kept);
    frame.copyTo(previous_);
    if (kept < 6 || !cv::solvePnP(points_, pixels_, k_, cv::noArray(), rvec_, tvec_, true, cv::SOLVEPNP_ITERATIVE)) {
      return false;
    }
    cv::Matx33d r;
    cv::Rodrigues(rvec_, r);
    for (int i = 0; i < 3; ++i) {
      for (int j = 0; j < 3; ++j) cam_from_world->rotation(i, j) = r(i, j);
      cam_from_world->translation(i) = tvec_.at<double>(i);
    }
    return true;
  }
  size_t points() const { return pixels_.size(); }

 private:
  cv::Matx33d k_;
  cv::Mat previous_;
  cv::Mat rvec_, tvec_;
  std::vector<cv::Point2f> pixels_;
  std::vector<cv::Point3f> points_;
};
#endif

// A rotating-camera video of kTrackedVideoFrames frames around the query's localised pose, tracked
// against the map; the frames after the first (relocalised) are timed.
Status TrackRotatingView(const LocalizationMap& map, const Query& query, const RadialCamera& camera,
                         const Rigid3& cam_from_world, TrackingSummary* summary) {
  testing::RotationScene scene;
  scene.photo = Image<uint8_t>(query.gray.width(), query.gray.height());
  std::copy(query.gray.data(), query.gray.data() + query.gray.width() * query.gray.height(), scene.photo.data());
  CameraIntrinsics intrinsics;
  intrinsics.width = query.gray.width();
  intrinsics.height = query.gray.height();
  intrinsics.fx = camera.focal;
  intrinsics.fy = camera.fy();
  intrinsics.cx = camera.cx;
  intrinsics.cy = camera.cy;
  intrinsics.k1 = camera.k1;
  intrinsics.k2 = camera.k2;
  // The query frame through its own (distorted) camera; the video's frames are rendered
  // undistorted, and the tracker is given that pinhole camera.
  scene.photo_camera = intrinsics;
  intrinsics.k1 = intrinsics.k2 = 0.0;
  scene.frame_camera = intrinsics;
  scene.photo_cam_from_world = cam_from_world;
  MapTrackerOptions options;
  options.intrinsics = intrinsics;
  options.localizer = LocalizePhotosOptions().localizer;
  options.sift = LocalizePhotosOptions().sift;
  summary->max_tracked_points = options.max_tracked_points;
  RECONAR_ASSIGN_OR_RETURN(std::unique_ptr<MapTracker> tracker, MapTracker::Create(&map, options));
  MapTrackerFrameReport report;
  ++summary->videos;
#ifdef RECONAR_BENCH_WITH_OPENCV
  std::unique_ptr<OpenCvFlowTracker> opencv;
#endif
  for (int i = 0; i < kTrackedVideoFrames; ++i) {
    // Yaw 0 -> 4 deg -> 0, pitch 0 -> 2 deg: up to ~0.4 deg (~4 px at 640 px) per frame.
    const double phase = static_cast<double>(i) / (kTrackedVideoFrames - 1);
    const Eigen::Matrix3d rotation = testing::YawPitchRoll(4.0 * std::sin(M_PI * phase), 2.0 * phase, 0.0);
    const Image<uint8_t> frame = testing::RenderRotatedView(scene, rotation);
    const Stopwatch clock;
    RECONAR_RETURN_IF_ERROR(tracker->Track(frame.view(), nullptr, &report));
    double wall_ms = 0.0, cpu_ms = 0.0;
    clock.Stop(&wall_ms, &cpu_ms);
    const Rigid3 truth = testing::RotatedViewPose(scene, rotation);
#ifdef RECONAR_BENCH_WITH_OPENCV
    const cv::Mat cv_frame(frame.height(), frame.width(), CV_8U, const_cast<uint8_t*>(frame.data()));
    if (i == 0 && report.found) opencv = std::make_unique<OpenCvFlowTracker>(intrinsics, report, cv_frame);
    if (i > 0 && opencv) {
      Rigid3 opencv_pose;
      const Stopwatch opencv_clock;
      const bool opencv_found = opencv->Track(cv_frame, &opencv_pose);
      double opencv_wall_ms = 0.0, opencv_cpu_ms = 0.0;
      opencv_clock.Stop(&opencv_wall_ms, &opencv_cpu_ms);
      if (opencv_found) {
        summary->opencv_ms.push_back(opencv_wall_ms);
        summary->opencv_cpu_ms.push_back(opencv_cpu_ms);
        summary->opencv_points.push_back(static_cast<double>(opencv->points()));
        AccumulatePoseError(opencv_pose, truth, &summary->opencv_rotation_error_deg, &summary->opencv_centre_error);
      } else {
        ++summary->opencv_lost_frames;
      }
    }
#endif
    if (i == 0) continue;
    if (!report.found) {
      ++summary->lost_frames;
      continue;
    }
    if (report.relocalised) continue;  // not a tracked frame
    summary->ms.push_back(wall_ms);
    summary->cpu_ms.push_back(cpu_ms);
    summary->inliers.push_back(report.inliers);
    AccumulatePoseError(report.cam_from_world, truth, &summary->rotation_error_deg, &summary->centre_error);
  }
  return Status::Ok();
}

std::vector<std::string> ImagePaths(const std::vector<std::string>& arguments) {
  std::vector<std::string> paths;
  for (const std::string& argument : arguments) {
    if (!std::filesystem::is_directory(argument)) {
      paths.push_back(argument);
      continue;
    }
    std::vector<std::string> found;
    for (const auto& entry : std::filesystem::directory_iterator(argument)) {
      std::string ext = entry.path().extension().string();
      std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return std::tolower(c); });
      if (entry.is_regular_file() && (ext == ".jpg" || ext == ".jpeg" || ext == ".png")) {
        found.push_back(entry.path().string());
      }
    }
    std::sort(found.begin(), found.end());
    paths.insert(paths.end(), found.begin(), found.end());
  }
  return paths;
}

int Fail(const Status& status) {
  std::fprintf(stderr, "bench_localize: %s\n", status.ToString().c_str());
  return 1;
}

void PrintRow(const char* label, const std::vector<double>& ms, const std::vector<double>& cpu_ms) {
  std::printf("  %-34s median %7.2f ms  p95 %7.2f ms   (thread CPU: median %7.2f, p95 %7.2f)\n", label, Median(ms),
              Quantile(ms, 0.95), Median(cpu_ms), Quantile(cpu_ms, 0.95));
}

void JsonTimes(JsonWriter* json, const std::string& key, const std::vector<double>& ms) {
  json->Key(key).BeginObject().Key("median").Double(Median(ms)).Key("p95").Double(Quantile(ms, 0.95)).EndObject();
}

void JsonSummary(JsonWriter* json, const std::string& key, const Summary& s, bool ours) {
  json->Key(key).BeginObject();
  JsonTimes(json, "pose_ms", s.pose_ms);
  JsonTimes(json, "pose_cpu_ms", s.pose_cpu_ms);
  JsonTimes(json, "sift_ms", s.sift_ms);
  JsonTimes(json, "sift_cpu_ms", s.sift_cpu_ms);
  if (ours) {
    JsonTimes(json, "retrieval_ms", s.retrieval_ms);
    JsonTimes(json, "matching_ms", s.matching_ms);
    JsonTimes(json, "ransac_refine_ms", s.ransac_ms);
  }
  json->Key("registered").Int(s.registered).Key("registered_with_reference").Int(s.registered_with_reference);
  json->Key("median_features").Double(Median(s.features)).Key("median_matches").Double(Median(s.matches));
  json->Key("median_inliers").Double(Median(s.inliers));
  json->Key("median_centre_error").Double(Median(s.centre_error));
  json->Key("median_rotation_error_deg").Double(Median(s.rotation_error_deg));
  json->EndObject();
}

int Run(int argc, char** argv) {
  bool as_json = false;
  std::vector<std::string> positional;
  for (int i = 1; i < argc; ++i) {
    if (std::strcmp(argv[i], "--json") == 0) {
      as_json = true;
    } else {
      positional.push_back(argv[i]);
    }
  }
  if (positional.size() < 2) {
    std::fprintf(stderr, "usage: bench_localize PROJECT IMAGE|DIR... [--json]\n");
    return 2;
  }
  const std::string map_path = positional[0] + "/map/map.rmap";
  auto map = ReadLocalizationMap(map_path);
  if (!map.ok()) return Fail(map.status());
  const uintmax_t file_bytes = std::filesystem::file_size(map_path);
  const LocalizePhotosOptions defaults;
  const Stopwatch create_clock;
  auto localizer = Localizer::Create(&*map, defaults.localizer);
  if (!localizer.ok()) return Fail(localizer.status());
  double create_ms = 0.0, create_cpu_ms = 0.0;
  create_clock.Stop(&create_ms, &create_cpu_ms);
  std::map<std::string, Rigid3> keyframe_pose;
  for (const MapKeyframe& keyframe : map->keyframes) keyframe_pose[keyframe.name] = keyframe.cam_from_world;

  std::vector<Query> queries;
  for (const std::string& path : ImagePaths({positional.begin() + 1, positional.end()})) {
    auto decoded = ReadImage(path);
    if (!decoded.ok()) return Fail(decoded.status());
    Query query;
    query.name = std::filesystem::path(path).filename().string();
    query.source_width = decoded->rgb.width();
    query.source_height = decoded->rgb.height();
    const int height = std::max(
        1, static_cast<int>(std::lround(static_cast<double>(kFrameWidth) * query.source_height / query.source_width)));
    query.gray = ToGray8(ResizeArea(decoded->rgb, kFrameWidth, height));
    if (auto it = keyframe_pose.find(query.name); it != keyframe_pose.end()) query.reference = it->second;
    queries.push_back(std::move(query));
  }
  if (queries.empty()) return Fail(InvalidArgument("no query image"));
  const int runs = queries.size() < 30 ? 3 : 1;

  SiftOptions sift_options = defaults.sift;
  SiftExtractor extractor(sift_options);
  std::map<std::pair<int, int>, QueryCamera> cameras;  // per frame size
  for (const Query& query : queries) {
    const std::pair<int, int> size(query.gray.width(), query.gray.height());
    if (cameras.count(size)) continue;
    auto camera = ResolveQueryCamera(*map, size.first, size.second, std::nullopt, 0.0);
    if (!camera.ok()) return Fail(camera.status());
    if (!camera->known)
      return Fail(FailedPrecondition("the map has no camera for " + std::to_string(size.first) + "x" +
                                     std::to_string(size.second) + " frames"));
    cameras[size] = *camera;
  }

  Summary ours, baseline;
  std::vector<std::optional<Rigid3>> localised(queries.size());
#ifdef RECONAR_BENCH_WITH_OPENCV
  cv::setNumThreads(1);
  OpenCvBaseline opencv(*map);
  const bool with_opencv = true;
#else
  const bool with_opencv = false;
#endif
  for (int run = 0; run < runs; ++run) {
    const bool last = run == runs - 1;
    for (size_t q = 0; q < queries.size(); ++q) {
      const Query& query = queries[q];
      const QueryCamera& camera = cameras[{query.gray.width(), query.gray.height()}];
      auto outcome = RunOurs(query, &extractor, *localizer, camera);
      if (!outcome.ok()) return Fail(outcome.status().WithContext(query.name));
      Accumulate(*outcome, query, last, &ours);
      if (last && outcome->registered) localised[q] = outcome->cam_from_world;
#ifdef RECONAR_BENCH_WITH_OPENCV
      Accumulate(opencv.Run(query, *camera.known, defaults.localizer), query, last, &baseline);
#endif
    }
  }

  TrackingSummary tracking;
  for (size_t q = 0; q < queries.size(); ++q) {
    if (!localised[q]) continue;
    const Status status =
        TrackRotatingView(*map, queries[q], *cameras[{queries[q].gray.width(), queries[q].gray.height()}].known,
                          *localised[q], &tracking);
    if (!status.ok()) return Fail(status.WithContext(queries[q].name));
  }

  int with_reference = 0;
  for (const Query& query : queries) with_reference += query.reference.has_value();
  const Query& first = queries.front();
  const RadialCamera& camera = *cameras[{first.gray.width(), first.gray.height()}].known;
  const double keyframes = static_cast<double>(map->keyframes.size());
  if (as_json) {
    JsonWriter json;
    json.BeginObject().Key("project").String(positional[0]).Key("frame").String(map->frame);
    json.Key("queries").Int(static_cast<int>(queries.size())).Key("runs").Int(runs);
    json.Key("queries_in_map").Int(with_reference);
    json.Key("query_width").Int(first.gray.width()).Key("query_height").Int(first.gray.height());
    json.Key("source_width").Int(first.source_width).Key("source_height").Int(first.source_height);
    json.Key("camera").BeginObject().Key("fx").Double(camera.focal).Key("fy").Double(camera.fy());
    json.Key("cx").Double(camera.cx).Key("cy").Double(camera.cy).Key("k1").Double(camera.k1).Key("k2").Double(
        camera.k2);
    json.EndObject();
    json.Key("map").BeginObject().Key("keyframes").Int(static_cast<int>(map->keyframes.size()));
    json.Key("points").Int(map->num_points()).Key("observations").Int(map->num_observations());
    json.Key("file_bytes").Int(static_cast<long long>(file_bytes));
    json.Key("memory_bytes").Int(static_cast<long long>(map->memory_bytes()));
    json.Key("file_bytes_per_keyframe").Double(static_cast<double>(file_bytes) / keyframes);
    json.Key("memory_bytes_per_keyframe").Double(static_cast<double>(map->memory_bytes()) / keyframes);
    json.EndObject();
    JsonSummary(&json, "ours", ours, true);
    json.Key("tracked")
        .BeginObject()
        .Key("videos")
        .Int(tracking.videos)
        .Key("frames")
        .Int(static_cast<int>(tracking.ms.size()));
    json.Key("lost_frames").Int(tracking.lost_frames).Key("max_tracked_points").Int(tracking.max_tracked_points);
    JsonTimes(&json, "frame_ms", tracking.ms);
    JsonTimes(&json, "frame_cpu_ms", tracking.cpu_ms);
    json.Key("median_inliers").Double(Median(tracking.inliers));
    json.Key("median_rotation_error_deg").Double(Median(tracking.rotation_error_deg));
    json.Key("p95_rotation_error_deg").Double(Quantile(tracking.rotation_error_deg, 0.95));
    json.Key("median_centre_error").Double(Median(tracking.centre_error));
    if (with_opencv) {
      JsonTimes(&json, "opencv_frame_ms", tracking.opencv_ms);
      JsonTimes(&json, "opencv_frame_cpu_ms", tracking.opencv_cpu_ms);
      json.Key("opencv_lost_frames").Int(tracking.opencv_lost_frames);
      json.Key("opencv_median_rotation_error_deg").Double(Median(tracking.opencv_rotation_error_deg));
      json.Key("opencv_median_centre_error").Double(Median(tracking.opencv_centre_error));
    }
    json.EndObject();
    if (with_opencv) {
      JsonSummary(&json, "opencv", baseline, false);
#ifdef RECONAR_BENCH_WITH_OPENCV
      json.Key("opencv_version").String(CV_VERSION).Key("opencv_flann_train_ms").Double(opencv.train_ms);
#endif
      json.Key("ratio_pose_ms").Double(Median(ours.pose_ms) / Median(baseline.pose_ms));
      json.Key("ratio_pose_p95_ms").Double(Quantile(ours.pose_ms, 0.95) / Quantile(baseline.pose_ms, 0.95));
      json.Key("ratio_pose_cpu_ms").Double(Median(ours.pose_cpu_ms) / Median(baseline.pose_cpu_ms));
      json.Key("ratio_registered").Double(static_cast<double>(ours.registered) / std::max(1, baseline.registered));
      json.Key("ratio_centre_error").Double(Median(ours.centre_error) / Median(baseline.centre_error));
      json.Key("ratio_rotation_error").Double(Median(ours.rotation_error_deg) / Median(baseline.rotation_error_deg));
    }
    json.EndObject();
    std::printf("%s\n", json.str().c_str());
    return 0;
  }

  std::printf("map %s: %zu keyframes, %d points, %d observations; frame: %s\n", map_path.c_str(), map->keyframes.size(),
              map->num_points(), map->num_observations(), map->frame.c_str());
  std::printf("  on disk %.2f MiB (%.1f KiB per keyframe), in memory %.2f MiB (%.1f KiB per keyframe)\n",
              file_bytes / 1048576.0, file_bytes / 1024.0 / keyframes, map->memory_bytes() / 1048576.0,
              map->memory_bytes() / 1024.0 / keyframes);
  std::printf(
      "queries: %zu (%d of them keyframes of the map), %dx%d -> %dx%d grey (area filter), %d run(s), 1 thread\n",
      queries.size(), with_reference, first.source_width, first.source_height, first.gray.width(), first.gray.height(),
      runs);
  std::printf("camera (map, scaled): f %.2f/%.2f c %.2f,%.2f k1 %.4f k2 %.4f\n", camera.focal, camera.fy(), camera.cx,
              camera.cy, camera.k1, camera.k2);
  const auto print_accuracy = [&](const Summary& s) {
    std::printf("  registered %d/%zu; median features %.0f, 2D-3D matches %.0f, inliers %.0f\n", s.registered,
                queries.size(), Median(s.features), Median(s.matches), Median(s.inliers));
    std::printf("  vs keyframe pose (%d registered of %d): median centre %.4f (map units), rotation %.3f deg\n",
                s.registered_with_reference, with_reference, Median(s.centre_error), Median(s.rotation_error_deg));
  };
  std::printf("ours (SIFT first octave %d, Localize: %d keyframes, %d leaf checks, ratio %.2f, P3P LO-RANSAC + LM):\n",
              sift_options.first_octave, defaults.localizer.num_keyframes, defaults.localizer.max_leaf_checks,
              defaults.localizer.max_ratio);
  PrintRow("Localize() total", ours.pose_ms, ours.pose_cpu_ms);
  std::printf(
      "    retrieval %.2f / p95 %.2f ms, matching %.2f / %.2f ms, "
      "RANSAC + refinement %.2f / %.2f ms\n",
      Median(ours.retrieval_ms), Quantile(ours.retrieval_ms, 0.95), Median(ours.matching_ms),
      Quantile(ours.matching_ms, 0.95), Median(ours.ransac_ms), Quantile(ours.ransac_ms, 0.95));
  std::printf("    the localizer's kd-forest over all %d observations, built once when it is made: %.1f ms\n",
              map->num_observations(), create_ms);
  PrintRow("SIFT", ours.sift_ms, ours.sift_cpu_ms);
  print_accuracy(ours);
  std::printf(
      "tracked frames (MapTracker, %d points max; %d rotating-camera videos of %d frames around the registered "
      "queries' poses, the first frame relocalised):\n",
      tracking.max_tracked_points, tracking.videos, kTrackedVideoFrames);
  PrintRow("tracked frame", tracking.ms, tracking.cpu_ms);
  std::printf(
      "    %zu tracked frames, %d without a pose; median inliers %.0f; vs the rendered truth: rotation median "
      "%.4f / p95 %.4f deg, centre median %.5f (map units)\n",
      tracking.ms.size(), tracking.lost_frames, Median(tracking.inliers), Median(tracking.rotation_error_deg),
      Quantile(tracking.rotation_error_deg, 0.95), Median(tracking.centre_error));
  if (!with_opencv) {
    std::printf("OpenCV baseline: not built (OpenCV not found)\n");
    return 0;
  }
  std::printf("OpenCV tracked frames (calcOpticalFlowPyrLK 21x21, 3 levels + solvePnP iterative from the previous pose, "
              "started from our first frame's map inliers, no new points):\n");
  PrintRow("tracked frame", tracking.opencv_ms, tracking.opencv_cpu_ms);
  std::printf(
      "    %zu tracked frames, %d without a pose; median points %.0f; vs the rendered truth: rotation median %.4f / "
      "p95 %.4f deg, centre median %.5f (map units)\n",
      tracking.opencv_ms.size(), tracking.opencv_lost_frames, Median(tracking.opencv_points),
      Median(tracking.opencv_rotation_error_deg), Quantile(tracking.opencv_rotation_error_deg, 0.95),
      Median(tracking.opencv_centre_error));
  std::printf("    ratios ours/OpenCV: tracked frame median %.3f (thread CPU %.3f); rotation error median %.3f\n",
              Median(tracking.ms) / Median(tracking.opencv_ms), Median(tracking.cpu_ms) / Median(tracking.opencv_cpu_ms),
              Median(tracking.rotation_error_deg) / Median(tracking.opencv_rotation_error_deg));
#ifdef RECONAR_BENCH_WITH_OPENCV
  std::printf(
      "OpenCV %s (SIFT defaults; FLANN KD-tree 4 trees, 32 checks, over all %d map points, trained once in "
      "%.1f ms; ratio 0.80; solvePnPRansac P3P 10000 it. 4 px 0.999 + solvePnPRefineLM):\n",
      CV_VERSION, map->num_points(), opencv.train_ms);
#endif
  PrintRow("match + PnP + refine", baseline.pose_ms, baseline.pose_cpu_ms);
  PrintRow("SIFT", baseline.sift_ms, baseline.sift_cpu_ms);
  print_accuracy(baseline);
  std::printf(
      "ratios ours/OpenCV: pose time median %.3f, p95 %.3f (thread CPU median %.3f); SIFT median %.3f; "
      "registered %d/%d; median centre error %.3f, rotation error %.3f\n",
      Median(ours.pose_ms) / Median(baseline.pose_ms), Quantile(ours.pose_ms, 0.95) / Quantile(baseline.pose_ms, 0.95),
      Median(ours.pose_cpu_ms) / Median(baseline.pose_cpu_ms), Median(ours.sift_ms) / Median(baseline.sift_ms),
      ours.registered, baseline.registered, Median(ours.centre_error) / Median(baseline.centre_error),
      Median(ours.rotation_error_deg) / Median(baseline.rotation_error_deg));
  return 0;
}

}  // namespace
}  // namespace reconar

int main(int argc, char** argv) { return reconar::Run(argc, argv); }
