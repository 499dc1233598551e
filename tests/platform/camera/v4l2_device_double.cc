#include "tests/platform/camera/v4l2_device_double.h"

#include <dlfcn.h>
#include <fcntl.h>
#include <linux/videodev2.h>
#include <sys/ioctl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <cerrno>
#include <chrono>
#include <cstdarg>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <memory>
#include <mutex>
#include <sstream>
#include <thread>

#include "platform/camera/recorded_frames.h"

namespace reconar::testing {
namespace {

constexpr int kMaxBuffers = 8;  // the most buffers REQBUFS grants

struct ServedFrame {
  std::string payload;
  int64_t timestamp_ns = 0;
};

struct DeviceDouble {
  V4L2DeviceDoubleOptions options;
  dev_t device = 0;
  ino_t inode = 0;
  RawFrameLayout layout;
  std::vector<ServedFrame> frames;
  int disconnect_after = 0;
  size_t buffer_length = 0;  // each buffer's bytes in the file, page aligned
  int buffer_count = 0;
  // The buffers queued to the driver, oldest first: a fixed ring, so that serving a frame does not
  // allocate (the camera tests count the source's allocations per frame).
  std::array<int, kMaxBuffers> queued{};
  int queued_first = 0;
  int queued_count = 0;
  bool streaming = false;
  bool gone = false;
  int delivered = 0;
  std::chrono::steady_clock::time_point stream_start;
};

std::mutex g_mutex;
std::unique_ptr<DeviceDouble> g_double;  // guarded by g_mutex
std::atomic<bool> g_installed{false};

using IoctlFunction = int (*)(int, unsigned long, ...);

IoctlFunction LibraryIoctl() {
  static const IoctlFunction library = reinterpret_cast<IoctlFunction>(::dlsym(RTLD_NEXT, "ioctl"));
  return library;
}

bool IsQueued(const DeviceDouble& device, int index) {
  for (int k = 0; k < device.queued_count; ++k) {
    if (device.queued[static_cast<size_t>((device.queued_first + k) % kMaxBuffers)] == index) return true;
  }
  return false;
}

int Fail(int err) {
  errno = err;
  return -1;
}

size_t ImageBytes(const RawFrameLayout& layout) {
  const size_t rows = static_cast<size_t>(layout.height);
  switch (layout.format) {
    case PixelFormat::kNv12:
      return static_cast<size_t>(layout.bytes_per_line) * (rows + rows / 2);
    case PixelFormat::kMjpeg:
      return static_cast<size_t>(layout.width) * rows * 2;  // as uvcvideo advertises for MJPEG
    default:
      return static_cast<size_t>(layout.bytes_per_line) * rows;
  }
}

void FillFormat(const DeviceDouble& device, v4l2_pix_format* pix) {
  *pix = v4l2_pix_format{};
  pix->width = static_cast<uint32_t>(device.layout.width);
  pix->height = static_cast<uint32_t>(device.layout.height);
  pix->pixelformat = PixelFormatFourcc(device.layout.format);
  pix->field = V4L2_FIELD_NONE;
  pix->bytesperline = device.layout.bytes_per_line;
  pix->sizeimage = static_cast<uint32_t>(ImageBytes(device.layout));
  pix->colorspace = V4L2_COLORSPACE_SRGB;
  pix->quantization =
      device.layout.range == YuvRange::kFull ? V4L2_QUANTIZATION_FULL_RANGE : V4L2_QUANTIZATION_LIM_RANGE;
}

void FillBuffer(const DeviceDouble& device, int index, v4l2_buffer* buffer) {
  buffer->index = static_cast<uint32_t>(index);
  buffer->type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
  buffer->memory = V4L2_MEMORY_MMAP;
  buffer->length = static_cast<uint32_t>(device.buffer_length);
  buffer->m.offset = static_cast<uint32_t>(static_cast<size_t>(index) * device.buffer_length);
  buffer->flags = V4L2_BUF_FLAG_MAPPED | V4L2_BUF_FLAG_TIMESTAMP_MONOTONIC;
  if (IsQueued(device, index)) buffer->flags |= V4L2_BUF_FLAG_QUEUED;
  buffer->field = V4L2_FIELD_NONE;
}

int DequeueBuffer(DeviceDouble& device, int fd, v4l2_buffer* buffer) {
  if (buffer->type != V4L2_BUF_TYPE_VIDEO_CAPTURE || buffer->memory != V4L2_MEMORY_MMAP) return Fail(EINVAL);
  if (!device.streaming) return Fail(EINVAL);
  if (device.delivered >= device.disconnect_after) {
    device.gone = true;
    return Fail(ENODEV);
  }
  if (device.queued_count == 0) return Fail(EAGAIN);
  const int index = device.queued[static_cast<size_t>(device.queued_first)];
  device.queued_first = (device.queued_first + 1) % kMaxBuffers;
  --device.queued_count;
  const ServedFrame& frame = device.frames[static_cast<size_t>(device.delivered) % device.frames.size()];
  const off_t at = static_cast<off_t>(static_cast<size_t>(index) * device.buffer_length);
  if (::pwrite(fd, frame.payload.data(), frame.payload.size(), at) != static_cast<ssize_t>(frame.payload.size())) {
    return Fail(EIO);
  }
  FillBuffer(device, index, buffer);
  buffer->flags |= V4L2_BUF_FLAG_DONE;
  const std::vector<int>& damaged = device.options.damaged_frames;
  if (std::find(damaged.begin(), damaged.end(), device.delivered) != damaged.end()) {
    buffer->flags |= V4L2_BUF_FLAG_ERROR;
  }
  buffer->bytesused = static_cast<uint32_t>(frame.payload.size());
  buffer->sequence = static_cast<uint32_t>(device.delivered);
  buffer->timestamp.tv_sec = static_cast<time_t>(frame.timestamp_ns / 1000000000);
  buffer->timestamp.tv_usec = static_cast<suseconds_t>((frame.timestamp_ns % 1000000000) / 1000);
  ++device.delivered;
  return 0;
}

int Serve(DeviceDouble& device, int fd, unsigned long request, void* argument) {
  if (device.gone) return Fail(ENODEV);
  switch (request) {
    case VIDIOC_QUERYCAP: {
      auto* capability = static_cast<v4l2_capability*>(argument);
      *capability = v4l2_capability{};
      std::snprintf(reinterpret_cast<char*>(capability->driver), sizeof(capability->driver), "reconar-double");
      std::snprintf(reinterpret_cast<char*>(capability->card), sizeof(capability->card), "recorded frames");
      std::snprintf(reinterpret_cast<char*>(capability->bus_info), sizeof(capability->bus_info), "platform:double");
      capability->device_caps = V4L2_CAP_VIDEO_CAPTURE | V4L2_CAP_STREAMING;
      capability->capabilities = capability->device_caps | V4L2_CAP_DEVICE_CAPS;
      return 0;
    }
    case VIDIOC_ENUM_FMT: {
      auto* description = static_cast<v4l2_fmtdesc*>(argument);
      if (description->type != V4L2_BUF_TYPE_VIDEO_CAPTURE || description->index != 0) return Fail(EINVAL);
      description->pixelformat = PixelFormatFourcc(device.layout.format);
      std::snprintf(reinterpret_cast<char*>(description->description), sizeof(description->description), "%s",
                    PixelFormatName(device.layout.format));
      return 0;
    }
    case VIDIOC_G_FMT:
    case VIDIOC_S_FMT: {
      auto* format = static_cast<v4l2_format*>(argument);
      if (format->type != V4L2_BUF_TYPE_VIDEO_CAPTURE) return Fail(EINVAL);
      if (request == VIDIOC_S_FMT && device.buffer_count > 0) return Fail(EBUSY);
      FillFormat(device, &format->fmt.pix);
      return 0;
    }
    case VIDIOC_REQBUFS: {
      auto* request_buffers = static_cast<v4l2_requestbuffers*>(argument);
      if (request_buffers->type != V4L2_BUF_TYPE_VIDEO_CAPTURE || request_buffers->memory != V4L2_MEMORY_MMAP) {
        return Fail(EINVAL);
      }
      if (device.streaming) return Fail(EBUSY);
      const int count = static_cast<int>(std::min<uint32_t>(request_buffers->count, kMaxBuffers));
      if (::ftruncate(fd, static_cast<off_t>(static_cast<size_t>(count) * device.buffer_length)) != 0) {
        return Fail(ENOMEM);
      }
      device.buffer_count = count;
      device.queued_count = 0;
      request_buffers->count = static_cast<uint32_t>(count);
      return 0;
    }
    case VIDIOC_QUERYBUF: {
      auto* buffer = static_cast<v4l2_buffer*>(argument);
      if (buffer->type != V4L2_BUF_TYPE_VIDEO_CAPTURE || buffer->index >= static_cast<uint32_t>(device.buffer_count)) {
        return Fail(EINVAL);
      }
      FillBuffer(device, static_cast<int>(buffer->index), buffer);
      return 0;
    }
    case VIDIOC_QBUF: {
      auto* buffer = static_cast<v4l2_buffer*>(argument);
      const int index = static_cast<int>(buffer->index);
      if (buffer->type != V4L2_BUF_TYPE_VIDEO_CAPTURE || buffer->memory != V4L2_MEMORY_MMAP ||
          buffer->index >= static_cast<uint32_t>(device.buffer_count) || IsQueued(device, index)) {
        return Fail(EINVAL);
      }
      device.queued[static_cast<size_t>((device.queued_first + device.queued_count) % kMaxBuffers)] = index;
      ++device.queued_count;
      FillBuffer(device, index, buffer);
      return 0;
    }
    case VIDIOC_DQBUF:
      return DequeueBuffer(device, fd, static_cast<v4l2_buffer*>(argument));
    case VIDIOC_STREAMON:
    case VIDIOC_STREAMOFF: {
      if (*static_cast<const int*>(argument) != V4L2_BUF_TYPE_VIDEO_CAPTURE) return Fail(EINVAL);
      if (request == VIDIOC_STREAMOFF) {
        device.streaming = false;
        device.queued_count = 0;
        return 0;
      }
      if (device.buffer_count == 0) return Fail(EINVAL);
      if (!device.streaming) device.stream_start = std::chrono::steady_clock::now();
      device.streaming = true;
      return 0;
    }
    default:
      return Fail(ENOTTY);
  }
}

// When the device's next frame is due (its pace from STREAMON), for DQBUF to wait outside the lock.
std::chrono::steady_clock::time_point NextFrameDue(const DeviceDouble& device) {
  if (device.options.frames_per_second <= 0.0 || !device.streaming) return {};
  return device.stream_start + std::chrono::duration_cast<std::chrono::steady_clock::duration>(
                                   std::chrono::duration<double>(device.delivered / device.options.frames_per_second));
}

bool IsTheDevice(const DeviceDouble& device, int fd) {
  struct stat info {};
  return ::fstat(fd, &info) == 0 && info.st_dev == device.device && info.st_ino == device.inode;
}

Result<std::vector<ServedFrame>> ReadServedFrames(const V4L2DeviceDoubleOptions& options, RawFrameLayout* layout) {
  std::ifstream in(options.recording, std::ios::binary);
  if (!in) return FileError(StatusCode::kNotFound, options.recording, "cannot open");
  std::ostringstream contents;
  contents << in.rdbuf();
  const std::string bytes = contents.str();
  if (bytes.compare(0, kRecordedFramesHeaderBytes, kRecordedFramesMagic, kRecordedFramesHeaderBytes) != 0) {
    return FileError(StatusCode::kCorruptData, options.recording, "not a recorded-frames file");
  }
  const auto* data = reinterpret_cast<const uint8_t*>(bytes.data());
  std::vector<ServedFrame> frames;
  size_t offset = kRecordedFramesHeaderBytes;
  for (int index = 0; offset < bytes.size(); ++index) {
    Result<RecordedFrameRecord> record = ReadRecordedFrameRecord(data, bytes.size(), offset);
    if (!record.ok()) return record.status().WithContext(options.recording + ": frame " + std::to_string(index));
    offset = record->end_offset;
    if (index < options.first_frame) continue;
    if (options.num_frames >= 0 && index >= options.first_frame + options.num_frames) break;
    const RawFrameLayout& served = record->raw.layout;
    if (frames.empty()) *layout = served;
    if (served.format != layout->format || served.width != layout->width || served.height != layout->height ||
        served.bytes_per_line != layout->bytes_per_line || served.range != layout->range) {
      return FileError(StatusCode::kInvalidArgument, options.recording,
                       "frame " + std::to_string(index) + " has another layout than the first served frame");
    }
    frames.push_back(ServedFrame{std::string(reinterpret_cast<const char*>(record->raw.data), record->raw.size),
                                 record->timestamp_ns});
  }
  if (frames.empty()) return FileError(StatusCode::kInvalidArgument, options.recording, "no frame to serve");
  return frames;
}

}  // namespace

Status InstallV4L2DeviceDouble(const V4L2DeviceDoubleOptions& options) {
  if (options.device_path.empty()) return InvalidArgument("V4L2 double: no device path");
  if (options.first_frame < 0 || options.frames_per_second < 0.0) {
    return InvalidArgument("V4L2 double: first_frame and frames_per_second must not be negative");
  }
  auto device = std::make_unique<DeviceDouble>();
  device->options = options;
  RECONAR_ASSIGN_OR_RETURN(device->frames, ReadServedFrames(options, &device->layout));
  device->disconnect_after =
      options.disconnect_after >= 0 ? options.disconnect_after : static_cast<int>(device->frames.size());
  size_t largest = ImageBytes(device->layout);
  for (const ServedFrame& frame : device->frames) largest = std::max(largest, frame.payload.size());
  const size_t page = static_cast<size_t>(::sysconf(_SC_PAGESIZE));
  device->buffer_length = (largest + page - 1) / page * page;

  const int fd = ::open(options.device_path.c_str(), O_RDWR | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (fd < 0)
    return FileError(StatusCode::kIoError, options.device_path, std::string("cannot create: ") + std::strerror(errno));
  struct stat info {};
  const int stat_result = ::fstat(fd, &info);
  ::close(fd);
  if (stat_result != 0) return FileError(StatusCode::kIoError, options.device_path, "cannot stat");
  device->device = info.st_dev;
  device->inode = info.st_ino;
  std::lock_guard<std::mutex> lock(g_mutex);
  g_double = std::move(device);
  g_installed = true;
  return Status::Ok();
}

V4L2DeviceDoubleReport V4L2DeviceDoubleState() {
  std::lock_guard<std::mutex> lock(g_mutex);
  V4L2DeviceDoubleReport report;
  if (g_double == nullptr) return report;
  report.frames_dequeued = g_double->delivered;
  report.buffers_granted = g_double->buffer_count;
  report.streaming = g_double->streaming;
  report.gone = g_double->gone;
  return report;
}

void RemoveV4L2DeviceDouble() {
  std::lock_guard<std::mutex> lock(g_mutex);
  g_installed = false;
  g_double.reset();
}

}  // namespace reconar::testing

// Takes precedence over the C library's ioctl in a process that links or preloads the double.
extern "C" int ioctl(int fd, unsigned long request, ...) __THROW {
  va_list arguments;
  va_start(arguments, request);
  void* argument = va_arg(arguments, void*);
  va_end(arguments);
  namespace testing = reconar::testing;
  if (testing::g_installed.load()) {
    std::unique_lock<std::mutex> lock(testing::g_mutex);
    if (testing::g_double != nullptr && testing::IsTheDevice(*testing::g_double, fd)) {
      if (request == VIDIOC_DQBUF) {
        const auto due = testing::NextFrameDue(*testing::g_double);
        lock.unlock();
        std::this_thread::sleep_until(due);
        lock.lock();
        if (testing::g_double == nullptr) return testing::Fail(ENODEV);
      }
      return testing::Serve(*testing::g_double, fd, request, argument);
    }
  }
  const testing::IoctlFunction library = testing::LibraryIoctl();
  if (library == nullptr) {
    errno = ENOSYS;
    return -1;
  }
  return library(fd, request, argument);
}
