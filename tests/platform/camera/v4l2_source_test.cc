// V4L2FrameSource's streaming path on a machine without a camera: the V4L2 device double
// (v4l2_device_double.h) serves the committed recording's frames through the V4L2 ioctl and mmap
// interface, and the source's frames must be exactly those the recording decodes to; a damaged
// buffer is skipped, a disconnect (ENODEV) ends the stream with a clear error, and the source's
// own recording holds what the device delivered.
#include "platform/camera/v4l2_source.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <string>

#include "platform/camera/frame_source.h"
#include "platform/camera/recorded_frames.h"
#include "tests/platform/camera/camera_fixture.h"
#include "tests/platform/camera/jpeg_reference.h"
#include "tests/platform/camera/v4l2_device_double.h"

namespace reconar {
namespace {

const std::string kFixture = testing::CameraFixturePath();

// The fixture's record `index` decoded by the recording's own source, kept open for its views.
struct RecordedReference {
  std::unique_ptr<RecordedFrameSource> source;
  FrameHandle frame;
};
RecordedReference DecodeRecord(int index) {
  RecordedReference reference;
  auto source = RecordedFrameSource::Open(kFixture);
  EXPECT_TRUE(source.ok()) << source.status().ToString();
  if (!source.ok()) return reference;
  reference.source = std::move(*source);
  for (int i = 0; i <= index; ++i) {
    auto next = reference.source->Next();
    EXPECT_TRUE(next.ok()) << next.status().ToString();
    if (!next.ok()) return reference;
    reference.frame = std::move(*next);
  }
  return reference;
}

class V4L2SourceTest : public ::testing::Test {
 protected:
  void TearDown() override { testing::RemoveV4L2DeviceDouble(); }

  // A device serving the fixture's record `record` over and over, gone after `frames`.
  std::string InstallDevice(const std::string& name, int record, int frames) {
    testing::V4L2DeviceDoubleOptions device;
    device.device_path = testing::FreshCameraTestDirectory("v4l2_" + name) + "/video0";
    device.recording = kFixture;
    device.first_frame = record;
    device.num_frames = 1;
    device.disconnect_after = frames;
    device.damaged_frames = damaged_frames_;
    const Status installed = testing::InstallV4L2DeviceDouble(device);
    EXPECT_TRUE(installed.ok()) << installed.ToString();
    return device.device_path;
  }

