// Builds tests/platform/camera/data/tag_320x240.frames, the recorded fixture of the unit tests:
//   frame 0  MJPG  a 320x240 crop (x 176.., y 176..) of apriltag_ar_video_id12/frames/frame0000.jpg
//                  (libjpeg decode) re-encoded by libjpeg as baseline 4:2:0 JFIF, quality 90
//   frame 1  NV12  that JPEG's own Y/Cb/Cr planes (libjpeg raw-data output), bytes_per_line 336
//   frame 2  YUYV  the same planes, chroma rows duplicated to 4:2:2, bytes_per_line 645 (odd)
// all full range (JFIF), timestamps 0, 33333333, 66666667 ns.
// Usage: make_camera_fixture SHARED_DATA_DIR OUTPUT.frames
#include <cstdio>
#include <string>

#include "platform/camera/recorded_frames.h"
#include "tests/platform/camera/jpeg_reference.h"

namespace {

constexpr int kWidth = 320;
constexpr int kHeight = 240;
constexpr int kCropX = 176;
constexpr int kCropY = 176;

int Fail(const std::string& message) {
  std::fprintf(stderr, "make_camera_fixture: %s\n", message.c_str());
  return 1;
}

}  // namespace

int main(int argc, char** argv) {
  using namespace reconar;
  if (argc != 3) return Fail("usage: make_camera_fixture SHARED_DATA_DIR OUTPUT.frames");
  const std::string source = std::string(argv[1]) + "/apriltag_ar_video_id12/frames/frame0000.jpg";
  const std::string original = testing::ReadFileBytes(source);
  if (original.empty()) return Fail("cannot read " + source);
  int width = 0;
  int height = 0;
  const std::vector<uint8_t> rgb = testing::LibjpegDecode(original, 3, true, &width, &height);
  if (width < kCropX + kWidth || height < kCropY + kHeight) return Fail("source frame too small");
  std::vector<uint8_t> crop(static_cast<size_t>(kWidth) * kHeight * 3);
  for (int y = 0; y < kHeight; ++y) {
    for (int x = 0; x < 3 * kWidth; ++x) {
      crop[static_cast<size_t>(y) * kWidth * 3 + x] = rgb[(static_cast<size_t>(y + kCropY) * width + kCropX) * 3 + x];
    }
  }
  const std::string jpeg = testing::LibjpegEncodeRgb(crop, kWidth, kHeight, 90);
  testing::YcbcrPlanes planes;
  std::string reason;
  if (!testing::ReadYcbcr420Planes(jpeg, &planes, &reason)) return Fail(reason);
  const int nv12_pitch = 336;
  const int yuyv_pitch = 645;
  const std::vector<uint8_t> nv12 = testing::PackNv12(planes, nv12_pitch);
  const std::vector<uint8_t> yuyv = testing::PackYuyv(planes, yuyv_pitch);

  auto writer = RecordedFramesWriter::Create(argv[2]);
  if (!writer.ok()) return Fail(writer.status().ToString());
  RawFrame frame;
  frame.layout = RawFrameLayout{PixelFormat::kMjpeg, kWidth, kHeight, 0, YuvRange::kFull};
  frame.data = reinterpret_cast<const uint8_t*>(jpeg.data());
  frame.size = jpeg.size();
  Status status = (*writer)->Append(frame, 0);
  frame.layout = RawFrameLayout{PixelFormat::kNv12, kWidth, kHeight, nv12_pitch, YuvRange::kFull};
  frame.data = nv12.data();
  frame.size = nv12.size();
  if (status.ok()) status = (*writer)->Append(frame, 33333333);
  frame.layout = RawFrameLayout{PixelFormat::kYuyv, kWidth, kHeight, yuyv_pitch, YuvRange::kFull};
  frame.data = yuyv.data();
  frame.size = yuyv.size();
  if (status.ok()) status = (*writer)->Append(frame, 66666667);
  if (status.ok()) status = (*writer)->Finish();
  if (!status.ok()) return Fail(status.ToString());
  std::printf("wrote %s: MJPG %zu bytes, NV12 %zu bytes, YUYV %zu bytes\n", argv[2], jpeg.size(), nv12.size(),
              yuyv.size());
  return 0;
}
