#pragma once
// A V4L2 capture device in user space, for the tests of a machine without a camera. A regular
// file stands for the device node and this process's ioctl() is taken over for it (every other
// descriptor goes on to the C library's): the V4L2 mmap streaming interface is served from a
// .frames recording, so V4L2FrameSource runs its own code unchanged against recorded frames.
//
// Served: VIDIOC_QUERYCAP, ENUM_FMT (the recording's one format), G_FMT / S_FMT (the recording's
// size; a driver that cannot scale), REQBUFS, QUERYBUF, QBUF / DQBUF, STREAMON / STREAMOFF;
// anything else is ENOTTY. The buffers are the file's pages, so the source's own mmap() and poll()
// of the file work as they do on a device. After `disconnect_after` frames the camera is gone:
// DQBUF and every later ioctl fail with ENODEV, as on a USB camera pulled out of its socket
// (the kernel unregisters the video node; its ioctls return ENODEV from then on).
//
// Linked into a test executable (camera_v4l2_double), its ioctl() takes precedence over the C
// library's. As the shared library reconar_v4l2_double_preload it serves a process it is
// LD_PRELOADed into, configured by RECONAR_V4L2_DOUBLE (v4l2_device_double_preload.cc).
#include <string>
#include <vector>

#include "core/base/status.h"

namespace reconar::testing {

struct V4L2DeviceDoubleOptions {
  std::string device_path;  // the regular file standing for the device node (created or truncated)
  std::string recording;    // a .frames file; every record served must have the first one's layout
  int first_frame = 0;      // the recording's record served first
  int num_frames = -1;      // records served from first_frame on; -1: to the recording's end
  // Frames delivered before the camera is gone; -1: after the last served frame.
  int disconnect_after = -1;
  double frames_per_second = 0.0;   // a device's pace; 0: each frame as soon as it is asked for
  std::vector<int> damaged_frames;  // served frames (counted from 0) flagged V4L2_BUF_FLAG_ERROR
};

// Reads the recording and takes over `device_path`; replaces a double installed before.
// kNotFound / kCorruptData naming the recording; kInvalidArgument for mixed layouts or bad options.
Status InstallV4L2DeviceDouble(const V4L2DeviceDoubleOptions& options);

// What the double has seen since it was installed.
struct V4L2DeviceDoubleReport {
  int frames_dequeued = 0;  // DQBUF calls that returned a buffer (damaged ones included)
  int buffers_granted = 0;  // by the last VIDIOC_REQBUFS
  bool streaming = false;
  bool gone = false;  // the camera disconnected
};
V4L2DeviceDoubleReport V4L2DeviceDoubleState();

// Stops serving the device (its file stays); ioctl() on it is the C library's again.
void RemoveV4L2DeviceDouble();

}  // namespace reconar::testing
