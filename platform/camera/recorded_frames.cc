#include "platform/camera/recorded_frames.h"

#include <fcntl.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

namespace reconar {

namespace {

constexpr char kRecordTag[4] = {'F', 'R', 'A', 'M'};

std::string ErrnoText() { return std::strerror(errno); }

void PutU32(uint8_t* out, uint32_t value) {
  for (int i = 0; i < 4; ++i) out[i] = static_cast<uint8_t>(value >> (8 * i));
}

uint32_t GetU32(const uint8_t* in) {
  return static_cast<uint32_t>(in[0]) | static_cast<uint32_t>(in[1]) << 8 | static_cast<uint32_t>(in[2]) << 16 |
         static_cast<uint32_t>(in[3]) << 24;
}

std::string BaseName(const std::string& path) {
  const size_t slash = path.find_last_of('/');
  return slash == std::string::npos ? path : path.substr(slash + 1);
}

}  // namespace

Result<RecordedFrameRecord> ReadRecordedFrameRecord(const uint8_t* bytes, size_t size, size_t offset) {
  const auto corrupt = [](const std::string& reason) { return Status(StatusCode::kCorruptData, reason); };
  const size_t left = size - offset;
  if (left < kRecordedFrameRecordBytes) {
    return corrupt("truncated record header (" + std::to_string(left) + " of " +
                   std::to_string(kRecordedFrameRecordBytes) + " bytes)");
  }
  const uint8_t* record = bytes + offset;
  if (std::memcmp(record, kRecordTag, 4) != 0) return corrupt("bad record tag");
  RecordedFrameRecord result;
  RawFrame& raw = result.raw;
  const uint32_t fourcc = GetU32(record + 4);
  raw.layout.format = PixelFormatFromFourcc(fourcc);
  const uint32_t width = GetU32(record + 8);
  const uint32_t height = GetU32(record + 12);
  raw.layout.bytes_per_line = GetU32(record + 16);
  const uint32_t quantisation = GetU32(record + 20);
  result.timestamp_ns = static_cast<int64_t>(static_cast<uint64_t>(GetU32(record + 24)) |
                                             static_cast<uint64_t>(GetU32(record + 28)) << 32);
  const uint32_t payload = GetU32(record + 32);
  if (raw.layout.format == PixelFormat::kUnknown) {
    char hex[16];
    std::snprintf(hex, sizeof(hex), "0x%08x", fourcc);
    return corrupt(std::string("unknown pixel format fourcc ") + hex);
  }
  if (quantisation > 1) return corrupt("bad quantisation " + std::to_string(quantisation));
  if (width > 0x7FFF || height > 0x7FFF) {
    return corrupt("bad frame size " + std::to_string(width) + "x" + std::to_string(height));
  }
  raw.layout.width = static_cast<int>(width);
  raw.layout.height = static_cast<int>(height);
  raw.layout.range = quantisation == 1 ? YuvRange::kFull : YuvRange::kLimited;
  if (payload > left - kRecordedFrameRecordBytes) {
    return corrupt("truncated payload (" + std::to_string(payload) + " bytes declared, " +
                   std::to_string(left - kRecordedFrameRecordBytes) + " left)");
  }
  Status layout_status = CheckRawFrameLayout(raw.layout, "layout");
  if (!layout_status.ok()) return corrupt(layout_status.message());
  raw.data = record + kRecordedFrameRecordBytes;
  raw.size = payload;
  result.end_offset = offset + kRecordedFrameRecordBytes + payload;
  return result;
}

// ---------------------------------------------------------------------------------------------
// Writer

RecordedFramesWriter::RecordedFramesWriter(std::string path, std::string temp_path, std::FILE* file)
    : path_(std::move(path)), temp_path_(std::move(temp_path)), file_(file) {}

Result<std::unique_ptr<RecordedFramesWriter>> RecordedFramesWriter::Create(const std::string& path) {
  std::string temp_path = path + ".tmp-" + std::to_string(::getpid());
  std::FILE* file = std::fopen(temp_path.c_str(), "wb");
  if (file == nullptr) return FileError(StatusCode::kIoError, path, "cannot create temporary file: " + ErrnoText());
  std::unique_ptr<RecordedFramesWriter> writer(new RecordedFramesWriter(path, std::move(temp_path), file));
  RECONAR_RETURN_IF_ERROR(writer->Write(kRecordedFramesMagic, kRecordedFramesHeaderBytes));
  return writer;
}

RecordedFramesWriter::~RecordedFramesWriter() {
  if (file_ != nullptr) {
    std::fclose(file_);
    std::remove(temp_path_.c_str());
  }
}

Status RecordedFramesWriter::Write(const void* data, size_t size) {
  if (file_ == nullptr) return FileError(StatusCode::kFailedPrecondition, path_, "recording already finished");
  if (size > 0 && std::fwrite(data, 1, size, file_) != size) {
    return FileError(StatusCode::kIoError, path_, "write failed: " + ErrnoText());
  }
  return Status::Ok();
}

Status RecordedFramesWriter::Append(const RawFrame& frame, int64_t timestamp_ns) {
  const RawFrameLayout& layout = frame.layout;
  RECONAR_RETURN_IF_ERROR(CheckRawFrameLayout(layout, path_));
  const bool separate_chroma = layout.format == PixelFormat::kNv12 && frame.chroma != nullptr;
  const size_t payload = frame.size + (separate_chroma ? frame.chroma_size : 0);
  if (payload > 0xFFFFFFFFu) return FileError(StatusCode::kInvalidArgument, path_, "frame larger than 4 GiB");
  uint8_t record[kRecordedFrameRecordBytes];
  std::memcpy(record, kRecordTag, 4);
  PutU32(record + 4, PixelFormatFourcc(layout.format));
  PutU32(record + 8, static_cast<uint32_t>(layout.width));
  PutU32(record + 12, static_cast<uint32_t>(layout.height));
  PutU32(record + 16, layout.bytes_per_line);
  PutU32(record + 20, layout.range == YuvRange::kFull ? 1u : 0u);
  const uint64_t timestamp = static_cast<uint64_t>(timestamp_ns);
  PutU32(record + 24, static_cast<uint32_t>(timestamp));
  PutU32(record + 28, static_cast<uint32_t>(timestamp >> 32));
  PutU32(record + 32, static_cast<uint32_t>(payload));
  RECONAR_RETURN_IF_ERROR(Write(record, sizeof(record)));
  if (separate_chroma) {
    // The reader finds UV right after bytes_per_line * height bytes of Y.
    const size_t luma_bytes = static_cast<size_t>(layout.bytes_per_line) * static_cast<size_t>(layout.height);
    if (frame.size != luma_bytes) {
      return FileError(StatusCode::kInvalidArgument, path_, "NV12 Y plane of " + std::to_string(frame.size) +
                                                                " bytes, expected " + std::to_string(luma_bytes));
    }
    RECONAR_RETURN_IF_ERROR(Write(frame.data, frame.size));
    RECONAR_RETURN_IF_ERROR(Write(frame.chroma, frame.chroma_size));
  } else {
    RECONAR_RETURN_IF_ERROR(Write(frame.data, frame.size));
  }
  ++frames_written_;
  return Status::Ok();
}

Status RecordedFramesWriter::Finish() {
  if (file_ == nullptr) return FileError(StatusCode::kFailedPrecondition, path_, "recording already finished");
  std::FILE* file = file_;
  file_ = nullptr;
  Status status;
  if (std::fflush(file) != 0) status = FileError(StatusCode::kIoError, path_, "write failed: " + ErrnoText());
  if (status.ok() && ::fsync(fileno(file)) != 0) {
    status = FileError(StatusCode::kIoError, path_, "fsync failed: " + ErrnoText());
  }
  if (std::fclose(file) != 0 && status.ok()) {
    status = FileError(StatusCode::kIoError, path_, "close failed: " + ErrnoText());
  }
  if (status.ok() && std::rename(temp_path_.c_str(), path_.c_str()) != 0) {
    status = FileError(StatusCode::kIoError, path_, "rename failed: " + ErrnoText());
  }
  if (!status.ok()) std::remove(temp_path_.c_str());
  return status;
}

// ---------------------------------------------------------------------------------------------
// Reader

RecordedFrameSource::RecordedFrameSource(std::string path, const uint8_t* map, size_t size,
                                         const FrameSourceOptions& options)
    : path_(std::move(path)),
      base_name_(BaseName(path_)),
      map_(map),
      size_(size),
      converter_(FrameConversionSettings{options.want_rgb, options.gray_range}),
      buffers_(options.buffer_count) {}

RecordedFrameSource::~RecordedFrameSource() {
  if (map_ != nullptr) ::munmap(const_cast<uint8_t*>(map_), size_);
}

Result<std::unique_ptr<RecordedFrameSource>> RecordedFrameSource::Open(const std::string& path,
                                                                       const FrameSourceOptions& options) {
  RECONAR_RETURN_IF_ERROR(options.Check());
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) {
    const int err = errno;
    return FileError(err == ENOENT ? StatusCode::kNotFound : StatusCode::kIoError, path,
                     std::string("cannot open: ") + std::strerror(err));
  }
  struct stat info {};
  if (::fstat(fd, &info) != 0 || !S_ISREG(info.st_mode)) {
    ::close(fd);
    return FileError(StatusCode::kInvalidArgument, path, "not a regular file");
  }
  const size_t size = static_cast<size_t>(info.st_size);
  if (size < kRecordedFramesHeaderBytes) {
    ::close(fd);
    return FileError(StatusCode::kCorruptData, path, "not a recorded-frames file (shorter than its header)");
  }
  void* map = ::mmap(nullptr, size, PROT_READ, MAP_PRIVATE, fd, 0);
  ::close(fd);
  if (map == MAP_FAILED) return FileError(StatusCode::kIoError, path, "mmap failed: " + ErrnoText());
  std::unique_ptr<RecordedFrameSource> source(
      new RecordedFrameSource(path, static_cast<const uint8_t*>(map), size, options));
  if (std::memcmp(map, kRecordedFramesMagic, kRecordedFramesHeaderBytes) != 0) {
    return FileError(StatusCode::kCorruptData, path, "not a recorded-frames file (no \"RECONAR-FRAMES 1\" header)");
  }
  return source;
}

