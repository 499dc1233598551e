#include "platform/camera/libcamera_source.h"

#include <sys/mman.h>

#include <algorithm>
#include <chrono>
#include <condition_variable>
#include <map>
#include <mutex>
#include <vector>

#include <libcamera/libcamera.h>

#include "core/base/log.h"
#include "platform/camera/frame_buffers.h"
#include "platform/camera/raw_frame.h"
#include "platform/camera/recorded_frames.h"

namespace reconar {

namespace {

PixelFormat FromLibcamera(const libcamera::PixelFormat& format) {
  if (format == libcamera::formats::NV12) return PixelFormat::kNv12;
  if (format == libcamera::formats::YUYV) return PixelFormat::kYuyv;
  if (format == libcamera::formats::MJPEG) return PixelFormat::kMjpeg;
  return PixelFormat::kUnknown;
}

libcamera::PixelFormat ToLibcamera(PixelFormat format) {
  switch (format) {
    case PixelFormat::kNv12: return libcamera::formats::NV12;
    case PixelFormat::kYuyv: return libcamera::formats::YUYV;
    case PixelFormat::kMjpeg: return libcamera::formats::MJPEG;
    default: break;
  }
  return libcamera::PixelFormat();
}

Status CameraError(StatusCode code, const std::string& reason) { return Status(code, "libcamera: " + reason); }

}  // namespace

struct LibcameraFrameSource::Impl {
  struct Mapping {
    void* data = nullptr;
    size_t length = 0;
  };
  struct Slot {
    std::unique_ptr<libcamera::Request> request;
    libcamera::FrameBuffer* buffer = nullptr;
    const uint8_t* planes[2] = {nullptr, nullptr};
    size_t plane_lengths[2] = {0, 0};
  };

  explicit Impl(const FrameSourceOptions& options_in)
      : options(options_in), converter(FrameConversionSettings{options_in.want_rgb, options_in.gray_range}) {}

  ~Impl() {
    if (camera != nullptr) {
      if (started) camera->stop();
      camera->requestCompleted.disconnect(this);
      camera->disconnected.disconnect(this);
      slots.clear();
      if (allocator != nullptr && stream != nullptr) allocator->free(stream);
      allocator.reset();
      if (acquired) camera->release();
      camera.reset();
    }
    for (const Mapping& mapping : mappings) ::munmap(mapping.data, mapping.length);
    manager.reset();
    if (recorder != nullptr) {
      const Status status = recorder->Finish();
      if (!status.ok()) LogWarning(status.ToString());
    }
  }

  // libcamera's thread.
  void OnRequestCompleted(libcamera::Request* request) {
    if (request->status() == libcamera::Request::RequestCancelled) return;
    {
      std::lock_guard<std::mutex> lock(mutex);
      completed[(completed_head + completed_count) % completed.size()] = request;
      ++completed_count;
    }
    ready.notify_one();
  }

  void OnDisconnected() {
    {
      std::lock_guard<std::mutex> lock(mutex);
      disconnected = true;
    }
    ready.notify_one();
  }

