// `reconar capture` on the AR video's 93 real frames (a folder source, and a .frames recording of
// them): keyframes written as JPEG with the focal in their EXIF; the live model registering them
// while the capture runs, and `reconstruct` reusing its features and matches; a capture stopped
// (--max-keyframes, SIGKILL) and run again ends with the keyframes and model of an uninterrupted
// one; corrupt frames are skipped with a warning; a recording cut short and a full disk end with a
// clear error and lose nothing; a project that cannot be written fails naming it.
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>

#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <set>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "core/base/json_reader.h"
#include "core/io/exif.h"
#include "core/io/focal_prior.h"
#include "core/io/image_io.h"
#include "core/io/image_write.h"
#include "core/sfm/model_io.h"
#include "platform/camera/recorded_frames.h"
#include "tests/support/ar_video.h"
#include "tests/support/corridor_walk.h"
#include "tests/support/frame_effects.h"
#include "tests/support/run_command.h"
#include "tests/support/sfm_evaluation.h"

namespace reconar {
namespace {

namespace fs = std::filesystem;
using testing::CommandRun;
using testing::RunReconar;

std::string Frames() { return testing::ArVideoDir() + "/frames"; }

// The tests run without DISPLAY, so that `--window auto` opens no window on the test machine's
// screen (under xvfb-run it would); only the window's own test shows one.
std::string TakeDisplay() {
  const char* display = std::getenv("DISPLAY");
  const std::string saved = display != nullptr ? display : "";
  unsetenv("DISPLAY");
  return saved;
}
const std::string g_display = TakeDisplay();

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

// Every file of the capture's results: the keyframes, the features and matches, the live model.
std::map<std::string, std::string> CaptureResults(const fs::path& project) {
  std::map<std::string, std::string> files;
  for (const char* dir : {"images", "features", "matches", "live"}) {
    if (!fs::exists(project / dir)) continue;
    for (const auto& entry : fs::directory_iterator(project / dir)) {
      if (entry.path().filename() == "report.json") continue;  // times differ
      std::string bytes = ReadBytes(entry.path());
      // The image list names each keyframe by its path, which holds the project's.
      for (size_t at = bytes.find(project.string()); at != std::string::npos; at = bytes.find(project.string(), at))
        bytes.replace(at, project.string().size(), "PROJECT");
      files[std::string(dir) + "/" + entry.path().filename().string()] = bytes;
    }
  }
  return files;
}

// The AR video's JPEG frames as a camera delivering MJPEG would have recorded them, 30 frames per second.
void WriteArVideoRecording(const fs::path& path) {
  auto writer = RecordedFramesWriter::Create(path.string());
  ASSERT_TRUE(writer.ok()) << writer.status().ToString();
  std::vector<fs::path> frames;
  for (const auto& entry : fs::directory_iterator(Frames())) {
    if (entry.path().extension() == ".jpg") frames.push_back(entry.path());
  }
  std::sort(frames.begin(), frames.end());
  for (size_t i = 0; i < frames.size(); ++i) {
    const std::string jpeg = ReadBytes(frames[i]);
    RawFrame raw;
    raw.layout.format = PixelFormat::kMjpeg;
    raw.layout.width = 640;
    raw.layout.height = 480;
    raw.data = reinterpret_cast<const uint8_t*>(jpeg.data());
    raw.size = jpeg.size();
    ASSERT_TRUE((*writer)->Append(raw, static_cast<int64_t>(i) * 1000000000 / 30).ok());
  }
  ASSERT_TRUE((*writer)->Finish().ok());
}

double Number(const JsonValue& object, const char* key) {
  const JsonValue* value = object.Find(key);
  return value != nullptr && value->is_number() ? value->number() : -1.0;
}

// The live model registers every keyframe while the capture runs; `reconstruct` (here its sparse
// stages, `sfm`) then reuses the features and matches, which are the ones it would have computed;
// with --tag-size the model is in metres, the tag's edges measured against the printed 0.14 m.
TEST(CaptureCli, TheLiveModelRegistersTheKeyframesAndReconstructReusesItsWork) {
  const fs::path root = testing::MakeTestDirectory("capture_live");
  const fs::path project = root / "project";
  const CameraIntrinsics k = testing::ArVideoCamera();
  const CommandRun run =
      RunReconar("capture " + Frames() + " " + project.string() + " --out-preview " + (root / "preview").string() +
                     " --json --realtime --intrinsics " + std::to_string(k.fx) + "," + std::to_string(k.fy) + "," +
                     std::to_string(k.cx) + "," + std::to_string(k.cy),
                 testing::StderrMode::kSeparate);
  ASSERT_EQ(run.exit_code, 0) << run.output << run.error;
  auto end = EndEvent(run.output);
  ASSERT_TRUE(end.ok()) << end.status().ToString();
  const double keyframes = Number(*end, "keyframes");
  const JsonValue* live = end->Find("live");
  ASSERT_NE(live, nullptr) << run.output;
  size_t registered_events = 0;
  for (size_t at = run.output.find("\"event\":\"registered\""); at != std::string::npos;
       at = run.output.find("\"event\":\"registered\"", at + 1))
    ++registered_events;
  std::printf(
      "%g keyframes, %g registered live (%zu events), %g points; keyframe to registration %.2f s median, "
      "%.2f s 95th percentile\n",
      keyframes, Number(*live, "registered"), registered_events, Number(*live, "points"),
      Number(*live, "median_latency_s"), Number(*live, "p95_latency_s"));
  EXPECT_GE(keyframes, 3.0);
  EXPECT_EQ(Number(*live, "registered"), keyframes);
  EXPECT_EQ(static_cast<double>(registered_events), keyframes);
  EXPECT_TRUE(fs::exists(project / "live" / "points3D.txt"));
  EXPECT_TRUE(fs::exists(project / "live" / "report.json"));
  // The preview after the end: every keyframe's square green (registered), bottom left, 8 px apart.
  auto latest = ReadImage((root / "preview" / "latest.png").string());
  ASSERT_TRUE(latest.ok()) << latest.status().ToString();
  ASSERT_EQ(latest->rgb.width(), 640);
  for (int square = 0; square < static_cast<int>(keyframes); ++square) {
    const uint8_t* pixel = latest->rgb.row(480 - 4 * 8 + 3) + 3 * (2 * 8 + square * 16 + 3);
    EXPECT_GT(pixel[1], 150) << "keyframe " << square;
    EXPECT_LT(pixel[0], 100) << "keyframe " << square;
  }
  // The tag, in view in every frame of the video, outlined in yellow (255, 220, 0).
  int yellow = 0;
  for (int y = 0; y < 480; ++y) {
    for (int x = 0; x < 640; ++x) {
      const uint8_t* pixel = latest->rgb.row(y) + 3 * x;
      yellow += pixel[0] > 235 && pixel[1] > 200 && pixel[1] < 240 && pixel[2] < 40 ? 1 : 0;
    }
  }
  EXPECT_GT(yellow, 400) << "the tag's outline";
  EXPECT_GE(std::distance(fs::directory_iterator(root / "preview"), fs::directory_iterator()),
            static_cast<std::ptrdiff_t>(keyframes) + 1);

  const CommandRun sfm = RunReconar("sfm " + (project / "images").string() + " " + project.string() +
                                    " --threads 2 --tag-size " + std::to_string(testing::kArVideoTagSize));
  ASSERT_EQ(sfm.exit_code, 0) << sfm.output;
  EXPECT_NE(sfm.output.find("features  reused"), std::string::npos) << sfm.output;
  EXPECT_NE(sfm.output.find("matching  reused"), std::string::npos) << sfm.output;
  EXPECT_NE(sfm.output.find("continued from the capture's live model"), std::string::npos) << sfm.output;
  auto tags = ReadJsonFile((project / "tags.json").string());
  ASSERT_TRUE(tags.ok()) << tags.status().ToString();
  ASSERT_TRUE(tags->Find("metric")->bool_value()) << sfm.output;
  const JsonValue& edges = *(*tags->Find("tags"))[0].Find("edges_m");
  for (size_t e = 0; e < edges.size(); ++e) {
    std::printf("tag edge %zu: %.4f m (printed %.2f m)\n", e, edges[e].number(), testing::kArVideoTagSize);
    EXPECT_NEAR(edges[e].number(), testing::kArVideoTagSize, 0.003);
  }

  // What the match stage computes from the keyframes in a project of its own, to the byte.
  const CommandRun fresh =
      RunReconar("sfm " + (project / "images").string() + " " + (root / "offline").string() + " --threads 2");
  ASSERT_EQ(fresh.exit_code, 0) << fresh.output;
  EXPECT_EQ(ReadBytes(project / "matches" / "matches.txt"), ReadBytes(root / "offline" / "matches" / "matches.txt"));
  EXPECT_EQ(ReadBytes(project / "features" / "images.txt"), ReadBytes(root / "offline" / "features" / "images.txt"));
  for (const fs::path& keyframe : Keyframes(project)) {
    const std::string features = "features/" + keyframe.filename().string() + ".rfeat";
    EXPECT_EQ(ReadBytes(project / features), ReadBytes(root / "offline" / features)) << features;
  }

  // Two keyframes taken out of the photos: the mapping still continues from the live model, without them.
  const std::vector<fs::path> all_keyframes = Keyframes(project);
  ASSERT_GE(all_keyframes.size(), 4u);
  std::vector<std::string> kept;
  for (size_t i = 0; i + 2 < all_keyframes.size(); ++i) kept.push_back(all_keyframes[i].filename().string());
  const std::string subset = testing::LinkFiles((root / "subset_photos").string(), (project / "images").string(), kept);
  fs::copy(project, root / "subset", fs::copy_options::recursive);
  const CommandRun fewer = RunReconar("sfm " + subset + " " + (root / "subset").string() + " --threads 2");
  ASSERT_EQ(fewer.exit_code, 0) << fewer.output;
  EXPECT_NE(fewer.output.find("continued from the capture's live model"), std::string::npos) << fewer.output;
  auto fewer_report = ReadJsonFile((root / "subset" / "sparse" / "report.json").string());
  ASSERT_TRUE(fewer_report.ok()) << fewer_report.status().ToString();
  EXPECT_EQ(Number(*fewer_report, "registered"), static_cast<double>(kept.size()));

  // A damaged live model is passed over with the reason, and the mapper starts over.
  {
    std::ofstream damaged(project / "live" / "images.txt", std::ios::app);
    damaged << "9 not a pose\n";
  }
  fs::remove(project / "sparse" / "report.json");  // so that the mapping stage runs again
  const CommandRun again = RunReconar("sfm " + (project / "images").string() + " " + project.string() + " --threads 2");
  ASSERT_EQ(again.exit_code, 0) << again.output;
  EXPECT_NE(again.output.find("live model not used: " + (project / "live" / "images.txt").string()), std::string::npos)
      << again.output;
  auto report = ReadJsonFile((project / "sparse" / "report.json").string());
  ASSERT_TRUE(report.ok()) << report.status().ToString();
  // Started over: as `sfm` on the same keyframes in a project of its own (above).
  auto fresh_report = ReadJsonFile((root / "offline" / "sparse" / "report.json").string());
  ASSERT_TRUE(fresh_report.ok()) << fresh_report.status().ToString();
  std::printf("started over: %g of %g keyframes registered; in a project of its own: %g\n",
              Number(*report, "registered"), keyframes, Number(*fresh_report, "registered"));
  EXPECT_EQ(Number(*report, "registered"), Number(*fresh_report, "registered"));
  // From scratch too, every keyframe of the capture registers.
  EXPECT_EQ(Number(*report, "registered"), keyframes);
  fs::remove_all(root);
}

// Killed (SIGKILL) once 30 % and once 70 % of an uninterrupted capture's keyframes are on disk, then
// run again: the same keyframes, features, matches and live model, to the byte.
TEST(CaptureCli, AKilledCaptureRunAgainEndsAsAnUninterruptedOne) {
  const fs::path root = testing::MakeTestDirectory("capture_killed");
  const fs::path recording = root / "ar_video.frames";
  WriteArVideoRecording(recording);
  const std::string capture = std::string(RECONAR_BINARY) + " capture " + recording.string() + " ";
  ASSERT_EQ(RunReconar("capture " + recording.string() + " " + (root / "whole").string()).exit_code, 0);
  const auto whole = CaptureResults(root / "whole");
  const size_t whole_keyframes = Keyframes(root / "whole").size();
  ASSERT_GE(whole_keyframes, 4u);
  ASSERT_TRUE(whole.count("live/points3D.txt"));
  int killed = 0;
  for (const double share : {0.3, 0.7}) {
    const fs::path project = root / ("killed_" + std::to_string(static_cast<int>(100 * share)));
    const size_t kill_at = std::max<size_t>(1, static_cast<size_t>(share * static_cast<double>(whole_keyframes)));
    const int pid = testing::SpawnCommand(capture + project.string() + " --realtime");
    ASSERT_GT(pid, 0);
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(60);
    while (Keyframes(project).size() < kill_at && std::chrono::steady_clock::now() < deadline)
      std::this_thread::sleep_for(std::chrono::milliseconds(5));
    ::kill(pid, SIGKILL);
    int status = 0;
    ::waitpid(pid, &status, 0);
    if (WIFSIGNALED(status)) ++killed;
    const size_t on_disk = Keyframes(project).size();
    EXPECT_GE(on_disk, kill_at);
    EXPECT_LT(on_disk, whole_keyframes);
    const CommandRun again = RunReconar("capture " + recording.string() + " " + project.string());
    ASSERT_EQ(again.exit_code, 0) << again.output;
    const auto resumed = CaptureResults(project);
    EXPECT_EQ(resumed.size(), whole.size()) << "killed at " << on_disk << " keyframes";
    for (const auto& [name, bytes] : whole) {
      const auto it = resumed.find(name);
      ASSERT_NE(it, resumed.end()) << name << " missing after a kill at " << on_disk << " keyframes";
      EXPECT_TRUE(it->second == bytes) << name << " differs after a kill at " << on_disk << " keyframes";
    }
  }
  EXPECT_EQ(killed, 2);
  fs::remove_all(root);
}

// A camera that stops delivering: the recording cut in the middle of a frame. The capture ends
// with the recording's error and exit code 1; the keyframes taken and the live model stay.
TEST(CaptureCli, ARecordingCutShortEndsWithItsErrorAndKeepsTheKeyframes) {
  const fs::path root = testing::MakeTestDirectory("capture_cut");
  const fs::path recording = root / "cut.frames";
  WriteArVideoRecording(recording);
  fs::resize_file(recording, fs::file_size(recording) * 6 / 10 + 1000);
  const CommandRun run = RunReconar("capture " + recording.string() + " " + (root / "project").string());
  EXPECT_EQ(run.exit_code, 1) << run.output;
  EXPECT_NE(run.output.find("reconar: error: " + recording.string()), std::string::npos) << run.output;
  EXPECT_NE(run.output.find("truncated"), std::string::npos) << run.output;
  std::printf("%s", run.output.substr(run.output.find("reconar: error:")).c_str());
  const std::vector<fs::path> keyframes = Keyframes(root / "project");
  EXPECT_GE(keyframes.size(), 2u);
  for (const fs::path& file : keyframes) EXPECT_TRUE(ReadImage(file.string()).ok()) << file;
  EXPECT_TRUE(fs::exists(root / "project" / "live" / "report.json"));
  fs::remove_all(root);
}

#ifdef RECONAR_V4L2_DOUBLE_PRELOAD
// A camera pulled out mid-capture, through the V4L2 code path: the V4L2 device double
// (tests/platform/camera/v4l2_device_double.h), preloaded into `reconar capture v4l2:DEVICE`,
// serves the AR video's frames at 30 fps through the V4L2 ioctl and mmap interface, and after 50
// frames fails with ENODEV as a USB camera pulled out does. The capture ends naming the device and
// keeps the keyframes and the live model. Plugged in again (the video's frames 50 to 92), the
// capture goes on after those keyframes, leaves them as they were, and its live model grows from
// them: every keyframe of both runs is in it.
TEST(CaptureCli, ACameraThatDisconnectsEndsNamingItAndTheNextRunGoesOnFromItsKeyframes) {
  const fs::path root = testing::MakeTestDirectory("capture_v4l2");
  const fs::path recording = root / "video.frames";
  WriteArVideoRecording(recording);
  const fs::path device = root / "video0";
  const fs::path project = root / "project";
  const auto capture = [&](const std::string& frames) {
    return testing::RunCommand("ASAN_OPTIONS=verify_asan_link_order=0 LD_PRELOAD=" RECONAR_V4L2_DOUBLE_PRELOAD
                               " RECONAR_V4L2_DOUBLE='device=" +
                               device.string() + ";recording=" + recording.string() + ";" + frames + ";fps=30' " +
                               RECONAR_BINARY + " capture v4l2:" + device.string() + " " + project.string());
  };
  const auto live_report = [&]() -> std::pair<double, double> {
    auto report = ParseJson(ReadBytes(project / "live" / "report.json"), "live/report.json");
    EXPECT_TRUE(report.ok()) << report.status().ToString();
    if (!report.ok()) return {-1.0, -1.0};
    return {Number(*report, "keyframes"), Number(*report, "registered")};
  };

  const CommandRun first = capture("first=0;frames=50");
  EXPECT_EQ(first.exit_code, 1) << first.output;
  EXPECT_NE(first.output.find("reconar: error: " + device.string() + ": camera disconnected"), std::string::npos)
      << first.output;
  std::printf("%s", first.output.substr(first.output.find("reconar: error:")).c_str());
  const std::vector<fs::path> first_keyframes = Keyframes(project);
  ASSERT_GE(first_keyframes.size(), 2u) << first.output;
  std::map<fs::path, std::string> first_bytes;
  for (const fs::path& file : first_keyframes) {
    EXPECT_TRUE(ReadImage(file.string()).ok()) << file;
    first_bytes[file] = ReadBytes(file);
  }
  EXPECT_EQ(live_report(),
            std::make_pair(static_cast<double>(first_keyframes.size()), static_cast<double>(first_keyframes.size())));

  const CommandRun second = capture("first=50");
  EXPECT_EQ(second.exit_code, 1) << second.output;
  EXPECT_NE(second.output.find("reconar: error: " + device.string() + ": camera disconnected"), std::string::npos)
      << second.output;
  EXPECT_NE(second.output.find("(" + std::to_string(first_keyframes.size()) + " already there)"), std::string::npos)
      << second.output;
  const std::vector<fs::path> keyframes = Keyframes(project);
  EXPECT_GT(keyframes.size(), first_keyframes.size()) << second.output;
  for (const auto& [file, bytes] : first_bytes) EXPECT_EQ(ReadBytes(file), bytes) << file << " changed";
  EXPECT_EQ(live_report(), std::make_pair(static_cast<double>(keyframes.size()), static_cast<double>(keyframes.size())))
      << second.output;
  std::printf("first run %zu keyframes, both runs %zu, all in the live model\n", first_keyframes.size(),
              keyframes.size());
  fs::remove_all(root);
}
#endif

// The disk fills while keyframes and their features are written (ulimit -f; SIGXFSZ ignored, so a
// write fails with EFBIG): an error naming the file, every file on disk whole, none half written.
TEST(CaptureCli, AFullDiskEndsWithAClearErrorAndNoHalfFile) {
  const fs::path root = testing::MakeTestDirectory("capture_full_disk");
  const fs::path project = root / "project";
  const CommandRun run =
      testing::RunCommand("bash -c \"trap '' XFSZ; ulimit -f 80; exec " + std::string(RECONAR_BINARY) + " capture " +
                          Frames() + " " + project.string() + "\"");
  EXPECT_EQ(run.exit_code, 1) << run.output;
  ASSERT_NE(run.output.find("reconar: error:"), std::string::npos) << run.output;
  EXPECT_NE(run.output.find(project.string()), std::string::npos) << "the error names the file: " << run.output;
  std::printf("%s", run.output.substr(run.output.find("reconar: error:")).c_str());
  for (const auto& entry : fs::recursive_directory_iterator(project)) {
    const std::string name = entry.path().filename().string();
    EXPECT_EQ(name.find(".tmp-"), std::string::npos) << "temporary file left: " << entry.path();
    if (entry.path().extension() == ".jpg") {
      EXPECT_TRUE(ReadImage(entry.path().string()).ok()) << entry.path();
    }
  }
  EXPECT_GE(Keyframes(project).size(), 1u);
  fs::remove_all(root);
}

// A model's registered cameras against the truth (sfm_evaluation.h); a failure when unreadable.
testing::ModelScore ScoreAgainstTruth(const fs::path& model_dir, const testing::GroundTruthByName& truth,
                                      const std::function<std::string(const std::string&)>& truth_name) {
  auto score = testing::ScoreModelAgainstTruth(model_dir.string(), truth, truth_name);
  EXPECT_TRUE(score.ok()) << score.status().ToString();
  return score.ok() ? *score : testing::ModelScore();
}

// A hand-held video with known poses: a slow walk down the rendered corridor (corridor_walk.h: its
// panels are pictures, the camera sways, bobs and turns as a walker's does), with a 9-pixel motion
// blur on every seventh frame and a darker stretch (the exposure at 60 %). The blurred frames are
// never keyframes; the keyframes register in the live model (at least 95 %), whose cameras are as
// close to the truth as those of `sfm` on every k-th frame, k giving as many frames, and as those
// of `sfm` run afterwards on the same keyframes.
TEST(CaptureCli, AHandHeldVideoGivesKeyframesThatServeTheModel) {
  const fs::path root = testing::MakeTestDirectory("capture_hand_held");
  const fs::path video = root / "video";
  fs::create_directories(video);
  auto rendered = testing::RenderCorridorVideo(video.string());
  ASSERT_TRUE(rendered.ok()) << rendered.status().ToString();
  const testing::CorridorWalkOptions& walk = rendered->walk;
  const testing::GroundTruthByName* truth = &rendered->truth;
  const std::vector<std::string>& names = rendered->names;
  ASSERT_EQ(names.size(), 90u);
  std::set<int> blurred;
  for (int i = 0; i < walk.frames; ++i) {
    const bool blur = i % 7 == 3, dark = i >= 40 && i < 55;
    if (!blur && !dark) continue;
    if (blur) blurred.insert(i);
    auto frame = ReadImage((video / names[static_cast<size_t>(i)]).string());
    ASSERT_TRUE(frame.ok()) << frame.status().ToString();
    Image<uint8_t> changed = std::move(frame->rgb);
    if (blur) changed = testing::MotionBlurred(changed, 9);
    if (dark) changed = testing::ExposureScaled(changed, 0.6);
    ASSERT_TRUE(WritePng((video / names[static_cast<size_t>(i)]).string(), changed.view(), 3).ok());
  }

  const fs::path project = root / "capture";
  const CommandRun run =
      RunReconar("capture " + video.string() + " " + project.string() + " --json", testing::StderrMode::kSeparate);
  ASSERT_EQ(run.exit_code, 0) << run.output << run.error;
  auto end = EndEvent(run.output);
  ASSERT_TRUE(end.ok()) << end.status().ToString();
  // Which frame each keyframe is, from the keyframe events.
  std::map<std::string, std::string> frame_of_keyframe;
  std::istringstream lines(run.output);
  for (std::string line; std::getline(lines, line);) {
    if (line.find("\"event\":\"keyframe\"") == std::string::npos) continue;
    auto event = ParseJson(line, "a keyframe event");
    ASSERT_TRUE(event.ok()) << line;
    const int frame = static_cast<int>(Number(*event, "frame"));
    ASSERT_TRUE(frame >= 0 && frame < walk.frames) << line;
    EXPECT_EQ(blurred.count(frame), 0u) << "blurred frame " << frame << " taken as a keyframe";
    frame_of_keyframe[fs::path(event->Find("path")->string()).filename().string()] = names[static_cast<size_t>(frame)];
  }
  const int keyframes = static_cast<int>(frame_of_keyframe.size());
  ASSERT_GE(keyframes, 5);
  const testing::ModelScore live = ScoreAgainstTruth(project / "live", *truth, [&](const std::string& name) {
    const auto it = frame_of_keyframe.find(name);
    return it == frame_of_keyframe.end() ? std::string() : it->second;
  });

  const auto frame_of = [&](const std::string& name) {
    const auto it = frame_of_keyframe.find(name);
    return it == frame_of_keyframe.end() ? std::string() : it->second;
  };
  // `sfm` in the capture's project continues from the live model (and reuses its features and
  // matches); run offline on the same keyframes in a project of its own, it starts over.
  const CommandRun continued_run =
      RunReconar("sfm " + (project / "images").string() + " " + project.string() + " --threads 2");
  ASSERT_EQ(continued_run.exit_code, 0) << continued_run.output;
  EXPECT_NE(continued_run.output.find("continued from the capture's live model"), std::string::npos)
      << continued_run.output;
  const testing::ModelScore continued = ScoreAgainstTruth(project / "sparse", *truth, frame_of);
  const CommandRun offline_run =
      RunReconar("sfm " + (project / "images").string() + " " + (root / "offline").string() + " --threads 2");
  ASSERT_EQ(offline_run.exit_code, 0) << offline_run.output;
  const testing::ModelScore offline = ScoreAgainstTruth(root / "offline" / "sparse", *truth, frame_of);

  // Every k-th frame, k giving as many frames as the capture took keyframes.
  const int k = std::max(1, static_cast<int>(std::lround(static_cast<double>(walk.frames) / keyframes)));
  std::vector<std::string> every_kth;
  for (int i = 0; i < walk.frames && static_cast<int>(every_kth.size()) < keyframes; i += k)
    every_kth.push_back(names[static_cast<size_t>(i)]);
  const fs::path kth_dir = testing::LinkFiles((root / "every_kth").string(), video.string(), every_kth);
  const CommandRun sfm =
      RunReconar("sfm " + kth_dir.string() + " " + (root / "every_kth_project").string() + " --threads 2");
  testing::ModelScore kth;
  if (sfm.exit_code == 0) {
    kth =
        ScoreAgainstTruth(root / "every_kth_project" / "sparse", *truth, [](const std::string& name) { return name; });
  }
  const double walk_length = rendered->length_m();
  std::printf(
      "%d frames, %zu blurred, 15 darker: %d keyframes (passed over: %g judged blurred, %g badly exposed, %g too "
      "close, %g lost); live model %d of %d registered, centre error mean %.3f %% of the %.2f m walk "
      "(max %.3f %%), rotation mean %.3f deg; baseline from the map poses for %g frames\n",
      walk.frames, blurred.size(), keyframes, Number(*end, "blurred"), Number(*end, "bad_exposure"),
      Number(*end, "too_close"), Number(*end, "lost"), live.registered, keyframes,
      100.0 * live.errors.centre_mean / walk_length, walk_length, 100.0 * live.errors.centre_max / walk_length,
      live.errors.rotation_mean_deg,
      end->Find("map") != nullptr ? Number(*end->Find("map"), "frames_baseline_from_map") : -1.0);
  std::printf(
      "every %d-th frame (%zu frames, %zu of them blurred): %d registered, centre error mean %.3f %% (max %.3f "
      "%%), rotation mean %.3f deg%s\n",
      k, every_kth.size(),
      static_cast<size_t>(std::count_if(every_kth.begin(), every_kth.end(),
                                        [&](const std::string& n) {
                                          return blurred.count(static_cast<int>(
                                                     std::find(names.begin(), names.end(), n) - names.begin())) > 0;
                                        })),
      kth.registered, 100.0 * kth.errors.centre_mean / walk_length, 100.0 * kth.errors.centre_max / walk_length,
      kth.errors.rotation_mean_deg, sfm.exit_code == 0 ? "" : " (sfm failed)");
  std::printf(
      "offline sfm on the keyframes: %d registered, centre error mean %.3f %% (max %.3f %%), rotation mean "
      "%.3f deg\n",
      offline.registered, 100.0 * offline.errors.centre_mean / walk_length,
      100.0 * offline.errors.centre_max / walk_length, offline.errors.rotation_mean_deg);
  std::printf(
      "sfm continued from the live model: %d registered, centre error mean %.3f %% (max %.3f %%), rotation mean "
      "%.3f deg\n",
      continued.registered, 100.0 * continued.errors.centre_mean / walk_length,
      100.0 * continued.errors.centre_max / walk_length, continued.errors.rotation_mean_deg);
  EXPECT_GE(live.registered, static_cast<int>(std::ceil(0.95 * keyframes)));
  // The live model, grown one keyframe at a time, is as good as the offline one (within half again).
  EXPECT_GE(live.registered, offline.registered);
  EXPECT_LE(live.errors.centre_mean, 1.5 * offline.errors.centre_mean);
  EXPECT_GE(continued.registered, offline.registered);
  EXPECT_LE(continued.errors.centre_mean, 1.5 * offline.errors.centre_mean);
  // Compared only when every k-th frame registered all its frames (else the capture is better
  // already). Since weak poses register provisionally (provisional_registration.h), the blurred
  // frames among every k-th register too, and the uniform spacing of a steady synthetic walk is as
  // good a choice as any: the keyframes must be as good within the same half again as above.
  if (kth.registered == static_cast<int>(every_kth.size())) {
    std::printf("live model against every %d-th frame: centre error %.2fx\n", k,
                live.errors.centre_mean / kth.errors.centre_mean);
    EXPECT_LE(live.errors.centre_mean, 1.5 * kth.errors.centre_mean);
  }
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

TEST(CaptureCli, TheWindowShowsTheViewOrIsRefusedBeforeAnythingIsWritten) {
  const fs::path root = testing::MakeTestDirectory("capture_window");
  const CommandRun refused = RunReconar("capture " + Frames() + " " + (root / "refused").string() + " --window x11");
  EXPECT_NE(refused.exit_code, 0);
  EXPECT_NE(refused.output.find("no display for the capture's window"), std::string::npos) << refused.output;
  EXPECT_FALSE(fs::exists(root / "refused")) << "nothing may be written when the window cannot open";
  const CommandRun bad_kind = RunReconar("capture " + Frames() + " " + (root / "bad").string() + " --window tv");
  EXPECT_NE(bad_kind.exit_code, 0);
  EXPECT_NE(bad_kind.output.find("--window: 'tv' is not auto, x11, gbm or none"), std::string::npos) << bad_kind.output;

  if (g_display.empty()) GTEST_SKIP() << "DISPLAY is not set: the window itself is not shown";
  setenv("DISPLAY", g_display.c_str(), 1);
  const CommandRun shown =
      RunReconar("capture " + Frames() + " " + (root / "shown").string() + " --no-live --max-keyframes 3");
  ASSERT_EQ(shown.exit_code, 0) << shown.output;
  EXPECT_NE(shown.output.find("showing the view in x11"), std::string::npos) << shown.output;
  EXPECT_EQ(Keyframes(root / "shown").size(), 3u);
  const CommandRun hidden = RunReconar("capture " + Frames() + " " + (root / "hidden").string() +
                                       " --no-live --max-keyframes 3 --window none");
  ASSERT_EQ(hidden.exit_code, 0) << hidden.output;
  EXPECT_EQ(hidden.output.find("showing the view"), std::string::npos) << hidden.output;
  // The window changes nothing of what is captured.
  for (int k = 0; k < 3; ++k) {
    EXPECT_EQ(ReadBytes(Keyframes(root / "shown")[static_cast<size_t>(k)]),
              ReadBytes(Keyframes(root / "hidden")[static_cast<size_t>(k)]));
  }
  fs::remove_all(root);
}

}  // namespace
}  // namespace reconar
