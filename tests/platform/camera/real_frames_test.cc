// Conversion correctness on real camera frames (apriltag_ar_video_id12: 93 JPEG frames 640x480,
// see its SOURCE.txt). Each JPEG's own Y/Cb/Cr planes (libjpeg raw-data output) are packed into
// NV12 and YUYV buffers as a camera would deliver them, recorded into a .frames file, played back
// through RecordedFrameSource, and compared with libjpeg's own RGB / gray decode of that JPEG.
#include <gtest/gtest.h>

#include <chrono>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <string>
#include <vector>

#include "platform/camera/image_folder_source.h"
#include "platform/camera/recorded_frames.h"
#include "tests/platform/camera/camera_fixture.h"
#include "tests/platform/camera/jpeg_reference.h"

namespace reconar {
namespace {

const std::string kFrames = std::string(RECONAR_SHARED_DATA_DIR) + "/apriltag_ar_video_id12/frames";

std::vector<std::string> FramePaths() {
  std::vector<std::string> paths;
  for (const auto& entry : std::filesystem::directory_iterator(kFrames)) paths.push_back(entry.path().string());
  std::sort(paths.begin(), paths.end());
  return paths;
}

struct DiffStats {
  int max = 0;
  double sum = 0;
  double count = 0;
  void Add(const ImageView<const uint8_t>& view, const std::vector<uint8_t>& packed) {
    for (int y = 0; y < view.height; ++y) {
      for (int x = 0; x < view.width; ++x) {
        const int d = std::abs(view.at(x, y) - packed[static_cast<size_t>(y) * view.width + x]);
        max = std::max(max, d);
        sum += d;
      }
    }
    count += static_cast<double>(view.width) * view.height;
  }
  double mean() const { return count > 0 ? sum / count : 0; }
};

double Milliseconds(std::chrono::steady_clock::duration d) {
  return std::chrono::duration<double, std::milli>(d).count();
}

TEST(CameraRealFrames, Nv12AndYuyvFromJpegPlanesMatchLibjpeg) {
  const std::vector<std::string> paths = FramePaths();
  ASSERT_EQ(paths.size(), 93u);
  const std::string recording = ::testing::TempDir() + "camera_real_yuv.frames";
  std::vector<std::string> jpegs;
  {
    auto writer = RecordedFramesWriter::Create(recording);
    ASSERT_TRUE(writer.ok());
    for (const std::string& path : paths) {
      jpegs.push_back(testing::ReadFileBytes(path));
      testing::YcbcrPlanes planes;
      std::string reason;
      ASSERT_TRUE(testing::ReadYcbcr420Planes(jpegs.back(), &planes, &reason)) << path << ": " << reason;
      ASSERT_EQ(planes.width, 640);
      ASSERT_EQ(planes.height, 480);
      const std::vector<uint8_t> nv12 = testing::PackNv12(planes, 640);
      const std::vector<uint8_t> yuyv = testing::PackYuyv(planes, 1288);  // padded pitch
      RawFrame raw;
      raw.layout = RawFrameLayout{PixelFormat::kNv12, 640, 480, 640, YuvRange::kFull};
      raw.data = nv12.data();
      raw.size = nv12.size();
      ASSERT_TRUE((*writer)->Append(raw, 0).ok());
      raw.layout = RawFrameLayout{PixelFormat::kYuyv, 640, 480, 1288, YuvRange::kFull};
      raw.data = yuyv.data();
      raw.size = yuyv.size();
      ASSERT_TRUE((*writer)->Append(raw, 0).ok());
    }
    ASSERT_TRUE((*writer)->Finish().ok());
  }

  auto source = RecordedFrameSource::Open(recording);
  ASSERT_TRUE(source.ok()) << source.status().ToString();
  DiffStats gray, nv12_replicated, yuyv_replicated, nv12_fancy;
  for (const std::string& jpeg : jpegs) {
    auto nv12 = (*source)->Next();
    auto yuyv = (*source)->Next();
    ASSERT_TRUE(nv12.ok() && yuyv.ok());
    const std::vector<uint8_t> reference_gray = testing::LibjpegDecode(jpeg, 1, false);
    const std::vector<uint8_t> reference_rgb = testing::LibjpegDecode(jpeg, 3, false);
    gray.Add((*nv12)->gray, reference_gray);
    gray.Add((*yuyv)->gray, reference_gray);
    nv12_replicated.Add((*nv12)->rgb, reference_rgb);
    yuyv_replicated.Add((*yuyv)->rgb, reference_rgb);
    nv12_fancy.Add((*nv12)->rgb, testing::LibjpegDecode(jpeg, 3, true));
  }
  EXPECT_TRUE(IsEndOfStream((*source)->Next().status()));
  std::printf("93 frames 640x480, |ours - libjpeg|: gray max %d mean %.4f; NV12 RGB (libjpeg without fancy "
              "upsampling) max %d mean %.4f; YUYV RGB max %d mean %.4f; NV12 RGB vs libjpeg default fancy "
              "upsampling max %d mean %.4f\n",
              gray.max, gray.mean(), nv12_replicated.max, nv12_replicated.mean(), yuyv_replicated.max,
              yuyv_replicated.mean(), nv12_fancy.max, nv12_fancy.mean());
  // Gray is the JPEG's Y plane: exact.
  EXPECT_EQ(gray.max, 0);
  // Same samples, same chroma replication (do_fancy_upsampling = FALSE), libjpeg's constants and
  // rounding: at most a last-bit difference from a SIMD colour converter.
  EXPECT_LE(nv12_replicated.max, 1);
  EXPECT_LE(yuyv_replicated.max, 1);
  // Fancy upsampling interpolates chroma (9:3:3:1 weights), so it differs only where chroma
  // changes between neighbouring 2x2 blocks; a swapped Cb/Cr or a chroma shift of one block
  // would raise the mean far above this.
  EXPECT_LT(nv12_fancy.mean(), 1.0);
  std::remove(recording.c_str());
}

TEST(CameraRealFrames, RecordedMjpegMatchesFolderSourceAndTiming) {
  const std::vector<std::string> paths = FramePaths();
  const std::string recording = ::testing::TempDir() + "camera_real_mjpeg.frames";
  {
    auto writer = RecordedFramesWriter::Create(recording);
    ASSERT_TRUE(writer.ok());
    int64_t timestamp = 0;
    for (const std::string& path : paths) {
      const std::string jpeg = testing::ReadFileBytes(path);
      RawFrame raw;
      raw.layout = RawFrameLayout{PixelFormat::kMjpeg, 640, 480, 0, YuvRange::kFull};
      raw.data = reinterpret_cast<const uint8_t*>(jpeg.data());
      raw.size = jpeg.size();
      ASSERT_TRUE((*writer)->Append(raw, timestamp).ok());
      timestamp += 33333333;
    }
    ASSERT_TRUE((*writer)->Finish().ok());
  }
  auto recorded = RecordedFrameSource::Open(recording);
  auto folder = ImageFolderFrameSource::Open(kFrames);
  ASSERT_TRUE(recorded.ok() && folder.ok());
  int frames = 0;
  std::chrono::steady_clock::duration decode_time{};
  for (;;) {
    const auto start = std::chrono::steady_clock::now();
    auto a = (*recorded)->Next();
    decode_time += std::chrono::steady_clock::now() - start;
    auto b = (*folder)->Next();
    if (!a.ok()) {
      EXPECT_TRUE(IsEndOfStream(a.status())) << a.status().ToString();
      EXPECT_TRUE(IsEndOfStream(b.status()));
      break;
    }
    ASSERT_TRUE(b.ok()) << b.status().ToString();
    EXPECT_EQ((*b)->name, std::filesystem::path(paths[static_cast<size_t>(frames)]).filename().string());
    // Recorded: 33333333 ns steps; folder: round(i * 1e9 / 30).
    EXPECT_NEAR(static_cast<double>((*a)->timestamp_ns), static_cast<double>((*b)->timestamp_ns), 100.0);
    EXPECT_TRUE(testing::SameViews((*a)->gray, (*b)->gray)) << frames;
    EXPECT_TRUE(testing::SameViews((*a)->rgb, (*b)->rgb)) << frames;
    ++frames;
  }
  EXPECT_EQ(frames, 93);
  std::printf("MJPEG 640x480 decode to gray + RGB through RecordedFrameSource: %.2f ms/frame\n",
              Milliseconds(decode_time) / frames);
  std::remove(recording.c_str());
}

}  // namespace
}  // namespace reconar
