// The image-folder source, OpenFrameSource's dispatch, and the device sources' errors on a
// machine without cameras (V4L2 and libcamera; both tests also pass where a camera exists).
#include <png.h>
#include <gtest/gtest.h>

#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "platform/camera/image_folder_source.h"
#include "platform/camera/recorded_frames.h"
#include "tests/platform/camera/camera_fixture.h"
#include "tests/platform/camera/jpeg_reference.h"
#ifdef RECONAR_HAVE_V4L2
#include "platform/camera/v4l2_source.h"
#endif
#ifdef RECONAR_HAVE_LIBCAMERA
#include "platform/camera/libcamera_source.h"
#endif

namespace reconar {
namespace {

const std::string kFixture = testing::CameraFixturePath();

void WriteBytes(const std::string& path, const std::string& bytes) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
}

TEST(ImageFolderSource, EmptyOrMissingFolderIsNotFound) {
  const std::string empty = testing::FreshCameraTestDirectory("sources_empty");
  WriteBytes(empty + "/notes.txt", "not an image");
  auto source = ImageFolderFrameSource::Open(empty);
  ASSERT_FALSE(source.ok());
  EXPECT_EQ(source.status().code(), StatusCode::kNotFound);
  EXPECT_NE(source.status().message().find(empty), std::string::npos);
  EXPECT_NE(source.status().message().find("no .jpg/.jpeg/.png images"), std::string::npos);
  EXPECT_EQ(ImageFolderFrameSource::Open(empty + "/nope").status().code(), StatusCode::kNotFound);
}

// Numbered frames come in the order they were numbered, padded or not (frame_10 after frame_9).
TEST(ImageFolderSource, NumberedFramesComeInTheirNumbersOrder) {
  const std::string folder = testing::FreshCameraTestDirectory("sources_numbered");
  const std::string jpeg = testing::RecordPayload(testing::ReadFileBytes(kFixture), 0);
  for (const char* name : {"frame_10.jpg", "frame_2.jpg", "frame_1.jpg", "frame_100.jpg", "frame_9.jpg"})
    WriteBytes(folder + "/" + name, jpeg);
  auto source = ImageFolderFrameSource::Open(folder);
  ASSERT_TRUE(source.ok()) << source.status().ToString();
  EXPECT_EQ((*source)->file_names(),
            (std::vector<std::string>{"frame_1.jpg", "frame_2.jpg", "frame_9.jpg", "frame_10.jpg", "frame_100.jpg"}));
}

// The folder's JPEG decodes to exactly the recording's MJPEG frame (same bytes, same path), a
// PNG of those pixels to the same RGB, files in name order, and a broken file is named.
TEST(ImageFolderSource, JpegAndPngMatchTheRecordedMjpegFrame) {
  auto recorded = RecordedFrameSource::Open(kFixture);
  ASSERT_TRUE(recorded.ok());
  auto mjpeg = (*recorded)->Next();
  ASSERT_TRUE(mjpeg.ok());

  const std::string folder = testing::FreshCameraTestDirectory("sources_images");
  WriteBytes(folder + "/b.JPG", testing::RecordPayload(testing::ReadFileBytes(kFixture), 0));
  std::vector<uint8_t> packed(static_cast<size_t>((*mjpeg)->rgb.width) * (*mjpeg)->rgb.height);
  for (int y = 0; y < (*mjpeg)->rgb.height; ++y) {
    std::memcpy(&packed[static_cast<size_t>(y) * (*mjpeg)->rgb.width], (*mjpeg)->rgb.row(y), (*mjpeg)->rgb.width);
  }
  png_image png{};
  png.version = PNG_IMAGE_VERSION;
  png.width = 320;
  png.height = 240;
  png.format = PNG_FORMAT_RGB;
  ASSERT_NE(png_image_write_to_file(&png, (folder + "/c.png").c_str(), 0, packed.data(), 0, nullptr), 0);
  WriteBytes(folder + "/d.jpeg", testing::RecordPayload(testing::ReadFileBytes(kFixture), 0).substr(0, 3000));  // truncated
  WriteBytes(folder + "/a.jpg", testing::RecordPayload(testing::ReadFileBytes(kFixture), 0));

  FrameSourceOptions options;
  options.folder_fps = 10;
  auto source = ImageFolderFrameSource::Open(folder, options);
  ASSERT_TRUE(source.ok()) << source.status().ToString();
  EXPECT_EQ((*source)->file_names(), (std::vector<std::string>{"a.jpg", "b.JPG", "c.png", "d.jpeg"}));
  auto a = (*source)->Next();
  ASSERT_TRUE(a.ok()) << a.status().ToString();
  EXPECT_EQ((*a)->name, "a.jpg");
  EXPECT_TRUE(testing::SameViews((*a)->gray, (*mjpeg)->gray));
  EXPECT_TRUE(testing::SameViews((*a)->rgb, (*mjpeg)->rgb));
  a->reset();
  auto b = (*source)->Next();
  ASSERT_TRUE(b.ok());
  EXPECT_EQ((*b)->timestamp_ns, 100000000);
  b->reset();
  auto c = (*source)->Next();
  ASSERT_TRUE(c.ok()) << c.status().ToString();
  EXPECT_EQ((*c)->name, "c.png");
  EXPECT_TRUE(testing::SameViews((*c)->rgb, (*mjpeg)->rgb));
  c->reset();
  auto d = (*source)->Next();
  ASSERT_FALSE(d.ok());
  EXPECT_EQ(d.status().code(), StatusCode::kCorruptData);
  EXPECT_NE(d.status().message().find("d.jpeg: invalid JPEG data"), std::string::npos) << d.status().message();
  EXPECT_TRUE(IsEndOfStream((*source)->Next().status()));
}

TEST(OpenFrameSource, DispatchesOnTheSpecification) {
  auto recorded = OpenFrameSource(kFixture);
  ASSERT_TRUE(recorded.ok()) << recorded.status().ToString();
  EXPECT_NE((*recorded)->Describe().find("recording"), std::string::npos);
  const std::string folder = testing::FreshCameraTestDirectory("sources_dispatch");
  WriteBytes(folder + "/x.jpg", testing::RecordPayload(testing::ReadFileBytes(kFixture), 0));
  auto images = OpenFrameSource(folder);
  ASSERT_TRUE(images.ok());
  EXPECT_EQ((*images)->Describe(), "folder " + folder + " (1 images)");

  EXPECT_EQ(OpenFrameSource("rtsp://camera").status().code(), StatusCode::kInvalidArgument);
  EXPECT_EQ(OpenFrameSource(folder + "/x.jpg").status().code(), StatusCode::kInvalidArgument);
  EXPECT_EQ(OpenFrameSource("libcamera:x").status().code(), StatusCode::kInvalidArgument);
  FrameSourceOptions bad;
  bad.buffer_count = 0;
  EXPECT_EQ(OpenFrameSource(kFixture, bad).status().code(), StatusCode::kInvalidArgument);
}

TEST(V4L2Source, MissingDeviceIsNotFoundNamingTheDevice) {
  for (const std::string spec : {"/dev/video9", "v4l2:/dev/video9"}) {
    auto source = OpenFrameSource(spec);
    ASSERT_FALSE(source.ok());
#ifdef RECONAR_HAVE_V4L2
    EXPECT_EQ(source.status().code(), StatusCode::kNotFound);
    EXPECT_EQ(source.status().message(), "/dev/video9: no such device");
#else
    EXPECT_EQ(source.status().code(), StatusCode::kUnsupported);
#endif
  }
}

#ifdef RECONAR_HAVE_V4L2
TEST(V4L2Source, NonVideoDeviceIsRefused) {
  auto source = V4L2FrameSource::Open("/dev/null");
  ASSERT_FALSE(source.ok());
  EXPECT_EQ(source.status().code(), StatusCode::kUnsupported);
  EXPECT_NE(source.status().message().find("/dev/null: not a V4L2 device"), std::string::npos)
      << source.status().message();
}
#endif

// Passes with or without a camera: with none the error is exact; with one, a frame arrives or
// the error is a clear device error (busy, timeout) rather than a crash.
TEST(LibcameraSource, OpensOrFailsClearly) {
  FrameSourceOptions options;
  options.timeout_ms = 3000;
  auto source = OpenFrameSource("libcamera", options);
#ifdef RECONAR_HAVE_LIBCAMERA
  if (!source.ok()) {
    const Status& status = source.status();
    if (status.code() == StatusCode::kNotFound) {
      EXPECT_EQ(status.message(), "libcamera: no cameras found");
    } else {
      EXPECT_EQ(status.message().rfind("libcamera: ", 0), 0u) << status.message();
    }
    return;
  }
  auto frame = (*source)->Next();
  if (frame.ok()) {
    EXPECT_GT((*frame)->width, 0);
  } else {
    EXPECT_EQ(frame.status().code(), StatusCode::kIoError) << frame.status().ToString();
  }
#else
  EXPECT_EQ(source.status().code(), StatusCode::kUnsupported);
#endif
}

}  // namespace
}  // namespace reconar