  std::vector<int> damaged_frames_;
};

// MJPG, NV12 and YUYV (the fixture's three records): each frame the source takes from the device's
// mmap'ed buffers is the frame the recording decodes to, numbered by the driver's sequence, and the
// camera pulled out after four frames ends the stream with an error naming the device.
TEST_F(V4L2SourceTest, DeliversTheDevicesFramesAsTheRecordingDecodesThemUntilItDisconnects) {
  for (int record = 0; record < 3; ++record) {
    SCOPED_TRACE("record " + std::to_string(record));
    const RecordedReference reference = DecodeRecord(record);
    ASSERT_TRUE(reference.frame);
    const std::string device = InstallDevice("formats", record, 4);
    auto source = OpenFrameSource("v4l2:" + device);
    ASSERT_TRUE(source.ok()) << source.status().ToString();
    const std::string description = (*source)->Describe();
    EXPECT_NE(description.find("V4L2 " + device + " (reconar-double, recorded frames) 320x240 " +
                               PixelFormatName(reference.frame->source_format)),
              std::string::npos)
        << description;
    EXPECT_GE((*source)->buffer_count(), 2);
    for (int i = 0; i < 4; ++i) {
      auto frame = (*source)->Next();
      ASSERT_TRUE(frame.ok()) << frame.status().ToString();
      EXPECT_EQ((*frame)->index, i);
      EXPECT_EQ((*frame)->source_format, reference.frame->source_format);
      EXPECT_TRUE(testing::SameViews((*frame)->gray, reference.frame->gray));
      EXPECT_TRUE(testing::SameViews((*frame)->rgb, reference.frame->rgb));
    }
    auto gone = (*source)->Next();
    ASSERT_FALSE(gone.ok());
    EXPECT_EQ(gone.status().code(), StatusCode::kIoError);
    EXPECT_EQ(gone.status().message(), device + ": camera disconnected");
    EXPECT_FALSE(IsEndOfStream(gone.status()));
    EXPECT_TRUE(testing::V4L2DeviceDoubleState().gone);
    EXPECT_EQ(testing::V4L2DeviceDoubleState().frames_dequeued, 4);
  }
}

// A buffer the driver flags V4L2_BUF_FLAG_ERROR goes straight back to it; the next frame comes.
TEST_F(V4L2SourceTest, SkipsABufferTheDriverFlagsAsDamaged) {
  damaged_frames_ = {1, 2};
  const std::string device = InstallDevice("damaged", 2, 6);
  auto source = V4L2FrameSource::Open(device);
  ASSERT_TRUE(source.ok()) << source.status().ToString();
  std::vector<int64_t> indices;
  for (;;) {
    auto frame = (*source)->Next();
    if (!frame.ok()) {
      EXPECT_EQ(frame.status().message(), device + ": camera disconnected");
      break;
    }
    indices.push_back((*frame)->index);
  }
  EXPECT_EQ(indices, (std::vector<int64_t>{0, 3, 4, 5}));
}

// A frame held by the caller keeps its buffer from the driver; once every buffer is held, Next()
// says so instead of waiting for a frame that cannot come.
TEST_F(V4L2SourceTest, HeldFramesKeepTheirBuffers) {
  const RecordedReference reference = DecodeRecord(1);
  const std::string device = InstallDevice("held", 1, 100);
  FrameSourceOptions options;
  options.buffer_count = 3;
  auto source = V4L2FrameSource::Open(device, options);
  ASSERT_TRUE(source.ok()) << source.status().ToString();
  ASSERT_EQ((*source)->buffer_count(), 3);
  std::vector<FrameHandle> held;
  for (int i = 0; i < 3; ++i) {
    auto frame = (*source)->Next();
    ASSERT_TRUE(frame.ok()) << frame.status().ToString();
    held.push_back(std::move(*frame));
  }
  auto refused = (*source)->Next();
  EXPECT_EQ(refused.status().code(), StatusCode::kFailedPrecondition);
  for (const FrameHandle& frame : held) EXPECT_TRUE(testing::SameViews(frame->gray, reference.frame->gray));
  held.erase(held.begin());
  auto next = (*source)->Next();
  ASSERT_TRUE(next.ok()) << next.status().ToString();
  EXPECT_EQ((*next)->index, 3);
}

// FrameSourceOptions::record_path: the device's buffers as delivered, a .frames file the recorded
// source replays to the same frames.
TEST_F(V4L2SourceTest, RecordsTheBuffersTheDeviceDelivered) {
  const std::string device = InstallDevice("record", 2, 3);
  const std::string recording = testing::FreshCameraTestDirectory("v4l2_record_out") + "/session.frames";
  FrameSourceOptions options;
  options.record_path = recording;
  {
    auto source = V4L2FrameSource::Open(device, options);
    ASSERT_TRUE(source.ok()) << source.status().ToString();
    for (int i = 0; i < 3; ++i) ASSERT_TRUE((*source)->Next().ok());
    EXPECT_FALSE((*source)->Next().ok());
  }
  const std::string recorded = testing::ReadFileBytes(recording);
  const std::string expected = testing::RecordPayload(testing::ReadFileBytes(kFixture), 2);
  for (int i = 0; i < 3; ++i) EXPECT_EQ(testing::RecordPayload(recorded, i), expected) << "frame " << i;
  EXPECT_EQ(testing::RecordOffset(recorded, 3), recorded.size());
}

// A camera gone before it streams: the open fails naming the device.
TEST_F(V4L2SourceTest, ACameraGoneBeforeTheFirstFrameIsNamed) {
  const std::string device = InstallDevice("gone", 0, 0);
  auto source = OpenFrameSource("v4l2:" + device);
  ASSERT_TRUE(source.ok()) << source.status().ToString();
  auto frame = (*source)->Next();
  EXPECT_EQ(frame.status().message(), device + ": camera disconnected");
  // Every later request fails as well, and the source's close does not hang on the dead device.
  EXPECT_EQ((*source)->Next().status().message(), device + ": camera disconnected");
}

}  // namespace
}  // namespace reconar