  Status MapBuffers(const std::vector<std::unique_ptr<libcamera::FrameBuffer>>& allocated) {
    for (const auto& buffer : allocated) {
      Slot slot;
      slot.buffer = buffer.get();
      const auto& planes = buffer->planes();
      if (planes.empty() || planes.size() > 2) {
        return CameraError(StatusCode::kUnsupported, "buffer with " + std::to_string(planes.size()) + " planes");
      }
      // Planes usually share one dmabuf: map each distinct fd once, as far as its last plane reaches.
      std::map<int, size_t> extent;
      for (const auto& plane : planes) {
        size_t& end = extent[plane.fd.get()];
        end = std::max(end, static_cast<size_t>(plane.offset) + plane.length);
      }
      std::map<int, const uint8_t*> base;
      for (const auto& [fd, length] : extent) {
        void* data = ::mmap(nullptr, length, PROT_READ, MAP_SHARED, fd, 0);
        if (data == MAP_FAILED) return CameraError(StatusCode::kIoError, "mmap of a frame buffer failed");
        mappings.push_back(Mapping{data, length});
        base[fd] = static_cast<const uint8_t*>(data);
      }
      for (size_t p = 0; p < planes.size(); ++p) {
        slot.planes[p] = base[planes[p].fd.get()] + planes[p].offset;
        slot.plane_lengths[p] = planes[p].length;
      }
      slot.request = camera->createRequest(slots.size());
      if (slot.request == nullptr) return CameraError(StatusCode::kIoError, "cannot create a request");
      if (slot.request->addBuffer(stream, slot.buffer) != 0) {
        return CameraError(StatusCode::kIoError, "cannot add a buffer to a request");
      }
      slots.push_back(std::move(slot));
    }
    return Status::Ok();
  }

  FrameSourceOptions options;
  std::unique_ptr<libcamera::CameraManager> manager;
  std::shared_ptr<libcamera::Camera> camera;
  bool acquired = false;
  bool started = false;
  std::unique_ptr<libcamera::CameraConfiguration> configuration;
  libcamera::Stream* stream = nullptr;
  std::unique_ptr<libcamera::FrameBufferAllocator> allocator;
  std::vector<Mapping> mappings;
  std::vector<Slot> slots;
  RawFrameLayout layout;
  std::string name;
  RawFrameConverter converter;
  std::unique_ptr<camera_internal::FrameBuffers> buffers;
  std::unique_ptr<RecordedFramesWriter> recorder;

