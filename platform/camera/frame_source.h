#pragma once
// FrameSource: a stream of camera frames (live V4L2 / libcamera device, image folder, recorded
// .frames file) delivered as strided 8-bit views over buffers the source owns.
//
// Ownership and lifetime. Next() hands out a FrameHandle: a move-only owner of one of the source's
// `buffer_count()` buffers (a device buffer: V4L2 mmap, libcamera dmabuf; a recording's memory
// map; or a source-owned conversion buffer), into which the frame's views and name point. The
// buffer goes back to the source when the handle is destroyed, reset or assigned over (as a
// completed request's handle does in rpicam-apps), so no path can forget it. Handles must not
// outlive their source (destroying a source while one of its frames is held is a programmer
// error, RECONAR_CHECK). Up to buffer_count() frames may be held at once; while all of them are
// held, Next() returns kFailedPrecondition ("all N frame buffers are held") without blocking, so a
// caller that keeps too many gets an error, not a dead lock. For devices, holding frames also
// starves the driver's queue (it drops frames meanwhile).
//
// Zero copy where the layout allows it: NV12's Y plane and GRAY8 buffers are the gray image and
// RGB24 buffers are the rgb image (views straight into the device or recorded buffer); YUYV,
// MJPEG and the other combinations are converted into buffers preallocated when the frame size
// is first seen. After the first frame, Next() and releasing the handle on raw (non-JPEG) frames does not
// allocate.
//
// Streams end with IsEndOfStream(status) (code kNotFound, message "<source>: end of stream").
// Live sources never end; they fail with kIoError "...: camera disconnected" or
// "...: no frame within N ms" (timeout).
#include <cstdint>
#include <memory>
#include <string>
#include <string_view>

#include "core/base/image.h"
#include "core/base/status.h"
#include "platform/camera/pixel_format.h"

namespace reconar {

// How gray is produced from limited-range YUV (YUYV/NV12 from a device or a recording).
enum class GrayRange : uint8_t {
  kAsDelivered,  // luma samples as they are (16..235 for limited range); NV12 stays zero-copy
  kFull,         // expanded to 0..255 (one extra pass for NV12)
};

struct FrameSourceOptions {
  // Devices: requested capture size; 0 leaves the driver's current size.
  int width = 640;
  int height = 480;
  // Devices: the preferred buffer layout. kUnknown = the first of MJPEG, YUYV, NV12 the device offers.
  PixelFormat pixel_format = PixelFormat::kUnknown;
  // When false, Frame::rgb is empty and no RGB conversion (or MJPEG chroma decode) happens.
  bool want_rgb = true;
  GrayRange gray_range = GrayRange::kAsDelivered;
  // Frames that may be held at once (device buffers requested; conversion buffers allocated).
  int buffer_count = 4;
  // Live sources: how long Next() waits for a frame.
  int timeout_ms = 2000;
  // Folder sources have no clock: frame i gets timestamp i * 1e9 / folder_fps.
  double folder_fps = 30.0;
  // Live sources: if not empty, every raw buffer is also appended to this .frames file
  // (recorded_frames.h), committed atomically when the source is destroyed.
  std::string record_path;

  Status Check() const;  // kInvalidArgument naming the bad field
};

struct Frame {
  std::string_view name;  // e.g. "frame0003.jpg" or "/dev/video0#17"; valid while the frame is held
  int64_t index = 0;      // 0, 1, 2, ... in delivery order (device sequence numbers for V4L2)
  int64_t timestamp_ns = 0;  // capture time: CLOCK_MONOTONIC for devices, recorded/synthesised otherwise
  int width = 0;
  int height = 0;
  PixelFormat source_format = PixelFormat::kUnknown;  // the raw layout the frame came from
  ImageView<const uint8_t> gray;  // width x height
  ImageView<const uint8_t> rgb;   // interleaved, view width = 3 * width; empty unless want_rgb
  int buffer = -1;                // which source buffer holds it (given back by its FrameHandle)
};

class FrameSource;

// One frame held from a FrameSource; gives its buffer back on destruction, reset() or move
// assignment. Empty after a move or reset() (operator bool is false; * and -> are then a
// programmer error, RECONAR_CHECK).
// Makes no allocation.
class FrameHandle {
 public:
  FrameHandle() = default;
  FrameHandle(FrameHandle&& other) noexcept;
  FrameHandle& operator=(FrameHandle&& other) noexcept;
  FrameHandle(const FrameHandle&) = delete;
  FrameHandle& operator=(const FrameHandle&) = delete;
  ~FrameHandle() { reset(); }

  const Frame& operator*() const {
    RECONAR_CHECK(source_ != nullptr) << "an empty FrameHandle has no frame";
    return frame_;
  }
  const Frame* operator->() const { return &**this; }
  explicit operator bool() const { return source_ != nullptr; }
  // Gives the buffer back now; the views become invalid.
  void reset();

 private:
  friend class FrameSource;
  FrameHandle(FrameSource* source, const Frame& frame) : source_(source), frame_(frame) {}

  FrameSource* source_ = nullptr;  // not owned; nullptr when empty
  Frame frame_;
};

class FrameSource {
 public:
  virtual ~FrameSource();  // RECONAR_CHECK: no FrameHandle of this source is still held
  // Blocks until the next frame (live sources: at most options.timeout_ms).
  Result<FrameHandle> Next();
  // "V4L2 /dev/video0 (uvcvideo, USB Camera) 640x480 MJPG", "folder photos/ (93 images)", ...
  virtual std::string Describe() const = 0;
  virtual int buffer_count() const = 0;
  int frames_held() const { return frames_held_; }

 protected:
  // What each source implements: deliver a frame in one of its buffers, and take a buffer back
  // (called once per delivered frame, by its FrameHandle).
  virtual Result<Frame> NextFrame() = 0;
  virtual void ReleaseFrame(const Frame& frame) = 0;

 private:
  friend class FrameHandle;
  int frames_held_ = 0;
};

Status EndOfStream(std::string_view source_name);
bool IsEndOfStream(const Status& status);

// Opens a source by specification:
//   "/dev/videoN" or "v4l2:/dev/videoN"  → V4L2FrameSource
//   "libcamera" or "libcamera:N"         → LibcameraFrameSource (N-th camera, default 0)
//   an existing directory                → ImageFolderFrameSource
//   a path ending in ".frames"            → RecordedFrameSource
// Anything else is kInvalidArgument. Sources compiled out (RECONAR_WITH_V4L2/LIBCAMERA=OFF)
// give kUnsupported.
Result<std::unique_ptr<FrameSource>> OpenFrameSource(const std::string& spec, const FrameSourceOptions& options = {});

}  // namespace reconar
