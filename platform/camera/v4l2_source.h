#pragma once
// V4L2FrameSource: a Linux video capture device through the V4L2 ioctl interface (no libv4l),
// mmap streaming I/O with options.buffer_count driver buffers (the driver may grant more or
// fewer; buffer_count() says how many). Frames point into those buffers: a held frame is a
// buffer the driver cannot fill, so hold few and release them promptly (a FrameHandle's release = VIDIOC_QBUF).
//
// Format negotiation: options.pixel_format if the device offers it, else the first of MJPEG,
// YUYV, NV12, GREY, RGB3 that it offers (VIDIOC_ENUM_FMT), at options.width x options.height as
// the driver adjusts it (VIDIOC_S_FMT). Quantisation: V4L2_QUANTIZATION_FULL_RANGE → full,
// otherwise limited for YUV (V4L2's default); MJPEG is always full (JFIF).
//
// Errors (all name the device): "no such device" (kNotFound), "permission denied" (kIoError),
// "not a V4L2 device" / "not a capture device" / "no streaming I/O" (kUnsupported),
// "camera disconnected" (kIoError: EIO/ENODEV while streaming), "no frame within N ms" (kIoError).
#include <memory>
#include <string>
#include <vector>

#include "core/base/status.h"
#include "platform/camera/frame_buffers.h"
#include "platform/camera/frame_source.h"
#include "platform/camera/raw_frame.h"
#include "platform/camera/recorded_frames.h"

namespace reconar {

class V4L2FrameSource final : public FrameSource {
 public:
  static Result<std::unique_ptr<V4L2FrameSource>> Open(const std::string& device,
                                                       const FrameSourceOptions& options = {});
  // STREAMOFF, unmaps the buffers, closes the device, commits the recording (if any).
  ~V4L2FrameSource() override;

  std::string Describe() const override;
  int buffer_count() const override { return buffers_.count(); }

  // The negotiated buffer layout.
  const RawFrameLayout& layout() const { return layout_; }

 private:
  Result<Frame> NextFrame() override;
  void ReleaseFrame(const Frame& frame) override;
  struct Mapping {
    void* data = nullptr;
    size_t length = 0;
  };
  V4L2FrameSource(std::string device, int fd, std::string card, std::string driver, const RawFrameLayout& layout,
                  std::vector<Mapping> mappings, const FrameSourceOptions& options);
  Status DeviceError(StatusCode code, const std::string& reason) const;

  std::string device_;
  int fd_ = -1;
  std::string card_;
  std::string driver_;
  RawFrameLayout layout_;
  std::vector<Mapping> mappings_;
  FrameSourceOptions options_;
  bool streaming_ = false;
  RawFrameConverter converter_;
  camera_internal::FrameBuffers buffers_;
  std::unique_ptr<RecordedFramesWriter> recorder_;
  int64_t delivered_ = 0;

  friend class V4L2Opener;
};

}  // namespace reconar