Status RecordedFrameSource::FrameError(StatusCode code, const std::string& reason) const {
  return FileError(code, path_, "frame " + std::to_string(next_index_) + ": " + reason);
}

Result<Frame> RecordedFrameSource::NextFrame() {
  if (offset_ == size_) return EndOfStream(path_);
  if (buffers_.all_held()) {
    return FileError(StatusCode::kFailedPrecondition, path_,
                     "all " + std::to_string(buffers_.count()) + " frame buffers are held; release one first");
  }
  Result<RecordedFrameRecord> record = ReadRecordedFrameRecord(map_, size_, offset_);
  if (!record.ok()) return FrameError(record.status().code(), record.status().message());
  const RawFrame& raw = record->raw;
  const int64_t timestamp_ns = record->timestamp_ns;

  const bool resize_needed = buffers_.gray(0).width != raw.layout.width || buffers_.gray(0).height != raw.layout.height;
  if (resize_needed && buffers_.held() > 0) {
    return FrameError(StatusCode::kFailedPrecondition, "frame size changes while frames are held");
  }
  buffers_.Resize(raw.layout.width, raw.layout.height, converter_.settings().want_rgb);
  const int buffer = buffers_.Acquire();
  Frame frame;
  frame.index = next_index_;
  frame.timestamp_ns = timestamp_ns;
  frame.width = raw.layout.width;
  frame.height = raw.layout.height;
  frame.source_format = raw.layout.format;
  frame.buffer = buffer;
  char error_name[32];
  std::snprintf(error_name, sizeof(error_name), "frame %lld", static_cast<long long>(next_index_));
  Status status = converter_.Convert(raw, error_name, buffers_.gray(buffer), buffers_.rgb(buffer), &frame.gray,
                                     &frame.rgb);
  // A payload that does not decode is skipped: the container is intact, the next Next() goes on.
  offset_ = record->end_offset;
  ++next_index_;
  if (!status.ok()) {
    buffers_.Release(buffer);
    return status.WithContext(path_);
  }
  frame.name = buffers_.SetName(buffer, "%s#%lld", base_name_.c_str(), static_cast<long long>(frame.index));
  return frame;
}

void RecordedFrameSource::ReleaseFrame(const Frame& frame) { buffers_.Release(frame.buffer); }

std::string RecordedFrameSource::Describe() const {
  return "recording " + path_ + " (" + std::to_string(size_) + " bytes)";
}

}  // namespace reconar
