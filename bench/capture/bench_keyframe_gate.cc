// The capture's keyframe gate per frame, one thread: median ms per frame at 640x480 and 1280x720 on
// a rotating-camera sweep over fountain-P11's photo (tests/tracker/rotation_video.h), and on the AR
// video's 93 real 640x480 frames. With OpenCV found, the same work done with OpenCV runs beside it in
// the same process, alternating runs: INTER_AREA resize to the analysis width, Laplacian variance,
// mean and clipped share, goodFeaturesToTrack on keyframes, calcOpticalFlowPyrLK forward and back
// (window 11, 3 levels, as ours), findHomography (RANSAC, 1 px) from the keyframe's corners and the
// median distance from it (the parallax). Reported as ratios: these machines are noisy.
// Then the gate again with a capture's live model working in the same process (its worker thread
// extracting, matching and registering the AR video's frames as keyframes, as `reconar capture`
// runs it), against the gate alone in the same run.
//   bench_keyframe_gate [repeats=5]
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "bench/common/bench_images.h"
#include "core/io/image_io.h"
#include "core/pipeline/live_reconstruction.h"
#include "tests/support/ar_video.h"
#include "tests/tracker/rotation_video.h"
#include "tracker/keyframe_gate.h"

#ifdef RECONAR_BENCH_WITH_OPENCV
#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/video/tracking.hpp>
#endif

namespace {

using reconar::Image;
using Clock = std::chrono::steady_clock;

struct Run {
  double median_ms = 0.0;
  int keyframes = 0;
};

Run RunOurs(const std::vector<Image<uint8_t>>& frames) {
  reconar::KeyframeGate gate;
  reconar::GateFrameReport report;
  std::vector<double> ms;
  for (const Image<uint8_t>& frame : frames) {
    const Clock::time_point start = Clock::now();
    const reconar::Status status = gate.Process(frame.view(), &report);
    ms.push_back(std::chrono::duration<double, std::milli>(Clock::now() - start).count());
    if (!status.ok()) {
      std::fprintf(stderr, "gate: %s\n", status.ToString().c_str());
      std::exit(1);
    }
  }
  return {reconar::bench::Median(ms), gate.keyframes()};
}

#ifdef RECONAR_BENCH_WITH_OPENCV
Run RunOpenCv(const std::vector<Image<uint8_t>>& frames) {
  std::vector<double> ms;
  cv::Mat small, previous, laplacian;
  std::vector<cv::Point2f> keyframe_points, points, forward, backward, predicted;
  std::vector<uchar> status, back_status;
  std::vector<float> error;
  int keyframes = 0;
  size_t keyframe_count = 0;
  for (const Image<uint8_t>& frame : frames) {
    const Clock::time_point start = Clock::now();
    const cv::Mat input(frame.height(), frame.width(), CV_8UC1, const_cast<uint8_t*>(frame.data()));
    const int factor = (frame.width() + 319) / 320;
    cv::resize(input, small, cv::Size(frame.width() / factor, frame.height() / factor), 0, 0, cv::INTER_AREA);
    cv::Laplacian(small, laplacian, CV_32F);
    cv::Scalar mean, deviation;
    cv::meanStdDev(laplacian, mean, deviation);
    const double level = cv::mean(small)[0];
    const int clipped = cv::countNonZero(small <= 4) + cv::countNonZero(small >= 251);
    bool keyframe = keyframe_count == 0;
    if (!keyframe) {
      cv::calcOpticalFlowPyrLK(previous, small, points, forward, status, error, cv::Size(11, 11), 2);
      cv::calcOpticalFlowPyrLK(small, previous, forward, backward, back_status, error, cv::Size(11, 11), 2);
      std::vector<cv::Point2f> kept, kept_keyframe;
      std::vector<float> moved;
      for (size_t i = 0; i < points.size(); ++i) {
        if (!status[i] || !back_status[i] || cv::norm(backward[i] - points[i]) > 1.0) continue;
        kept.push_back(forward[i]);
        kept_keyframe.push_back(keyframe_points[i]);
        moved.push_back(static_cast<float>(cv::norm(forward[i] - keyframe_points[i])));
      }
      points = kept;
      keyframe_points = kept_keyframe;
      double parallax = 0.0;
      if (points.size() >= 8) {
        const cv::Mat homography = cv::findHomography(keyframe_points, points, cv::RANSAC, 1.0);
        if (!homography.empty()) {
          cv::perspectiveTransform(keyframe_points, predicted, homography);
          moved.clear();
          for (size_t i = 0; i < points.size(); ++i)
            moved.push_back(static_cast<float>(cv::norm(predicted[i] - points[i])));
          std::nth_element(moved.begin(), moved.begin() + static_cast<long>(moved.size() / 2), moved.end());
          parallax = moved[moved.size() / 2];
        }
      }
      keyframe = parallax >= 0.02 * small.cols || points.size() < 0.6 * keyframe_count;
    }
    if (keyframe) {
      cv::goodFeaturesToTrack(small, points, 80, 0.01, 0.6 * small.cols / 10);
      keyframe_points = points;
      keyframe_count = points.size();
      ++keyframes;
    }
    small.copyTo(previous);
    ms.push_back(std::chrono::duration<double, std::milli>(Clock::now() - start).count());
    if (deviation[0] < 0 || level < 0 || clipped < 0) std::exit(1);
  }
  return {reconar::bench::Median(ms), keyframes};
}
#endif

void Measure(const char* name, const std::vector<Image<uint8_t>>& frames, int repeats) {
  std::vector<double> ours, theirs;
  int our_keyframes = 0, their_keyframes = 0;
  for (int r = 0; r < repeats; ++r) {
    const Run a = RunOurs(frames);
    ours.push_back(a.median_ms);
    our_keyframes = a.keyframes;
#ifdef RECONAR_BENCH_WITH_OPENCV
    const Run b = RunOpenCv(frames);
    theirs.push_back(b.median_ms);
    their_keyframes = b.keyframes;
#endif
  }
  std::printf("%-34s %3zu frames  reconar %.2f ms/frame (%d keyframes)", name, frames.size(),
              reconar::bench::Median(ours), our_keyframes);
  if (!theirs.empty()) {
    std::printf("  OpenCV %.2f ms/frame (%d keyframes)  ratio %.2f", reconar::bench::Median(theirs), their_keyframes,
                reconar::bench::Median(ours) / reconar::bench::Median(theirs));
  }
  std::printf("\n");
}

}  // namespace

