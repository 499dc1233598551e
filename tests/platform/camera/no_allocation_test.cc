// After the first frame, Next() and the FrameHandle's release on a recording of raw YUYV / NV12 buffers makes no
// heap allocation (the steady state of a tracking loop fed by a camera), nor on a V4L2 device
// delivering them (the V4L2 device double, v4l2_device_double.h).
#include <gtest/gtest.h>

#include <cstdio>
#include <fstream>
#include <string>

#include "platform/camera/recorded_frames.h"
#include "tests/platform/camera/camera_fixture.h"
#include "tests/platform/camera/jpeg_reference.h"
#include "tests/support/allocation_counter.h"
#ifdef RECONAR_HAVE_V4L2
#include "platform/camera/v4l2_source.h"
#include "tests/platform/camera/v4l2_device_double.h"
#endif

namespace reconar {
namespace {

const std::string kFixture = testing::CameraFixturePath();

// A recording of the fixture's NV12 and YUYV records (frames 1 and 2), repeated `pairs` times.
std::string MakeRawRecording(int pairs) {
  const std::string file = testing::ReadFileBytes(kFixture);
  const std::string raw_records = file.substr(testing::RecordOffset(file, 1));  // skip the MJPEG frame
  std::string out = file.substr(0, kRecordedFramesHeaderBytes);
  for (int i = 0; i < pairs; ++i) out += raw_records;
  const std::string path = ::testing::TempDir() + "camera_no_allocation.frames";
  std::ofstream(path, std::ios::binary | std::ios::trunc) << out;
  return path;
}

struct Loop {
  long allocations = -1;
  int frames = 0;
  bool all_ok = true;
};

// Takes a first frame (which sizes the buffers), then counts the allocations of up to `frames`
// more, each released at once.
Loop CountSteadyStateAllocations(FrameSource& source, int frames) {
  Loop loop;
  auto first = source.Next();
  EXPECT_TRUE(first.ok()) << first.status().ToString();
  if (!first.ok()) return loop;
  first->reset();
  testing::NoAllocationScope scope;
  for (int i = 0; i < frames; ++i) {
    Result<FrameHandle> frame = source.Next();
    if (!frame.ok()) {
      loop.all_ok = false;
      break;
    }
    ++loop.frames;
    frame->reset();
  }
  loop.allocations = scope.allocations();
  return loop;
}

TEST(CameraNoAllocation, RecordedYuyvAndNv12SteadyState) {
  const std::string path = MakeRawRecording(8);
  for (const bool want_rgb : {true, false}) {
    for (const GrayRange gray_range : {GrayRange::kAsDelivered, GrayRange::kFull}) {
      FrameSourceOptions options;
      options.want_rgb = want_rgb;
      options.gray_range = gray_range;
      auto source = RecordedFrameSource::Open(path, options);
      ASSERT_TRUE(source.ok()) << source.status().ToString();
      // Count allocations through the last frame, excluding the end-of-stream status.
      const Loop loop = CountSteadyStateAllocations(**source, 15);
      EXPECT_TRUE(loop.all_ok);
      EXPECT_EQ(loop.frames, 15);
      EXPECT_EQ(loop.allocations, 0) << "want_rgb " << want_rgb;
      EXPECT_TRUE(IsEndOfStream((*source)->Next().status()));
    }
  }
  std::remove(path.c_str());
}

#ifdef RECONAR_HAVE_V4L2
// 200 frames, so that a queue that grows in blocks would show; the double itself allocates nothing.
TEST(CameraNoAllocation, V4L2YuyvAndNv12SteadyState) {
  for (const int record : {1, 2}) {
    testing::V4L2DeviceDoubleOptions device;
    device.device_path = ::testing::TempDir() + "camera_no_allocation_video0";
    device.recording = kFixture;
    device.first_frame = record;
    device.num_frames = 1;
    device.disconnect_after = 201;
    ASSERT_TRUE(testing::InstallV4L2DeviceDouble(device).ok());
    auto source = V4L2FrameSource::Open(device.device_path);
    ASSERT_TRUE(source.ok()) << source.status().ToString();
    const Loop loop = CountSteadyStateAllocations(**source, 200);
    EXPECT_TRUE(loop.all_ok);
    EXPECT_EQ(loop.frames, 200);
    EXPECT_EQ(loop.allocations, 0) << "record " << record;
    source->reset();
    testing::RemoveV4L2DeviceDouble();
  }
}
#endif

TEST(CameraNoAllocation, TheGuardCountsAllocations) {
  testing::NoAllocationScope scope;
  std::string* heap = new std::string(100, 'x');
  const long counted = scope.allocations();
  delete heap;
  EXPECT_GE(counted, 1);
}

}  // namespace
}  // namespace reconar
