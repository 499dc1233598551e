// The capture loop's live view (CaptureOptions::show_preview, render/ar/capture_session.h) on the
// AR video: every frame shown at its size with the words on it, a window closed by the person ends
// the capture as Ctrl-C does, and a display that fails ends it like a camera that disconnects,
// keeping the keyframes taken.
#include "render/ar/capture_session.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <string>

#include "core/base/atomic_file.h"
#include "tests/support/ar_video.h"
#include "tests/support/run_command.h"

namespace reconar {
namespace {

namespace fs = std::filesystem;

CaptureOptions ArVideoCapture(const std::string& project) {
  CaptureOptions options;
  options.source = testing::ArVideoDir() + "/frames";
  options.project_dir = project;
  options.reconstruct_live = false;
  return options;
}

int JpegsIn(const fs::path& dir) {
  int count = 0;
  for (const auto& entry : fs::directory_iterator(dir)) count += entry.path().extension() == ".jpg";
  return count;
}

TEST(CaptureSession, EveryFrameIsShownAndClosingTheWindowStopsTheCapture) {
  const std::string root = testing::MakeTestDirectory("capture_session_window");
  CaptureOptions whole = ArVideoCapture(root + "/whole");
  auto all = RunCapture(whole, nullptr);
  ASSERT_TRUE(all.ok()) << all.status().ToString();

  CaptureOptions options = ArVideoCapture(root + "/closed");
  int shown = 0, keyframes_when_closed = 0;
  options.show_preview = [&](const Image<uint8_t>& rgb) -> Result<bool> {
    EXPECT_EQ(rgb.width(), 640);
    EXPECT_EQ(rgb.height(), 480);
    EXPECT_EQ(rgb.channels(), 3);
    ++shown;
    if (shown < 40) return true;
    keyframes_when_closed = JpegsIn(root + "/closed/images");
    return false;  // 'q' in the window
  };
  auto closed = RunCapture(options, nullptr);
  ASSERT_TRUE(closed.ok()) << closed.status().ToString();
  EXPECT_EQ(shown, 40);
  EXPECT_EQ(closed->frames, 40);
  EXPECT_EQ(closed->stop_reason, "window closed");
  EXPECT_FALSE(closed->window_failed);
  EXPECT_EQ(closed->keyframes, keyframes_when_closed);
  EXPECT_LT(closed->keyframes, all->keyframes);
  // The keyframes before the window closed are the uninterrupted run's first ones.
  for (int k = 0; k < closed->keyframes; ++k) {
    auto mine = ReadFileToString(closed->keyframe_files[static_cast<size_t>(k)]);
    auto theirs = ReadFileToString(all->keyframe_files[static_cast<size_t>(k)]);
    ASSERT_TRUE(mine.ok() && theirs.ok());
    EXPECT_TRUE(*mine == *theirs) << "keyframe " << k + 1;
  }
}

TEST(CaptureSession, AFailingDisplayEndsTheCaptureAndKeepsTheKeyframes) {
  const std::string root = testing::MakeTestDirectory("capture_session_display_lost");
  CaptureOptions options = ArVideoCapture(root + "/project");
  int shown = 0;
  options.show_preview = [&](const Image<uint8_t>&) -> Result<bool> {
    if (++shown < 60) return true;
    return FailedPrecondition("X11: the connection to the display was lost");
  };
  auto report = RunCapture(options, nullptr);
  ASSERT_TRUE(report.ok()) << report.status().ToString();
  EXPECT_TRUE(report->window_failed);
  EXPECT_FALSE(report->source_failed);
  EXPECT_EQ(report->frames, 60);
  EXPECT_NE(report->stop_reason.find("the window failed: X11: the connection to the display was lost"),
            std::string::npos)
      << report->stop_reason;
  EXPECT_GT(report->keyframes, 0);
  EXPECT_EQ(JpegsIn(root + "/project/images"), report->keyframes);
}

}  // namespace
}  // namespace reconar
