// The camera followed against the live model while the capture grows it (CaptureOptions::track_map),
// on a rendered hand-held walk down a corridor with the true pose of every frame. A replay follows
// each frame against the map of all keyframes but the newest (CaptureOptions::map_lag_keyframes),
// waiting for the worker, so the test does not depend on the machine's speed. Each map the live model published has a
// frame of its own (a model that starts again picks another), so the frames posed against one map are aligned to the
// truth by a 7-DoF similarity of their own (the absolute trajectory error of that stretch).
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include "render/ar/capture_session.h"
#include "tests/support/corridor_walk.h"
#include "tests/support/run_command.h"
#include "tests/support/sfm_evaluation.h"

namespace reconar {
namespace {

namespace fs = std::filesystem;

TEST(CaptureMapTracking, FramesArePosedAgainstTheGrowingModel) {
  const fs::path root = testing::MakeTestDirectory("capture_map_tracking");
  auto video = testing::RenderCorridorVideo((root / "video").string());
  ASSERT_TRUE(video.ok()) << video.status().ToString();
  const int frames = video->walk.frames;

  CaptureOptions options;
  options.source = (root / "video").string();
  options.project_dir = (root / "capture").string();
  options.frame_events = true;
  // Per map version: the frames posed against it, and their true poses.
  std::map<int, std::vector<testing::CameraPose>> posed, true_poses;
  int events = 0, frames_with_map = 0;
  std::map<std::string, std::string> frame_of_keyframe;
  auto report = RunCapture(options, [&](const CaptureEvent& event) {
    if (event.kind == CaptureEvent::Kind::kRegistered || event.kind == CaptureEvent::Kind::kWarning) return;
    ++events;
    if (event.kind == CaptureEvent::Kind::kKeyframe) {
      frame_of_keyframe[fs::path(event.path).filename().string()] =
          video->names[static_cast<size_t>(event.frame_index)];
    }
    frames_with_map += event.map_version > 0;
    if (!event.map_pose_found) return;
    ASSERT_TRUE(event.frame_index >= 0 && event.frame_index < frames);
    testing::CameraPose pose;
    pose.cam_from_world_rotation = event.cam_from_world.rotation;
    pose.centre = CameraCenterInWorld(event.cam_from_world);
    posed[event.map_version].push_back(pose);
    true_poses[event.map_version].push_back(
        testing::PoseOf(video->truth.at(video->names[static_cast<size_t>(event.frame_index)])));
  });
  ASSERT_TRUE(report.ok()) << report.status().ToString();
  EXPECT_EQ(events, frames) << "every frame is reported once";
  EXPECT_GT(frames_with_map, 0);
  const double walk_length = video->length_m();
  std::printf(
      "%d frames, %d keyframes, %d registered; %d maps; %d of the %d frames after the first map posed "
      "against them, %.2f ms per frame (median); baseline from the poses for %d frames\n",
      report->frames, report->keyframes, report->live_model.registered, report->maps_used, report->frames_map_posed,
      frames_with_map, report->median_map_track_ms, report->frames_map_motion);
  // The keyframes in the final live model, for scale: what the map's own poses are worth.
  auto keyframes = testing::ScoreModelAgainstTruth((root / "capture" / "live").string(), video->truth,
                                                   [&](const std::string& name) { return frame_of_keyframe.at(name); });
  ASSERT_TRUE(keyframes.ok()) << keyframes.status().ToString();
  std::printf(
      "keyframes in the final live model: centre error mean %.3f %% (max %.3f %%), relative rotation mean "
      "%.3f deg\n",
      100.0 * keyframes->errors.centre_mean / walk_length, 100.0 * keyframes->errors.centre_max / walk_length,
      keyframes->errors.relative_rotation_mean_deg);
  // A stretch shorter than 5 frames is too short to align (its centres are nearly on a line).
  int evaluated = 0;
  std::vector<double> centre_errors, rotation_errors;
  for (const auto& [version, estimated] : posed) {
    if (estimated.size() < 5) continue;
    auto errors = testing::CameraCenterErrors(estimated, true_poses[version]);
    ASSERT_TRUE(errors.ok()) << errors.status().ToString();
    // Rotation without the alignment: a short straight stretch leaves its roll about the walking
    // direction to the alignment's choice.
    std::printf(
        "map %d: %zu frames posed, centre error mean %.3f %% of the %.2f m walk (max %.3f %%), relative "
        "rotation mean %.3f deg\n",
        version, estimated.size(), 100.0 * errors->centre_mean / walk_length, walk_length,
        100.0 * errors->centre_max / walk_length, errors->relative_rotation_mean_deg);
    evaluated += static_cast<int>(estimated.size());
    centre_errors.insert(centre_errors.end(), errors->centre_errors.begin(), errors->centre_errors.end());
    rotation_errors.push_back(errors->relative_rotation_mean_deg);
  }
  EXPECT_GE(report->maps_used, 2);
  // The map lags the camera by the worker's delay, yet most frames are posed against it. The poses
  // are to tell how far the camera is from the last keyframe, so they are judged against the
  // spacing of the keyframes: typically a tenth of it, never half of it.
  EXPECT_GE(report->frames_map_posed, frames_with_map / 2);
  EXPECT_GE(evaluated, report->frames_map_posed / 2);
  ASSERT_FALSE(centre_errors.empty());
  const double spacing = walk_length / std::max(report->keyframes, 1);
  const double median = testing::Median(centre_errors);
  const double worst = *std::max_element(centre_errors.begin(), centre_errors.end());
  std::printf("centre error over the frames posed: median %.1f mm, max %.1f mm; keyframe spacing %.1f mm\n",
              1000.0 * median, 1000.0 * worst, 1000.0 * spacing);
  EXPECT_LE(median, 0.1 * spacing);
  EXPECT_LE(worst, 0.5 * spacing);
  EXPECT_LE(*std::max_element(rotation_errors.begin(), rotation_errors.end()), 0.25);
  fs::remove_all(root);
}

}  // namespace
}  // namespace reconar
