#include "platform/camera/recorded_frames.h"

#include <gtest/gtest.h>

#include <cstdio>
#include <cstring>
#include <fstream>
#include <string>
#include <vector>

#include "tests/platform/camera/camera_fixture.h"
#include "tests/platform/camera/jpeg_reference.h"

namespace reconar {
namespace {

const std::string kFixture = testing::CameraFixturePath();

std::string TempPath(const std::string& name) { return ::testing::TempDir() + "camera_recorded_" + name; }

void WriteBytes(const std::string& path, const std::string& bytes) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
}


struct Difference {
  int max = 0;
  double mean = 0;
};

Difference Compare(const ImageView<const uint8_t>& view, const std::vector<uint8_t>& packed) {
  Difference d;
  long total = 0;
  for (int y = 0; y < view.height; ++y) {
    for (int x = 0; x < view.width; ++x) {
      const int diff = std::abs(view.at(x, y) - packed[static_cast<size_t>(y) * view.width + x]);
      d.max = std::max(d.max, diff);
      total += diff;
    }
  }
  d.mean = static_cast<double>(total) / (static_cast<double>(view.width) * view.height);
  return d;
}

TEST(RecordedFrames, FixtureLayoutsDecodeToLibjpegPixels) {
  auto source = RecordedFrameSource::Open(kFixture);
  ASSERT_TRUE(source.ok()) << source.status().ToString();
  auto mjpeg = (*source)->Next();
  auto nv12 = (*source)->Next();
  auto yuyv = (*source)->Next();
  ASSERT_TRUE(mjpeg.ok()) << mjpeg.status().ToString();
  ASSERT_TRUE(nv12.ok()) << nv12.status().ToString();
  ASSERT_TRUE(yuyv.ok()) << yuyv.status().ToString();
  EXPECT_EQ((*mjpeg)->source_format, PixelFormat::kMjpeg);
  EXPECT_EQ((*nv12)->source_format, PixelFormat::kNv12);
  EXPECT_EQ((*yuyv)->source_format, PixelFormat::kYuyv);
  EXPECT_EQ((*mjpeg)->name, "tag_320x240.frames#0");
  EXPECT_EQ((*yuyv)->index, 2);
  EXPECT_EQ((*nv12)->timestamp_ns, 33333333);
  EXPECT_EQ((*nv12)->width, 320);
  EXPECT_EQ((*nv12)->height, 240);
  // NV12's gray is the recorded Y plane itself (zero copy: the recording's 336-byte pitch).
  EXPECT_EQ((*nv12)->gray.stride, 336);
  EXPECT_EQ((*mjpeg)->gray.stride, 320);

  // All three carry the same Y samples, and NV12 / YUYV the same chroma.
  EXPECT_TRUE(testing::SameViews((*mjpeg)->gray, (*nv12)->gray));
  EXPECT_TRUE(testing::SameViews((*yuyv)->gray, (*nv12)->gray));
  EXPECT_TRUE(testing::SameViews((*yuyv)->rgb, (*nv12)->rgb));

  // Against libjpeg's own decode of the same JPEG.
  const std::string jpeg = testing::RecordPayload(testing::ReadFileBytes(kFixture), 0);
  const Difference gray = Compare((*nv12)->gray, testing::LibjpegDecode(jpeg, 1, false));
  const Difference replicated = Compare((*nv12)->rgb, testing::LibjpegDecode(jpeg, 3, false));
  const Difference fancy = Compare((*mjpeg)->rgb, testing::LibjpegDecode(jpeg, 3, true));
  const Difference raw_vs_fancy = Compare((*nv12)->rgb, testing::LibjpegDecode(jpeg, 3, true));
  std::printf("gray max %d mean %.4f; NV12 RGB vs libjpeg (replicated chroma) max %d mean %.4f; MJPEG RGB vs "
              "libjpeg (fancy upsampling) max %d mean %.4f; NV12 vs fancy max %d mean %.3f\n",
              gray.max, gray.mean, replicated.max, replicated.mean, fancy.max, fancy.mean, raw_vs_fancy.max,
              raw_vs_fancy.mean);
  EXPECT_EQ(gray.max, 0);
  // Same samples, same chroma replication, libjpeg's own fixed-point constants: equal up to a
  // possible last-bit difference of libjpeg-turbo's SIMD colour conversion.
  EXPECT_LE(replicated.max, 1);
  EXPECT_LE(fancy.max, 1);

  EXPECT_TRUE(IsEndOfStream((*source)->Next().status()));
}

TEST(RecordedFrames, HoldingEveryBufferIsAnErrorNotADeadlock) {
  FrameSourceOptions options;
  options.buffer_count = 2;
  auto source = RecordedFrameSource::Open(kFixture, options);
  ASSERT_TRUE(source.ok());
  auto a = (*source)->Next();
  auto b = (*source)->Next();
  ASSERT_TRUE(a.ok() && b.ok());
  auto c = (*source)->Next();
  ASSERT_FALSE(c.ok());
  EXPECT_EQ(c.status().code(), StatusCode::kFailedPrecondition);
  EXPECT_NE(c.status().message().find("all 2 frame buffers are held"), std::string::npos) << c.status().message();
  const int a_buffer = (*a)->buffer;
  a->reset();
  auto d = (*source)->Next();
  ASSERT_TRUE(d.ok()) << d.status().ToString();
  EXPECT_EQ((*d)->index, 2);
  EXPECT_EQ((*d)->buffer, a_buffer);
}

// A FrameHandle gives its buffer back when it is destroyed, reset or assigned over, and a move
// passes the buffer on without giving it back.
TEST(RecordedFrames, FrameHandlesGiveTheirBufferBack) {
  FrameSourceOptions options;
  options.buffer_count = 1;
  auto source = RecordedFrameSource::Open(kFixture, options);
  ASSERT_TRUE(source.ok());
  {
    auto first = (*source)->Next();
    ASSERT_TRUE(first.ok());
    EXPECT_EQ((*source)->frames_held(), 1);
    EXPECT_EQ((*source)->Next().status().code(), StatusCode::kFailedPrecondition);
  }
  EXPECT_EQ((*source)->frames_held(), 0);
  auto second = (*source)->Next();
  ASSERT_TRUE(second.ok()) << second.status().ToString();
  EXPECT_EQ((*second)->index, 1);
  FrameHandle moved = std::move(*second);
  EXPECT_FALSE(*second);
  ASSERT_TRUE(moved);
  EXPECT_EQ(moved->index, 1);
  EXPECT_EQ((*source)->frames_held(), 1);
  moved = FrameHandle();
  EXPECT_FALSE(moved);
  EXPECT_EQ((*source)->frames_held(), 0);
  auto third = (*source)->Next();
  ASSERT_TRUE(third.ok()) << third.status().ToString();
  EXPECT_EQ((*third)->index, 2);
}

TEST(RecordedFramesDeathTest, AnEmptyHandleHasNoFrame) {
  FrameHandle empty;
  EXPECT_FALSE(empty);
  EXPECT_DEATH((void)empty->index, "an empty FrameHandle has no frame");
}

TEST(RecordedFramesDeathTest, DestroyingASourceWhileAFrameIsHeldIsAProgrammerError) {
  EXPECT_DEATH(
      {
        auto source = RecordedFrameSource::Open(kFixture);
        RECONAR_CHECK(source.ok());
        auto frame = (*source)->Next();
        RECONAR_CHECK(frame.ok());
        FrameHandle held = std::move(*frame);
        source->reset();
      },
      "still held");
}

TEST(RecordedFrames, WithoutRgbOnlyGray) {
  FrameSourceOptions options;
  options.want_rgb = false;
  auto source = RecordedFrameSource::Open(kFixture, options);
  ASSERT_TRUE(source.ok());
  for (int i = 0; i < 3; ++i) {
    auto frame = (*source)->Next();
    ASSERT_TRUE(frame.ok()) << frame.status().ToString();
    EXPECT_TRUE((*frame)->rgb.empty());
    EXPECT_EQ((*frame)->gray.width, 320);
  }
}

// Drains a source; returns the final status and counts the frames delivered.
Status Drain(RecordedFrameSource* source, int* frames) {
  *frames = 0;
  for (;;) {
    auto frame = source->Next();
    if (!frame.ok()) return frame.status();
    ++*frames;
  }
}

TEST(RecordedFrames, TruncatedRecordingsAreCorruptDataNamingFileAndFrame) {
  const std::string file = testing::ReadFileBytes(kFixture);
  const size_t second_record = testing::RecordOffset(file, 1);
  const std::string path = TempPath("truncated.frames");

  WriteBytes(path, file.substr(0, second_record + 10));  // inside frame 1's record header
  auto source = RecordedFrameSource::Open(path);
  ASSERT_TRUE(source.ok());
  int frames = 0;
  Status status = Drain(source->get(), &frames);
  EXPECT_EQ(frames, 1);
  EXPECT_EQ(status.code(), StatusCode::kCorruptData);
  EXPECT_NE(status.message().find(path), std::string::npos) << status.message();
  EXPECT_NE(status.message().find("frame 1: truncated record header"), std::string::npos) << status.message();

  WriteBytes(path, file.substr(0, file.size() - 1000));  // inside frame 2's payload
  source = RecordedFrameSource::Open(path);
  ASSERT_TRUE(source.ok());
  status = Drain(source->get(), &frames);
  EXPECT_EQ(frames, 2);
  EXPECT_EQ(status.code(), StatusCode::kCorruptData);
  EXPECT_NE(status.message().find("frame 2: truncated payload"), std::string::npos) << status.message();

  // Every cut point: never a crash, always end of stream or CorruptData.
  for (size_t cut = 0; cut < file.size(); cut += 2003) {
    WriteBytes(path, file.substr(0, cut));
    auto cut_source = RecordedFrameSource::Open(path);
    if (!cut_source.ok()) {
      EXPECT_EQ(cut_source.status().code(), StatusCode::kCorruptData) << cut;
      continue;
    }
    status = Drain(cut_source->get(), &frames);
    EXPECT_TRUE(IsEndOfStream(status) || status.code() == StatusCode::kCorruptData) << cut << status.ToString();
  }
  std::remove(path.c_str());
}

TEST(RecordedFrames, DamagedJpegPayloadIsCorruptDataAndSkipped) {
  std::string file = testing::ReadFileBytes(kFixture);
  const uint32_t jpeg_size = testing::U32At(file, kRecordedFramesHeaderBytes + 32);
  // Cut the JPEG to half but keep the container consistent: payload_size shrinks accordingly.
  const size_t payload_at = kRecordedFramesHeaderBytes + kRecordedFrameRecordBytes;
  file.erase(payload_at + jpeg_size / 2, jpeg_size - jpeg_size / 2);
  const uint32_t half = jpeg_size / 2;
  for (int i = 0; i < 4; ++i) file[kRecordedFramesHeaderBytes + 32 + i] = static_cast<char>(half >> (8 * i));
  const std::string path = TempPath("damaged_jpeg.frames");
  WriteBytes(path, file);
  auto source = RecordedFrameSource::Open(path);
  ASSERT_TRUE(source.ok());
  auto first = (*source)->Next();
  ASSERT_FALSE(first.ok());
  EXPECT_EQ(first.status().code(), StatusCode::kCorruptData);
  EXPECT_NE(first.status().message().find("frame 0: invalid JPEG data"), std::string::npos)
      << first.status().message();
  auto second = (*source)->Next();  // the container is intact: playback goes on
  ASSERT_TRUE(second.ok()) << second.status().ToString();
  EXPECT_EQ((*second)->index, 1);
  std::remove(path.c_str());
}

TEST(RecordedFrames, BadFilesAreClearErrors) {
  auto missing = RecordedFrameSource::Open(TempPath("missing.frames"));
  EXPECT_EQ(missing.status().code(), StatusCode::kNotFound);
  const std::string path = TempPath("bad.frames");
  WriteBytes(path, "RECONAR-FRAMES 2 and more bytes");
  auto bad_magic = RecordedFrameSource::Open(path);
  EXPECT_EQ(bad_magic.status().code(), StatusCode::kCorruptData);
  EXPECT_NE(bad_magic.status().message().find("RECONAR-FRAMES 1"), std::string::npos);
  WriteBytes(path, "");
  EXPECT_EQ(RecordedFrameSource::Open(path).status().code(), StatusCode::kCorruptData);

  std::string file = testing::ReadFileBytes(kFixture);
  file[kRecordedFramesHeaderBytes + 4] = 'X';  // fourcc of frame 0
  WriteBytes(path, file);
  auto source = RecordedFrameSource::Open(path);
  ASSERT_TRUE(source.ok());
  auto frame = (*source)->Next();
  EXPECT_EQ(frame.status().code(), StatusCode::kCorruptData);
  EXPECT_NE(frame.status().message().find("frame 0: unknown pixel format"), std::string::npos);

  file = testing::ReadFileBytes(kFixture);
  file[kRecordedFramesHeaderBytes + 0] = 'G';  // record tag
  WriteBytes(path, file);
  source = RecordedFrameSource::Open(path);
  ASSERT_TRUE(source.ok());
  EXPECT_NE((*source)->Next().status().message().find("frame 0: bad record tag"), std::string::npos);
  std::remove(path.c_str());
}

TEST(RecordedFrames, WriterRoundTripWithPassthroughAndLimitedRange) {
  const std::string path = TempPath("roundtrip.frames");
  std::remove(path.c_str());
  // 4x2 limited-range YUYV: black, white, and neutral grey 126 (→ 128 after range expansion).
  const std::vector<uint8_t> yuyv = {16, 128, 235, 128, 0, 0, 126, 128, 126, 128, 0, 0};
  const std::vector<uint8_t> gray8 = {1, 2, 3, 9, 4, 5, 6, 9};  // 3x2 at pitch 4
  const std::vector<uint8_t> rgb24 = {10, 20, 30, 40, 50, 60, 7, 70, 80, 90, 100, 110, 120, 7};  // 2x2 at pitch 7
  {
    auto writer = RecordedFramesWriter::Create(path);
    ASSERT_TRUE(writer.ok()) << writer.status().ToString();
    RawFrame raw;
    raw.layout = RawFrameLayout{PixelFormat::kYuyv, 2, 2, 6, YuvRange::kLimited};
    raw.data = yuyv.data();
    raw.size = yuyv.size();
    ASSERT_TRUE((*writer)->Append(raw, -5).ok());
    raw.layout = RawFrameLayout{PixelFormat::kGray8, 3, 2, 4, YuvRange::kFull};
    raw.data = gray8.data();
    raw.size = gray8.size();
    ASSERT_TRUE((*writer)->Append(raw, 1LL << 40).ok());
    raw.layout = RawFrameLayout{PixelFormat::kRgb24, 2, 2, 7, YuvRange::kFull};
    raw.data = rgb24.data();
    raw.size = rgb24.size();
    ASSERT_TRUE((*writer)->Append(raw, 3).ok());
    raw.layout = RawFrameLayout{PixelFormat::kYuyv, 3, 2, 6, YuvRange::kFull};  // odd YUYV width
    EXPECT_EQ((*writer)->Append(raw, 4).code(), StatusCode::kInvalidArgument);
    EXPECT_EQ((*writer)->frames_written(), 3);
    std::FILE* unfinished = std::fopen(path.c_str(), "rb");
    EXPECT_EQ(unfinished, nullptr) << "nothing at the final path before Finish()";
    if (unfinished != nullptr) std::fclose(unfinished);
    ASSERT_TRUE((*writer)->Finish().ok());
  }
  FrameSourceOptions options;
  options.gray_range = GrayRange::kFull;
  auto source = RecordedFrameSource::Open(path, options);
  ASSERT_TRUE(source.ok());
  auto yuyv_frame = (*source)->Next();
  ASSERT_TRUE(yuyv_frame.ok()) << yuyv_frame.status().ToString();
  EXPECT_EQ((*yuyv_frame)->timestamp_ns, -5);
  EXPECT_EQ((*yuyv_frame)->gray.at(0, 0), 0);
  EXPECT_EQ((*yuyv_frame)->gray.at(1, 0), 255);
  EXPECT_EQ((*yuyv_frame)->gray.at(1, 1), 128);
  EXPECT_EQ((*yuyv_frame)->rgb.at(3, 0), 255);
  // The next frame has another size: its buffers can only be resized once no frame is held.
  EXPECT_EQ((*source)->Next().status().code(), StatusCode::kFailedPrecondition);
  yuyv_frame->reset();
  auto gray_frame = (*source)->Next();
  ASSERT_TRUE(gray_frame.ok()) << gray_frame.status().ToString();
  EXPECT_EQ((*gray_frame)->timestamp_ns, 1LL << 40);
  EXPECT_EQ((*gray_frame)->gray.stride, 4);  // zero copy
  EXPECT_EQ((*gray_frame)->gray.at(2, 1), 6);
  EXPECT_EQ((*gray_frame)->rgb.at(8, 1), 6);
  gray_frame->reset();
  auto rgb_frame = (*source)->Next();
  ASSERT_TRUE(rgb_frame.ok());
  EXPECT_EQ((*rgb_frame)->rgb.stride, 7);  // zero copy
  EXPECT_EQ((*rgb_frame)->rgb.at(5, 1), 120);
  EXPECT_EQ((*rgb_frame)->gray.at(0, 0), (19595 * 10 + 38470 * 20 + 7471 * 30 + 32768) >> 16);
  EXPECT_TRUE(IsEndOfStream((*source)->Next().status()));
  std::remove(path.c_str());
}

TEST(RecordedFrames, AbandonedWriterLeavesNoFile) {
  const std::string path = TempPath("abandoned.frames");
  std::remove(path.c_str());
  {
    auto writer = RecordedFramesWriter::Create(path);
    ASSERT_TRUE(writer.ok());
  }
  std::FILE* file = std::fopen(path.c_str(), "rb");
  EXPECT_EQ(file, nullptr);
  if (file != nullptr) std::fclose(file);
}

}  // namespace
}  // namespace reconar