  std::mutex mutex;
  std::condition_variable ready;
  std::vector<libcamera::Request*> completed;  // ring buffer, one place per slot
  size_t completed_head = 0;
  size_t completed_count = 0;
  bool disconnected = false;
};

LibcameraFrameSource::LibcameraFrameSource(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}

LibcameraFrameSource::~LibcameraFrameSource() = default;

Result<std::unique_ptr<LibcameraFrameSource>> LibcameraFrameSource::Open(int camera_index,
                                                                         const FrameSourceOptions& options) {
  RECONAR_RETURN_IF_ERROR(options.Check());
  auto impl = std::make_unique<Impl>(options);
  impl->manager = std::make_unique<libcamera::CameraManager>();
  if (impl->manager->start() != 0) {
    impl->manager.reset();
    return CameraError(StatusCode::kIoError, "camera manager failed to start");
  }
  const std::vector<std::shared_ptr<libcamera::Camera>> cameras = impl->manager->cameras();
  if (cameras.empty()) return CameraError(StatusCode::kNotFound, "no cameras found");
  if (camera_index < 0 || static_cast<size_t>(camera_index) >= cameras.size()) {
    return CameraError(StatusCode::kNotFound, "camera " + std::to_string(camera_index) + " not found (" +
                                                  std::to_string(cameras.size()) + " cameras)");
  }
  impl->camera = cameras[static_cast<size_t>(camera_index)];
  impl->name = "libcamera:" + std::to_string(camera_index) + " (" + impl->camera->id() + ")";
  if (impl->camera->acquire() != 0) return CameraError(StatusCode::kIoError, impl->name + ": camera is busy");
  impl->acquired = true;

  impl->configuration = impl->camera->generateConfiguration({libcamera::StreamRole::Viewfinder});
  if (impl->configuration == nullptr || impl->configuration->empty()) {
    return CameraError(StatusCode::kUnsupported, impl->name + ": no viewfinder configuration");
  }
  libcamera::StreamConfiguration& stream_config = impl->configuration->at(0);
  const std::vector<libcamera::PixelFormat> offered = stream_config.formats().pixelformats();
  auto offers = [&](PixelFormat format) {
    return std::find(offered.begin(), offered.end(), ToLibcamera(format)) != offered.end();
  };
  PixelFormat chosen = PixelFormat::kUnknown;
  if (options.pixel_format != PixelFormat::kUnknown && offers(options.pixel_format)) chosen = options.pixel_format;
  for (PixelFormat format : {PixelFormat::kNv12, PixelFormat::kYuyv, PixelFormat::kMjpeg}) {
    if (chosen == PixelFormat::kUnknown && offers(format)) chosen = format;
  }
  if (chosen == PixelFormat::kUnknown) {
    return CameraError(StatusCode::kUnsupported, impl->name + ": offers none of NV12, YUYV, MJPEG");
  }
  stream_config.pixelFormat = ToLibcamera(chosen);
  if (options.width > 0 && options.height > 0) {
    stream_config.size = libcamera::Size(static_cast<unsigned>(options.width), static_cast<unsigned>(options.height));
  }
  stream_config.bufferCount = static_cast<unsigned>(options.buffer_count);
  if (impl->configuration->validate() == libcamera::CameraConfiguration::Invalid) {
    return CameraError(StatusCode::kUnsupported, impl->name + ": configuration " + stream_config.toString() +
                                                     " is invalid");
  }
  if (impl->camera->configure(impl->configuration.get()) != 0) {
    return CameraError(StatusCode::kIoError, impl->name + ": configure failed");
  }
  impl->layout.format = FromLibcamera(stream_config.pixelFormat);
  if (impl->layout.format == PixelFormat::kUnknown) {
    return CameraError(StatusCode::kUnsupported,
                       impl->name + ": camera adjusted the format to " + stream_config.pixelFormat.toString());
  }
  impl->layout.width = static_cast<int>(stream_config.size.width);
  impl->layout.height = static_cast<int>(stream_config.size.height);
  impl->layout.bytes_per_line = impl->layout.format == PixelFormat::kMjpeg ? 0 : stream_config.stride;
  const bool full_range = impl->layout.format == PixelFormat::kMjpeg ||
                          (stream_config.colorSpace.has_value() &&
                           stream_config.colorSpace->range == libcamera::ColorSpace::Range::Full);
  impl->layout.range = full_range ? YuvRange::kFull : YuvRange::kLimited;
  RECONAR_RETURN_IF_ERROR(CheckRawFrameLayout(impl->layout, impl->name));
  impl->stream = stream_config.stream();

  impl->allocator = std::make_unique<libcamera::FrameBufferAllocator>(impl->camera);
  if (impl->allocator->allocate(impl->stream) < 1) {
    return CameraError(StatusCode::kResourceExhausted, impl->name + ": cannot allocate frame buffers");
  }
  RECONAR_RETURN_IF_ERROR(impl->MapBuffers(impl->allocator->buffers(impl->stream)));
  const int count = static_cast<int>(impl->slots.size());
  impl->buffers = std::make_unique<camera_internal::FrameBuffers>(count);
  impl->buffers->Resize(impl->layout.width, impl->layout.height, options.want_rgb);
  impl->completed.assign(impl->slots.size(), nullptr);
  if (!options.record_path.empty()) {
    RECONAR_ASSIGN_OR_RETURN(impl->recorder, RecordedFramesWriter::Create(options.record_path));
  }

  impl->camera->requestCompleted.connect(impl.get(), &Impl::OnRequestCompleted);
  impl->camera->disconnected.connect(impl.get(), &Impl::OnDisconnected);
  if (impl->camera->start() != 0) return CameraError(StatusCode::kIoError, impl->name + ": start failed");
  impl->started = true;
  for (Impl::Slot& slot : impl->slots) {
    if (impl->camera->queueRequest(slot.request.get()) != 0) {
      return CameraError(StatusCode::kIoError, impl->name + ": cannot queue a request");
    }
  }
  return std::unique_ptr<LibcameraFrameSource>(new LibcameraFrameSource(std::move(impl)));
}

Result<Frame> LibcameraFrameSource::NextFrame() {
  Impl& impl = *impl_;
  if (impl.buffers->all_held()) {
    return CameraError(StatusCode::kFailedPrecondition, impl.name + ": all " + std::to_string(impl.buffers->count()) +
                                                            " frame buffers are held; release one first");
  }
  for (;;) {
    libcamera::Request* request = nullptr;
    {
      std::unique_lock<std::mutex> lock(impl.mutex);
      const bool woke = impl.ready.wait_for(lock, std::chrono::milliseconds(impl.options.timeout_ms),
                                            [&] { return impl.completed_count > 0 || impl.disconnected; });
      if (impl.disconnected) return CameraError(StatusCode::kIoError, impl.name + ": camera disconnected");
      if (!woke) {
        return CameraError(StatusCode::kIoError,
                           impl.name + ": no frame within " + std::to_string(impl.options.timeout_ms) + " ms");
      }
      request = impl.completed[impl.completed_head];
      impl.completed_head = (impl.completed_head + 1) % impl.completed.size();
      --impl.completed_count;
    }
    const int index = static_cast<int>(request->cookie());
    Impl::Slot& slot = impl.slots[static_cast<size_t>(index)];
    const libcamera::FrameMetadata& metadata = slot.buffer->metadata();
    if (metadata.status != libcamera::FrameMetadata::FrameSuccess) {
      request->reuse(libcamera::Request::ReuseBuffers);
      impl.camera->queueRequest(request);
      continue;
    }
    impl.buffers->MarkHeld(index);
    RawFrame raw;
    raw.layout = impl.layout;
    raw.data = slot.planes[0];
    const auto planes = metadata.planes();
    raw.size = planes.size() > 0 ? std::min<size_t>(planes[0].bytesused, slot.plane_lengths[0]) : 0;
    if (slot.planes[1] != nullptr) {
      raw.chroma = slot.planes[1];
      raw.chroma_size = planes.size() > 1 ? std::min<size_t>(planes[1].bytesused, slot.plane_lengths[1]) : 0;
    }
    const int64_t timestamp_ns = static_cast<int64_t>(metadata.timestamp);
    if (impl.recorder != nullptr) {
      const Status recorded = impl.recorder->Append(raw, timestamp_ns);
      if (!recorded.ok()) {
        LogWarning(recorded.ToString() + "; recording stopped");
        impl.recorder.reset();
      }
    }
    Frame frame;
    frame.name = impl.buffers->SetName(index, "libcamera#%u", metadata.sequence);
    frame.index = metadata.sequence;
    frame.timestamp_ns = timestamp_ns;
    frame.width = impl.layout.width;
    frame.height = impl.layout.height;
    frame.source_format = impl.layout.format;
    frame.buffer = index;
    Status status = impl.converter.Convert(raw, frame.name, impl.buffers->gray(index), impl.buffers->rgb(index),
                                           &frame.gray, &frame.rgb);
    if (!status.ok()) {
      ReleaseFrame(frame);
      return status;
    }
    return frame;
  }
}

void LibcameraFrameSource::ReleaseFrame(const Frame& frame) {
  Impl& impl = *impl_;
  impl.buffers->Release(frame.buffer);
  libcamera::Request* request = impl.slots[static_cast<size_t>(frame.buffer)].request.get();
  request->reuse(libcamera::Request::ReuseBuffers);
  // A failure here (camera gone) surfaces from the next Next().
  impl.camera->queueRequest(request);
}

std::string LibcameraFrameSource::Describe() const {
  const Impl& impl = *impl_;
  return impl.name + " " + std::to_string(impl.layout.width) + "x" + std::to_string(impl.layout.height) + " " +
         PixelFormatName(impl.layout.format) + (impl.layout.range == YuvRange::kFull ? " full range" : " limited range") +
         ", " + std::to_string(impl.buffers->count()) + " buffers";
}

int LibcameraFrameSource::buffer_count() const { return impl_->buffers->count(); }

}  // namespace reconar