int main(int argc, char** argv) {
  const int repeats = argc > 1 ? std::max(1, std::atoi(argv[1])) : 5;
  const std::string photo = std::string(RECONAR_SHARED_DATA_DIR) + "/strecha_fountain-P11/images/0005.jpg";
  std::vector<std::vector<Image<uint8_t>>> sweeps;
  for (const auto& [width, height] : {std::pair<int, int>{640, 480}, std::pair<int, int>{1280, 720}}) {
    auto scene = reconar::testing::MakeRotationScene(photo, 1280 / width, width, height);
    if (!scene.ok()) {
      std::fprintf(stderr, "%s\n", scene.status().ToString().c_str());
      return 1;
    }
    std::vector<Image<uint8_t>> frames;
    for (int i = 0; i < 90; ++i) {
      frames.push_back(reconar::testing::RenderRotatedView(
          *scene, reconar::testing::YawPitchRoll(-13.0 + 0.3 * i, 2.0 * std::sin(0.1 * i), 0.0)));
    }
    const std::string name = "rotating sweep " + std::to_string(width) + "x" + std::to_string(height);
    Measure(name.c_str(), frames, repeats);
    sweeps.push_back(std::move(frames));
  }
  std::vector<Image<uint8_t>> video;
  for (const reconar::testing::ArVideoFrame& frame : reconar::testing::ReadArVideoFrames()) {
    auto decoded = reconar::ReadImage(reconar::testing::ArVideoDir() + "/frames/" + frame.name);
    if (!decoded.ok()) {
      std::fprintf(stderr, "%s\n", decoded.status().ToString().c_str());
      return 1;
    }
    video.push_back(reconar::ToGray8(decoded->rgb));
  }
  Measure("AR video 640x480 (real frames)", video, repeats);

  // The gate alone, then beside the live model's worker, alternating.
  const std::filesystem::path project = std::filesystem::temp_directory_path() / "bench_keyframe_gate_live";
  std::filesystem::remove_all(project);
  const std::vector<reconar::testing::ArVideoFrame> frames = reconar::testing::ReadArVideoFrames();
  for (const auto& sweep : {std::make_pair(&sweeps[0], "rotating sweep 640x480"),
                            std::make_pair(&sweeps[1], "rotating sweep 1280x720")}) {
    std::vector<double> alone, beside;
    int busy = 0;
    for (int r = 0; r < repeats; ++r) {
      alone.push_back(RunOurs(*sweep.first).median_ms);
      reconar::LiveReconstruction live(reconar::Project(project.string()), reconar::LiveReconstructionOptions());
      for (size_t k = 0; k < frames.size(); k += 2)
        live.AddKeyframe(reconar::testing::ArVideoDir() + "/frames/" + frames[k].name);
      beside.push_back(RunOurs(*sweep.first).median_ms);
      busy += live.NumProcessed() < live.NumKeyframes();  // still working when the gate ended
    }
    std::printf("%-34s %3zu frames  reconar %.2f ms/frame alone, %.2f ms/frame beside the live model's worker "
                "(busy throughout in %d of %d runs), ratio %.2f\n",
                sweep.second, sweep.first->size(), reconar::bench::Median(alone), reconar::bench::Median(beside), busy,
                repeats, reconar::bench::Median(beside) / reconar::bench::Median(alone));
  }
  std::filesystem::remove_all(project);
  return 0;
}
