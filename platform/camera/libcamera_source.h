#pragma once
// LibcameraFrameSource: a camera through libcamera (0.0.3 API): CameraManager → Camera::acquire
// → one Viewfinder stream configured at options.width x options.height → FrameBufferAllocator
// buffers (dmabuf planes mmap'ed read-only) → one Request per buffer. The requestCompleted
// signal (libcamera's thread) pushes finished requests into a small locked queue; Next() waits
// on it for at most options.timeout_ms. Releasing a frame re-queues its request.
//
// Pixel format: options.pixel_format if the stream offers it, else NV12 (the native ISP output
// on Raspberry Pi class boards, zero-copy gray), YUYV, MJPEG. Quantisation from the stream's
// colour space (full or limited range; limited if unspecified, MJPEG always full).
// libcamera prints its own log lines to stderr (LIBCAMERA_LOG_LEVELS=*:ERROR quiets them).
//
// Errors: "libcamera: no cameras found" (kNotFound), "libcamera: camera N not found (M cameras)",
// "camera is busy" (kIoError), "camera disconnected", "no frame within N ms" (kIoError).
#include <memory>
#include <string>

#include "core/base/status.h"
#include "platform/camera/frame_source.h"

namespace reconar {

class LibcameraFrameSource final : public FrameSource {
 public:
  // camera_index counts libcamera's cameras in CameraManager::cameras() order.
  static Result<std::unique_ptr<LibcameraFrameSource>> Open(int camera_index, const FrameSourceOptions& options = {});
  // Stops the camera, frees its buffers, releases it; commits the recording (if any).
  ~LibcameraFrameSource() override;

  std::string Describe() const override;
  int buffer_count() const override;

  struct Impl;  // libcamera objects stay out of this header

 private:
  Result<Frame> NextFrame() override;
  void ReleaseFrame(const Frame& frame) override;
  explicit LibcameraFrameSource(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

}  // namespace reconar
