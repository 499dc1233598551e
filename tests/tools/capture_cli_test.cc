// `reconar capture` on the AR video's 93 real frames (a folder source): keyframes written as JPEG
// with the focal in their EXIF, a capture interrupted and run again ends with the keyframes of an
// uninterrupted one, corrupt frames are skipped with a warning, and a project that cannot be
// written fails naming it.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "core/base/json_reader.h"
#include "core/io/exif.h"
#include "core/io/focal_prior.h"
#include "core/io/image_io.h"
#include "tests/support/ar_video.h"
#include "tests/support/run_command.h"

namespace reconar {
namespace {

namespace fs = std::filesystem;
using testing::CommandRun;
using testing::RunReconar;

std::string Frames() { return testing::ArVideoDir() + "/frames"; }

std::string ReadBytes(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream out;
  out << in.rdbuf();
  return out.str();
}

std::vector<fs::path> Keyframes(const fs::path& project) {
  std::vector<fs::path> files;
  if (!fs::exists(project / "images")) return files;
  for (const auto& entry : fs::directory_iterator(project / "images")) files.push_back(entry.path());
  std::sort(files.begin(), files.end());
  return files;
}

// The last line of --json output: the "end" event.
Result<JsonValue> EndEvent(const std::string& output) {
  const size_t start = output.rfind("{\"event\":\"end\"");
  if (start == std::string::npos) return NotFound("no end event in: " + output);
  return ParseJson(output.substr(start, output.find('\n', start) - start), "the end event");
}

TEST(CaptureCli, ArVideoKeyframesAreJpegsWithTheirFocal) {
  const fs::path project = testing::MakeTestDirectory("capture_ar_video");
  const double fx = testing::ArVideoCamera().fx;
  const CommandRun run = RunReconar("capture " + Frames() + " " + project.string() + " --json --intrinsics " +
                                        std::to_string(fx) + ",822.8,304.8,236.3",
                                    testing::StderrMode::kSeparate);
  ASSERT_EQ(run.exit_code, 0) << run.output << run.error;
  auto end = EndEvent(run.output);
  ASSERT_TRUE(end.ok()) << end.status().ToString();
  EXPECT_EQ(end->Find("frames")->number(), 93.0);
  const std::vector<fs::path> keyframes = Keyframes(project);
  std::printf("%zu keyframes of 93 frames; passed over: %g blurred, %g too close\n", keyframes.size(),
              end->Find("blurred")->number(), end->Find("too_close")->number());
  EXPECT_EQ(static_cast<double>(keyframes.size()), end->Find("keyframes")->number());
  EXPECT_GE(keyframes.size(), 3u);
  EXPECT_LT(keyframes.size(), 93u / 3);
  for (const fs::path& file : keyframes) {
    auto image = ReadImage(file.string());
    ASSERT_TRUE(image.ok()) << image.status().ToString();
    EXPECT_EQ(image->rgb.width(), 640);
    EXPECT_EQ(image->rgb.height(), 480);
    ASSERT_TRUE(image->exif.present) << file;
    EXPECT_EQ(image->exif.make, "reconar");
    const FocalPrior prior = EstimateFocalPrior(image->exif, 640, 480);
    EXPECT_EQ(prior.source, FocalPrior::Source::kExif35mm);
    EXPECT_NEAR(prior.focal_px, fx, 0.5 / 36.0 * 640.0) << file;  // the 35 mm tag is a whole millimetre
  }
  fs::remove_all(project);
}

// Stopped after 30 % and after 70 % of the keyframes an uninterrupted run takes, then run again:
// the same keyframes, to the byte.
TEST(CaptureCli, AnInterruptedCaptureRunAgainEndsAsAnUninterruptedOne) {
  const fs::path root = testing::MakeTestDirectory("capture_resume");
  ASSERT_EQ(RunReconar("capture " + Frames() + " " + (root / "whole").string()).exit_code, 0);
  const std::vector<fs::path> whole = Keyframes(root / "whole");
  ASSERT_GE(whole.size(), 4u);
  for (const double share : {0.3, 0.7}) {
    const fs::path project = root / ("stopped_" + std::to_string(static_cast<int>(100 * share)));
    const int stop_after = std::max(1, static_cast<int>(share * static_cast<double>(whole.size())));
    const CommandRun first =
        RunReconar("capture " + Frames() + " " + project.string() + " --max-keyframes " + std::to_string(stop_after));
    ASSERT_EQ(first.exit_code, 0) << first.output;
    ASSERT_EQ(Keyframes(project).size(), static_cast<size_t>(stop_after));
    const CommandRun again = RunReconar("capture " + Frames() + " " + project.string());
    ASSERT_EQ(again.exit_code, 0) << again.output;
    EXPECT_NE(again.output.find("(" + std::to_string(stop_after) + " already there)"), std::string::npos)
        << again.output;
    const std::vector<fs::path> resumed = Keyframes(project);
    ASSERT_EQ(resumed.size(), whole.size());
    for (size_t k = 0; k < whole.size(); ++k) {
      EXPECT_EQ(resumed[k].filename(), whole[k].filename());
      EXPECT_EQ(ReadBytes(resumed[k]), ReadBytes(whole[k])) << resumed[k];
    }
  }
  fs::remove_all(root);
}

TEST(CaptureCli, CorruptFramesAreSkippedWithAWarning) {
  const fs::path root = testing::MakeTestDirectory("capture_corrupt");
  const fs::path frames = root / "frames";
  fs::create_directories(frames);
  int copied = 0;
  for (const auto& entry : fs::directory_iterator(Frames())) {
    if (entry.path().extension() != ".jpg") continue;
    fs::copy_file(entry.path(), frames / entry.path().filename());
    ++copied;
  }
  ASSERT_EQ(copied, 93);
  // frame0040.jpg cut to a quarter, frame0041.jpg replaced by text.
  const std::string bytes = ReadBytes(frames / "frame0040.jpg");
  std::ofstream(frames / "frame0040.jpg", std::ios::binary | std::ios::trunc) << bytes.substr(0, bytes.size() / 4);
  std::ofstream(frames / "frame0041.jpg", std::ios::trunc) << "not a picture\n";
  const CommandRun run = RunReconar("capture " + frames.string() + " " + (root / "project").string() + " --json",
                                    testing::StderrMode::kSeparate);
  ASSERT_EQ(run.exit_code, 0) << run.output << run.error;
  auto end = EndEvent(run.output);
  ASSERT_TRUE(end.ok()) << end.status().ToString();
  EXPECT_GE(end->Find("corrupt")->number(), 1.0);
  EXPECT_NE(run.output.find("frame0041.jpg"), std::string::npos) << run.output;
  EXPECT_GE(Keyframes(root / "project").size(), 3u);
  for (const fs::path& file : Keyframes(root / "project")) EXPECT_TRUE(ReadImage(file.string()).ok()) << file;
  fs::remove_all(root);
}

TEST(CaptureCli, AProjectThatCannotBeWrittenIsNamed) {
  const fs::path root = testing::MakeTestDirectory("capture_unwritable");
  std::ofstream(root / "a_file") << "x";
  const CommandRun run = RunReconar("capture " + Frames() + " " + (root / "a_file" / "project").string());
  EXPECT_NE(run.exit_code, 0);
  EXPECT_NE(run.output.find("a_file/project/images"), std::string::npos) << run.output;
  fs::remove_all(root);
}

}  // namespace
}  // namespace reconar
