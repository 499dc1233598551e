// ArSession (render/ar): a folder of synthetic frames of a tag at known poses, through the frame
// source and the tag pose source, one Step() per frame. No GL needed.
#include "render/ar/ar_session.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cstdio>
#include <string>

#include "core/io/image_write.h"
#include "platform/camera/recorded_frames.h"
#include "render/ar/ar_project.h"
#include "tests/support/allocation_counter.h"
#include "tests/support/run_command.h"
#include "tests/tracker/synthetic_tag_image.h"

namespace reconar {
namespace {

constexpr double kTagSize = 0.08;
constexpr int kFrames = 5;

Rigid3 CamFromTag(int frame) {
  Rigid3 pose;
  pose.rotation =
      Eigen::AngleAxisd(0.3 - 0.02 * frame, Eigen::Vector3d(0.2, 1.0, 0.1).normalized()).toRotationMatrix() *
      Eigen::AngleAxisd(M_PI, Eigen::Vector3d::UnitX()).toRotationMatrix();
  pose.translation = Eigen::Vector3d(0.01 * frame - 0.02, 0.01, 0.5);
  return pose;
}

// frame0000.png ... of tag 3 at CamFromTag(i).
std::string WriteFrames() {
  const std::string dir = testing::MakeTestDirectory("reconar_ar_session");
  for (int i = 0; i < kFrames; ++i) {
    testing::SyntheticTag tag;
    tag.id = 3;
    tag.size = kTagSize;
    tag.cam_from_tag = CamFromTag(i);
    const Image<uint8_t> image = testing::RenderTags(&tag, 1, testing::TestCamera(), testing::SyntheticRenderOptions());
    char name[32];
    std::snprintf(name, sizeof(name), "/frame%04d.png", i);
    EXPECT_TRUE(WritePng(dir + name, image.view(), 1).ok());
  }
  return dir;
}

ArSessionOptions Options(const std::string& dir) {
  ArSessionOptions options;
  options.source = dir;
  options.frames.want_rgb = false;
  options.pose.tracker.intrinsics = testing::TestCamera();
  options.pose.tracker.tag_size = kTagSize;
  return options;
}

TEST(ArSessionTest, EveryFrameGetsItsPoseThenTheStreamEnds) {
  const std::string dir = WriteFrames();
  auto session = ArSession::Open(Options(dir));
  ASSERT_TRUE(session.ok()) << session.status().ToString();
  EXPECT_EQ((*session)->width(), 640);
  EXPECT_EQ((*session)->height(), 480);
  for (int i = 0; i < kFrames; ++i) {
    auto more = (*session)->Step();
    ASSERT_TRUE(more.ok()) << more.status().ToString();
    ASSERT_TRUE(*more);
    EXPECT_EQ((*session)->frame().index, i);
    const WorldPose& pose = (*session)->pose();
    ASSERT_TRUE(pose.found) << i;
    EXPECT_NEAR((pose.cam_from_world.translation - CamFromTag(i).translation).norm(), 0.0, 2e-3) << i;
    EXPECT_LT((pose.cam_from_world.rotation - CamFromTag(i).rotation).norm(), 3e-2) << i;  // about a degree
    ASSERT_EQ(pose.markers.size(), 1u);
    EXPECT_EQ(pose.markers[0].id, 3);
  }
  auto end = (*session)->Step();
  ASSERT_TRUE(end.ok());
  EXPECT_FALSE(*end);
  EXPECT_EQ((*session)->frames(), kFrames);
}

TEST(ArSessionTest, MaxFramesStopsEarly) {
  ArSessionOptions options = Options(WriteFrames());
  options.max_frames = 2;
  auto session = ArSession::Open(options);
  ASSERT_TRUE(session.ok());
  int steps = 0;
  for (;;) {
    auto more = (*session)->Step();
    ASSERT_TRUE(more.ok());
    if (!*more) break;
    ++steps;
  }
  EXPECT_EQ(steps, 2);
}

// Run(): the Step() loop with each frame handed over, and what it saw.
TEST(ArSessionTest, RunHandsEveryFrameOverAndCountsWhatItSaw) {
  auto session = ArSession::Open(Options(WriteFrames()));
  ASSERT_TRUE(session.ok()) << session.status().ToString();
  int seen = 0;
  auto report = (*session)->Run([&](const ArSession& frame) -> Result<bool> {
    EXPECT_EQ(frame.frame().index, seen);
    EXPECT_TRUE(frame.pose().found);
    ++seen;
    return true;
  });
  ASSERT_TRUE(report.ok()) << report.status().ToString();
  EXPECT_EQ(seen, kFrames);
  EXPECT_EQ(report->frames, kFrames);
  EXPECT_EQ(report->frames_with_tags, kFrames);
  EXPECT_EQ(report->tag_instances, kFrames);
  EXPECT_EQ(report->frames_by_source[static_cast<size_t>(PoseSourceKind::kTags)], kFrames);
  EXPECT_GT(report->max_track_ms, 0.0);
  EXPECT_LE(report->median_track_ms, report->max_track_ms);
  EXPECT_LE(report->mean_track_ms, report->max_track_ms);

  // The callback stops the run (a closed window), and its error ends it.
  auto stopped = ArSession::Open(Options(WriteFrames()));
  ASSERT_TRUE(stopped.ok());
  auto two = (*stopped)->Run([](const ArSession& frame) -> Result<bool> { return frame.frames() < 2; });
  ASSERT_TRUE(two.ok());
  EXPECT_EQ(two->frames, 2);
  auto failing = ArSession::Open(Options(WriteFrames()));
  ASSERT_TRUE(failing.ok());
  auto failed = (*failing)->Run([](const ArSession&) -> Result<bool> { return Internal("drawing failed"); });
  EXPECT_EQ(failed.status().code(), StatusCode::kInternal);
}

// The project's camera (photos twice the video's size) is scaled to the first frame.
TEST(ArSessionTest, PhotoCameraIsScaledToTheVideo) {
  ArSessionOptions options = Options(WriteFrames());
  CameraIntrinsics photo = testing::TestCamera();
  photo.width = 1280;
  photo.height = 960;
  photo.fx = photo.fy = 1200.0;
  photo.cx = 640.5;  // pixel centres at integer coordinates: (640.5 + 0.5) / 2 - 0.5 = 320
  photo.cy = 480.5;
  options.photo_cameras = {photo};
  auto session = ArSession::Open(options);
  ASSERT_TRUE(session.ok()) << session.status().ToString();
  const CameraIntrinsics& k = (*session)->intrinsics();
  EXPECT_EQ(k.width, 640);
  EXPECT_EQ(k.fx, 600.0);
  EXPECT_EQ(k.cx, 320.0);
  EXPECT_EQ(k.cy, 240.0);
  photo.width = 1000;  // another aspect ratio
  EXPECT_EQ(ScaleIntrinsicsToFrame(photo, 640, 480).status().code(), StatusCode::kInvalidArgument);
}

// A project's cameras: the one of the frame's size, else the first of its aspect ratio, scaled.
TEST(ArSessionTest, PhotoCameraForFrameTakesTheCameraOfTheFramesSize) {
  CameraIntrinsics wide;  // 16:9, used by most photos
  wide.width = 1920;
  wide.height = 1080;
  wide.fx = wide.fy = 1500.0;
  wide.cx = 959.5;
  wide.cy = 539.5;
  CameraIntrinsics large = testing::TestCamera();  // 4:3
  large.width = 1280;
  large.height = 960;
  large.fx = large.fy = 1200.0;
  large.cx = 640.5;
  large.cy = 480.5;
  CameraIntrinsics small = large;
  small.width = 640;
  small.height = 480;
  small.fx = small.fy = 610.0;
  small.cx = 321.0;
  small.cy = 239.0;
  auto exact = PhotoCameraForFrame({wide, large, small}, 640, 480);
  ASSERT_TRUE(exact.ok()) << exact.status().ToString();
  EXPECT_EQ(exact->fx, 610.0);
  EXPECT_EQ(exact->cx, 321.0);
  auto scaled = PhotoCameraForFrame({wide, large}, 640, 480);
  ASSERT_TRUE(scaled.ok()) << scaled.status().ToString();
  EXPECT_EQ(scaled->fx, 600.0);
  EXPECT_EQ(scaled->cx, 320.0);
  auto none = PhotoCameraForFrame({wide}, 640, 480);
  EXPECT_EQ(none.status().code(), StatusCode::kInvalidArgument);
  EXPECT_NE(none.status().message().find("1920x1080"), std::string::npos) << none.status().message();
  EXPECT_EQ(PhotoCameraForFrame({}, 640, 480).status().code(), StatusCode::kInvalidArgument);
}

// The whole loop (a raw recording's frames, tracking, the world pose) makes no heap allocation per
// frame once running.
TEST(ArSessionTest, SteadyStateStepDoesNotAllocate) {
  const std::string path = testing::MakeTestDirectory("reconar_ar_session_raw") + "/tags.frames";
  constexpr int kRawFrames = 16;
  {
    auto writer = RecordedFramesWriter::Create(path);
    ASSERT_TRUE(writer.ok()) << writer.status().ToString();
    for (int i = 0; i < kRawFrames; ++i) {
      testing::SyntheticTag tag;
      tag.id = 3;
      tag.size = kTagSize;
      tag.cam_from_tag = CamFromTag(i % kFrames);
      const Image<uint8_t> image =
          testing::RenderTags(&tag, 1, testing::TestCamera(), testing::SyntheticRenderOptions());
      RawFrame raw;
      raw.layout = RawFrameLayout{PixelFormat::kGray8, image.width(), image.height(),
                                  static_cast<uint32_t>(image.view().stride), YuvRange::kFull};
      raw.data = image.view().row(0);
      raw.size = static_cast<size_t>(image.view().stride) * image.height();
      ASSERT_TRUE((*writer)->Append(raw, i).ok());
    }
    ASSERT_TRUE((*writer)->Finish().ok());
  }
  ArSessionOptions options = Options(path);
  options.pose.tracker.full_frame_interval = 5;
  auto session = ArSession::Open(options);
  ASSERT_TRUE(session.ok()) << session.status().ToString();
  for (int i = 0; i < 3; ++i) ASSERT_TRUE((*session)->Step().ok());
  long allocations = -1;
  int found = 0;
  {
    testing::NoAllocationScope scope;
    for (int i = 3; i < kRawFrames; ++i) {
      const Result<bool> more = (*session)->Step();
      if (!more.ok() || !*more) break;
      found += (*session)->pose().found;
    }
    allocations = scope.allocations();
  }
  EXPECT_EQ(allocations, 0);
  EXPECT_EQ(found, kRawFrames - 3);
}

TEST(ArSessionTest, BadSourceIsAnError) {
  ArSessionOptions options = Options("/nonexistent/video.frames");
  EXPECT_FALSE(ArSession::Open(options).ok());
}

}  // namespace
}  // namespace reconar
