#include "platform/camera/v4l2_source.h"

#include <fcntl.h>
#include <linux/videodev2.h>
#include <poll.h>
#include <sys/ioctl.h>
#include <sys/mman.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <initializer_list>

#include "core/base/log.h"

namespace reconar {

namespace {

int Ioctl(int fd, unsigned long request, void* argument) {
  int result;
  do {
    result = ::ioctl(fd, request, argument);
  } while (result == -1 && errno == EINTR);
  return result;
}

std::string ErrnoText(int err) { return std::strerror(err); }

bool IsDisconnect(int err) { return err == ENODEV || err == EIO || err == ENXIO; }

std::string FourccText(uint32_t fourcc) {
  std::string text(4, ' ');
  for (int i = 0; i < 4; ++i) {
    const char c = static_cast<char>((fourcc >> (8 * i)) & 0xFF);
    text[static_cast<size_t>(i)] = (c >= 32 && c < 127) ? c : '?';
  }
  return text;
}

// Closes the device and unmaps buffers unless ownership moved to the source.
struct DeviceGuard {
  int fd = -1;
  std::vector<std::pair<void*, size_t>> maps;
  ~DeviceGuard() {
    for (const auto& map : maps) ::munmap(map.first, map.second);
    if (fd >= 0) ::close(fd);
  }
};

Status Error(StatusCode code, const std::string& device, const std::string& reason) {
  return FileError(code, device, reason);
}

PixelFormat ChooseFormat(const std::vector<PixelFormat>& offered, PixelFormat preferred) {
  auto offers = [&](PixelFormat f) {
    for (PixelFormat o : offered) {
      if (o == f) return true;
    }
    return false;
  };
  if (preferred != PixelFormat::kUnknown && offers(preferred)) return preferred;
  for (PixelFormat f : {PixelFormat::kMjpeg, PixelFormat::kYuyv, PixelFormat::kNv12, PixelFormat::kGray8,
                        PixelFormat::kRgb24}) {
    if (offers(f)) return f;
  }
  return PixelFormat::kUnknown;
}

}  // namespace

V4L2FrameSource::V4L2FrameSource(std::string device, int fd, std::string card, std::string driver,
                                 const RawFrameLayout& layout, std::vector<Mapping> mappings,
                                 const FrameSourceOptions& options)
    : device_(std::move(device)),
      fd_(fd),
      card_(std::move(card)),
      driver_(std::move(driver)),
      layout_(layout),
      mappings_(std::move(mappings)),
      options_(options),
      converter_(FrameConversionSettings{options.want_rgb, options.gray_range}),
      buffers_(static_cast<int>(mappings_.size())) {
  buffers_.Resize(layout.width, layout.height, options.want_rgb);
}

Result<std::unique_ptr<V4L2FrameSource>> V4L2FrameSource::Open(const std::string& device,
                                                               const FrameSourceOptions& options) {
  RECONAR_RETURN_IF_ERROR(options.Check());
  DeviceGuard guard;
  guard.fd = ::open(device.c_str(), O_RDWR | O_NONBLOCK | O_CLOEXEC);
  if (guard.fd < 0) {
    const int err = errno;
    if (err == ENOENT || err == ENODEV || err == ENXIO) return Error(StatusCode::kNotFound, device, "no such device");
    if (err == EACCES || err == EPERM) {
      return Error(StatusCode::kIoError, device, "permission denied (is the user in the 'video' group?)");
    }
    return Error(StatusCode::kIoError, device, "cannot open: " + ErrnoText(err));
  }

  v4l2_capability capability{};
  if (Ioctl(guard.fd, VIDIOC_QUERYCAP, &capability) != 0) {
    return Error(StatusCode::kUnsupported, device, "not a V4L2 device (VIDIOC_QUERYCAP: " + ErrnoText(errno) + ")");
  }
  const uint32_t caps = (capability.capabilities & V4L2_CAP_DEVICE_CAPS) != 0 ? capability.device_caps
                                                                             : capability.capabilities;
  if ((caps & V4L2_CAP_VIDEO_CAPTURE) == 0) return Error(StatusCode::kUnsupported, device, "not a capture device");
  if ((caps & V4L2_CAP_STREAMING) == 0) {
    return Error(StatusCode::kUnsupported, device, "capture device without streaming I/O");
  }

  std::vector<PixelFormat> offered;
  std::string offered_text;
  for (uint32_t i = 0;; ++i) {
    v4l2_fmtdesc description{};
    description.index = i;
    description.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
    if (Ioctl(guard.fd, VIDIOC_ENUM_FMT, &description) != 0) break;
    offered.push_back(PixelFormatFromFourcc(description.pixelformat));
    offered_text += (offered_text.empty() ? "" : " ") + FourccText(description.pixelformat);
  }
  const PixelFormat format = ChooseFormat(offered, options.pixel_format);
  if (format == PixelFormat::kUnknown) {
    return Error(StatusCode::kUnsupported, device,
                 "offers no pixel format we decode (offers: " + (offered_text.empty() ? "none" : offered_text) +
                     "; we take MJPG, YUYV, NV12, GREY, RGB3)");
  }

  v4l2_format fmt{};
  fmt.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
  if (Ioctl(guard.fd, VIDIOC_G_FMT, &fmt) != 0) {
    return Error(StatusCode::kIoError, device, "VIDIOC_G_FMT failed: " + ErrnoText(errno));
  }
  if (options.width > 0 && options.height > 0) {
    fmt.fmt.pix.width = static_cast<uint32_t>(options.width);
    fmt.fmt.pix.height = static_cast<uint32_t>(options.height);
  }
  fmt.fmt.pix.pixelformat = PixelFormatFourcc(format);
  fmt.fmt.pix.field = V4L2_FIELD_NONE;
  fmt.fmt.pix.bytesperline = 0;  // let the driver choose its pitch
  if (Ioctl(guard.fd, VIDIOC_S_FMT, &fmt) != 0) {
    const int err = errno;
    if (err == EBUSY) return Error(StatusCode::kIoError, device, "device is busy (another program is capturing)");
    return Error(StatusCode::kIoError, device, "VIDIOC_S_FMT failed: " + ErrnoText(err));
  }
  RawFrameLayout layout;
  layout.format = PixelFormatFromFourcc(fmt.fmt.pix.pixelformat);
  layout.width = static_cast<int>(fmt.fmt.pix.width);
  layout.height = static_cast<int>(fmt.fmt.pix.height);
  layout.bytes_per_line = layout.format == PixelFormat::kMjpeg ? 0 : fmt.fmt.pix.bytesperline;
  if (layout.format != PixelFormat::kMjpeg && layout.bytes_per_line == 0) {
    layout.bytes_per_line = static_cast<uint32_t>(MinBytesPerLine(layout.format, layout.width));
  }
  layout.range = (layout.format == PixelFormat::kMjpeg || fmt.fmt.pix.quantization == V4L2_QUANTIZATION_FULL_RANGE)
                     ? YuvRange::kFull
                     : YuvRange::kLimited;
  if (layout.format != format) {
    return Error(StatusCode::kUnsupported, device,
                 "driver replaced " + std::string(PixelFormatName(format)) + " by " +
                     FourccText(fmt.fmt.pix.pixelformat));
  }
  RECONAR_RETURN_IF_ERROR(CheckRawFrameLayout(layout, device));

  v4l2_requestbuffers request{};
  request.count = static_cast<uint32_t>(options.buffer_count);
  request.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
  request.memory = V4L2_MEMORY_MMAP;
  if (Ioctl(guard.fd, VIDIOC_REQBUFS, &request) != 0) {
    return Error(StatusCode::kIoError, device, "VIDIOC_REQBUFS failed: " + ErrnoText(errno));
  }
  if (request.count < 1) return Error(StatusCode::kResourceExhausted, device, "driver granted no buffers");
  std::vector<Mapping> mappings;
  for (uint32_t i = 0; i < request.count; ++i) {
    v4l2_buffer buffer{};
    buffer.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
    buffer.memory = V4L2_MEMORY_MMAP;
    buffer.index = i;
    if (Ioctl(guard.fd, VIDIOC_QUERYBUF, &buffer) != 0) {
      return Error(StatusCode::kIoError, device, "VIDIOC_QUERYBUF failed: " + ErrnoText(errno));
    }
    void* data = ::mmap(nullptr, buffer.length, PROT_READ | PROT_WRITE, MAP_SHARED, guard.fd, buffer.m.offset);
    if (data == MAP_FAILED) return Error(StatusCode::kIoError, device, "mmap of a buffer failed: " + ErrnoText(errno));
    guard.maps.emplace_back(data, buffer.length);
    mappings.push_back(Mapping{data, buffer.length});
    if (Ioctl(guard.fd, VIDIOC_QBUF, &buffer) != 0) {
      return Error(StatusCode::kIoError, device, "VIDIOC_QBUF failed: " + ErrnoText(errno));
    }
  }

  std::unique_ptr<RecordedFramesWriter> recorder;
  if (!options.record_path.empty()) {
    RECONAR_ASSIGN_OR_RETURN(recorder, RecordedFramesWriter::Create(options.record_path));
  }
  int type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
  if (Ioctl(guard.fd, VIDIOC_STREAMON, &type) != 0) {
    const int err = errno;
    if (IsDisconnect(err)) return Error(StatusCode::kIoError, device, "camera disconnected");
    return Error(StatusCode::kIoError, device, "VIDIOC_STREAMON failed: " + ErrnoText(err));
  }
  std::unique_ptr<V4L2FrameSource> source(new V4L2FrameSource(
      device, guard.fd, reinterpret_cast<const char*>(capability.card),
      reinterpret_cast<const char*>(capability.driver), layout, std::move(mappings), options));
  source->streaming_ = true;
  source->recorder_ = std::move(recorder);
  guard.fd = -1;
  guard.maps.clear();
  return source;
}

V4L2FrameSource::~V4L2FrameSource() {
  if (streaming_) {
    int type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
    Ioctl(fd_, VIDIOC_STREAMOFF, &type);
  }
  for (const Mapping& mapping : mappings_) ::munmap(mapping.data, mapping.length);
  if (fd_ >= 0) ::close(fd_);
  if (recorder_ != nullptr) {
    const Status status = recorder_->Finish();
    if (!status.ok()) LogWarning(status.ToString());
  }
}

Status V4L2FrameSource::DeviceError(StatusCode code, const std::string& reason) const {
  return FileError(code, device_, reason);
}

Result<Frame> V4L2FrameSource::NextFrame() {
  if (buffers_.all_held()) {
    return DeviceError(StatusCode::kFailedPrecondition,
                       "all " + std::to_string(buffers_.count()) + " frame buffers are held; release one first");
  }
  v4l2_buffer buffer{};
  for (;;) {
    pollfd waiting{fd_, POLLIN, 0};
    const int ready = ::poll(&waiting, 1, options_.timeout_ms);
    if (ready < 0) {
      if (errno == EINTR) continue;
      return DeviceError(StatusCode::kIoError, "poll failed: " + ErrnoText(errno));
    }
    if (ready == 0) {
      return DeviceError(StatusCode::kIoError, "no frame within " + std::to_string(options_.timeout_ms) + " ms");
    }
    if ((waiting.revents & (POLLERR | POLLHUP | POLLNVAL)) != 0 && (waiting.revents & POLLIN) == 0) {
      return DeviceError(StatusCode::kIoError, "camera disconnected");
    }
    buffer = v4l2_buffer{};
    buffer.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
    buffer.memory = V4L2_MEMORY_MMAP;
    if (Ioctl(fd_, VIDIOC_DQBUF, &buffer) != 0) {
      const int err = errno;
      if (err == EAGAIN) continue;
      if (IsDisconnect(err)) return DeviceError(StatusCode::kIoError, "camera disconnected");
      return DeviceError(StatusCode::kIoError, "VIDIOC_DQBUF failed: " + ErrnoText(err));
    }
    if ((buffer.flags & V4L2_BUF_FLAG_ERROR) == 0 && buffer.bytesused > 0) break;
    // The driver flagged a damaged frame: give the buffer straight back and wait for the next.
    Ioctl(fd_, VIDIOC_QBUF, &buffer);
  }

  const int index = static_cast<int>(buffer.index);
  if (index < 0 || index >= buffers_.count()) {
    return DeviceError(StatusCode::kInternal, "driver returned buffer " + std::to_string(index) + " of " +
                                                  std::to_string(buffers_.count()));
  }
  buffers_.MarkHeld(index);
  RawFrame raw;
  raw.layout = layout_;
  raw.data = static_cast<const uint8_t*>(mappings_[static_cast<size_t>(index)].data);
  raw.size = std::min<size_t>(buffer.bytesused, mappings_[static_cast<size_t>(index)].length);
  const int64_t timestamp_ns =
      static_cast<int64_t>(buffer.timestamp.tv_sec) * 1000000000 + static_cast<int64_t>(buffer.timestamp.tv_usec) * 1000;
  if (recorder_ != nullptr) {
    const Status recorded = recorder_->Append(raw, timestamp_ns);
    if (!recorded.ok()) {
      LogWarning(recorded.ToString() + "; recording stopped");
      recorder_.reset();
    }
  }
  Frame frame;
  frame.name = buffers_.SetName(index, "%s#%u", device_.c_str(), buffer.sequence);
  frame.index = buffer.sequence;
  frame.timestamp_ns = timestamp_ns;
  frame.width = layout_.width;
  frame.height = layout_.height;
  frame.source_format = layout_.format;
  frame.buffer = index;
  Status status = converter_.Convert(raw, frame.name, buffers_.gray(index), buffers_.rgb(index), &frame.gray,
                                     &frame.rgb);
  if (!status.ok()) {
    ReleaseFrame(frame);
    return status;
  }
  ++delivered_;
  return frame;
}

void V4L2FrameSource::ReleaseFrame(const Frame& frame) {
  buffers_.Release(frame.buffer);
  v4l2_buffer buffer{};
  buffer.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
  buffer.memory = V4L2_MEMORY_MMAP;
  buffer.index = static_cast<uint32_t>(frame.buffer);
  // A failure here (device gone) surfaces as "camera disconnected" from the next Next().
  Ioctl(fd_, VIDIOC_QBUF, &buffer);
}

std::string V4L2FrameSource::Describe() const {
  return "V4L2 " + device_ + " (" + driver_ + ", " + card_ + ") " + std::to_string(layout_.width) + "x" +
         std::to_string(layout_.height) + " " + PixelFormatName(layout_.format) +
         (layout_.range == YuvRange::kFull ? " full range" : " limited range") + ", " +
         std::to_string(buffers_.count()) + " buffers";
}

}  // namespace reconar
