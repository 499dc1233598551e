#include "platform/camera/frame_source.h"

#include <cerrno>
#include <cstdlib>
#include <filesystem>

#include "platform/camera/image_folder_source.h"
#include "platform/camera/recorded_frames.h"
#ifdef RECONAR_HAVE_V4L2
#include "platform/camera/v4l2_source.h"
#endif
#ifdef RECONAR_HAVE_LIBCAMERA
#include "platform/camera/libcamera_source.h"
#endif

namespace reconar {

namespace {

constexpr std::string_view kEndOfStreamSuffix = ": end of stream";

bool StartsWith(const std::string& text, std::string_view prefix) {
  return text.size() >= prefix.size() && std::string_view(text).substr(0, prefix.size()) == prefix;
}

bool EndsWith(const std::string& text, std::string_view suffix) {
  return text.size() >= suffix.size() && std::string_view(text).substr(text.size() - suffix.size()) == suffix;
}

template <typename Source>
Result<std::unique_ptr<FrameSource>> Upcast(Result<std::unique_ptr<Source>> source) {
  if (!source.ok()) return source.status();
  return std::unique_ptr<FrameSource>(std::move(source).value());
}

}  // namespace

Status FrameSourceOptions::Check() const {
  if (width < 0 || height < 0 || width > (1 << 15) || height > (1 << 15)) {
    return InvalidArgument("frame source options: bad size " + std::to_string(width) + "x" + std::to_string(height));
  }
  if (buffer_count < 1 || buffer_count > 32) {
    return InvalidArgument("frame source options: buffer_count must be in [1, 32], got " +
                           std::to_string(buffer_count));
  }
  if (timeout_ms < 1) return InvalidArgument("frame source options: timeout_ms must be positive");
  if (!(folder_fps > 0.0)) return InvalidArgument("frame source options: folder_fps must be positive");
  return Status::Ok();
}

FrameHandle::FrameHandle(FrameHandle&& other) noexcept : source_(other.source_), frame_(other.frame_) {
  other.source_ = nullptr;
}

FrameHandle& FrameHandle::operator=(FrameHandle&& other) noexcept {
  if (this != &other) {
    reset();
    source_ = other.source_;
    frame_ = other.frame_;
    other.source_ = nullptr;
  }
  return *this;
}

void FrameHandle::reset() {
  if (source_ == nullptr) return;
  FrameSource* source = source_;
  source_ = nullptr;
  --source->frames_held_;
  source->ReleaseFrame(frame_);
}

FrameSource::~FrameSource() {
  RECONAR_CHECK(frames_held_ == 0) << frames_held_ << " frame(s) still held when their source was destroyed";
}

Result<FrameHandle> FrameSource::Next() {
  Result<Frame> frame = NextFrame();
  if (!frame.ok()) return frame.status();
  ++frames_held_;
  return FrameHandle(this, *frame);
}

Status EndOfStream(std::string_view source_name) {
  return Status(StatusCode::kNotFound, std::string(source_name) + std::string(kEndOfStreamSuffix));
}

bool IsEndOfStream(const Status& status) {
  return status.code() == StatusCode::kNotFound && EndsWith(status.message(), kEndOfStreamSuffix);
}

Result<std::unique_ptr<FrameSource>> OpenFrameSource(const std::string& spec, const FrameSourceOptions& options) {
  RECONAR_RETURN_IF_ERROR(options.Check());
  const bool is_v4l2 = StartsWith(spec, "v4l2:") || StartsWith(spec, "/dev/video");
  if (is_v4l2) {
    const std::string device = StartsWith(spec, "v4l2:") ? spec.substr(5) : spec;
#ifdef RECONAR_HAVE_V4L2
    return Upcast(V4L2FrameSource::Open(device, options));
#else
    return Unsupported(device + ": this build has no V4L2 support (RECONAR_WITH_V4L2=OFF)");
#endif
  }
  if (spec == "libcamera" || StartsWith(spec, "libcamera:")) {
    int camera_index = 0;
    if (spec.size() > 10) {
      const std::string number = spec.substr(10);
      char* end = nullptr;
      errno = 0;
      const long parsed = std::strtol(number.c_str(), &end, 10);
      if (number.empty() || *end != '\0' || errno != 0 || parsed < 0 || parsed > 64) {
        return InvalidArgument(spec + ": expected \"libcamera\" or \"libcamera:N\" with a camera number N");
      }
      camera_index = static_cast<int>(parsed);
    }
#ifdef RECONAR_HAVE_LIBCAMERA
    return Upcast(LibcameraFrameSource::Open(camera_index, options));
#else
    (void)camera_index;
    return Unsupported(spec + ": this build has no libcamera support (RECONAR_WITH_LIBCAMERA=OFF)");
#endif
  }
  if (EndsWith(spec, ".frames")) return Upcast(RecordedFrameSource::Open(spec, options));
  std::error_code ec;
  if (std::filesystem::is_directory(spec, ec)) return Upcast(ImageFolderFrameSource::Open(spec, options));
  return InvalidArgument(spec +
                         ": not a frame source (expected /dev/videoN, v4l2:DEVICE, libcamera[:N], an image "
                         "directory or a .frames recording)");
}

}  // namespace reconar
