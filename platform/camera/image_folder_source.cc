#include "platform/camera/image_folder_source.h"

#include <png.h>

#include <algorithm>
#include <cctype>
#include <cstdio>
#include <cstring>
#include <filesystem>

#include "core/base/atomic_file.h"
#include "core/base/file_order.h"
#include "platform/camera/pixel_convert.h"

namespace reconar {

namespace {

bool HasImageExtension(const std::string& name) {
  const size_t dot = name.find_last_of('.');
  if (dot == std::string::npos) return false;
  std::string extension = name.substr(dot + 1);
  std::transform(extension.begin(), extension.end(), extension.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return extension == "jpg" || extension == "jpeg" || extension == "png";
}

const uint8_t* Bytes(const std::string& bytes) { return reinterpret_cast<const uint8_t*>(bytes.data()); }

bool IsPng(const std::string& bytes) {
  static const uint8_t kSignature[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1A, '\n'};
  return bytes.size() >= 8 && std::memcmp(bytes.data(), kSignature, 8) == 0;
}

class PngImage {
 public:
  PngImage() {
    std::memset(&image_, 0, sizeof(image_));
    image_.version = PNG_IMAGE_VERSION;
  }
  ~PngImage() { png_image_free(&image_); }
  PngImage(const PngImage&) = delete;
  PngImage& operator=(const PngImage&) = delete;
  png_image* get() { return &image_; }

 private:
  png_image image_;
};

}  // namespace

ImageFolderFrameSource::ImageFolderFrameSource(std::string directory, std::vector<std::string> file_names,
                                               const FrameSourceOptions& options)
    : directory_(std::move(directory)),
      file_names_(std::move(file_names)),
      options_(options),
      buffers_(options.buffer_count) {}

Result<std::unique_ptr<ImageFolderFrameSource>> ImageFolderFrameSource::Open(const std::string& directory,
                                                                             const FrameSourceOptions& options) {
  RECONAR_RETURN_IF_ERROR(options.Check());
  std::error_code ec;
  if (!std::filesystem::is_directory(directory, ec)) {
    return FileError(StatusCode::kNotFound, directory, "no such directory");
  }
  std::vector<std::string> names;
  for (const auto& entry : std::filesystem::directory_iterator(directory, ec)) {
    const std::string name = entry.path().filename().string();
    if (HasImageExtension(name) && entry.is_regular_file(ec)) names.push_back(name);
  }
  if (ec) return FileError(StatusCode::kIoError, directory, "cannot list directory: " + ec.message());
  if (names.empty()) return FileError(StatusCode::kNotFound, directory, "no .jpg/.jpeg/.png images in the directory");
  SortFileNames(&names);
  return std::unique_ptr<ImageFolderFrameSource>(new ImageFolderFrameSource(directory, std::move(names), options));
}

Status ImageFolderFrameSource::DecodeInto(const std::string& path, int buffer) {
  const ImageView<uint8_t> gray = buffers_.gray(buffer);
  const ImageView<uint8_t> rgb = buffers_.rgb(buffer);
  if (!IsPng(bytes_)) return jpeg_.Decode(Bytes(bytes_), bytes_.size(), path, gray, rgb);
  PngImage png;
  if (png_image_begin_read_from_memory(png.get(), bytes_.data(), bytes_.size()) == 0 ||
      static_cast<int>(png.get()->width) != gray.width || static_cast<int>(png.get()->height) != gray.height) {
    return FileError(StatusCode::kCorruptData, path, std::string("invalid PNG data: ") + png.get()->message);
  }
  png.get()->format = PNG_FORMAT_RGB;
  if (rgb.empty()) {
    // Decode into a temporary RGB image only for the gray conversion.
    std::vector<uint8_t> scratch(static_cast<size_t>(3 * gray.width) * static_cast<size_t>(gray.height));
    const ImageView<uint8_t> view(3 * gray.width, gray.height, 3 * gray.width, scratch.data());
    if (png_image_finish_read(png.get(), nullptr, scratch.data(), 0, nullptr) == 0) {
      return FileError(StatusCode::kCorruptData, path, std::string("invalid PNG data: ") + png.get()->message);
    }
    RgbToGray(view, gray);
    return Status::Ok();
  }
  if (png_image_finish_read(png.get(), nullptr, rgb.data, static_cast<png_int_32>(rgb.stride), nullptr) == 0) {
    return FileError(StatusCode::kCorruptData, path, std::string("invalid PNG data: ") + png.get()->message);
  }
  RgbToGray(rgb, gray);
  return Status::Ok();
}

Result<Frame> ImageFolderFrameSource::NextFrame() {
  if (next_ >= file_names_.size()) return EndOfStream(directory_);
  if (buffers_.all_held()) {
    return FileError(StatusCode::kFailedPrecondition, directory_,
                     "all " + std::to_string(buffers_.count()) + " frame buffers are held; release one first");
  }
  const size_t index = next_++;
  const std::string& name = file_names_[index];
  const std::string path = (std::filesystem::path(directory_) / name).string();
  RECONAR_ASSIGN_OR_RETURN(bytes_, ReadFileToString(path));
  int width = 0;
  int height = 0;
  if (IsPng(bytes_)) {
    PngImage png;
    if (png_image_begin_read_from_memory(png.get(), bytes_.data(), bytes_.size()) == 0) {
      return FileError(StatusCode::kCorruptData, path, std::string("invalid PNG data: ") + png.get()->message);
    }
    width = static_cast<int>(png.get()->width);
    height = static_cast<int>(png.get()->height);
  } else {
    RECONAR_ASSIGN_OR_RETURN(const JpegHeader header, jpeg_.ReadHeader(Bytes(bytes_), bytes_.size(), path));
    width = header.width;
    height = header.height;
  }
  constexpr int kMaxSide = 1 << 15;
  if (width <= 0 || height <= 0 || width > kMaxSide || height > kMaxSide) {
    return FileError(StatusCode::kUnsupported, path, "image size " + std::to_string(width) + "x" +
                                                         std::to_string(height) + " is out of range");
  }
  if ((width != buffers_.gray(0).width || height != buffers_.gray(0).height) && buffers_.held() > 0) {
    return FileError(StatusCode::kFailedPrecondition, path, "image size differs from the held frames");
  }
  buffers_.Resize(width, height, options_.want_rgb);
  const int buffer = buffers_.Acquire();
  Status status = DecodeInto(path, buffer);
  if (!status.ok()) {
    buffers_.Release(buffer);
    return status;
  }
  Frame frame;
  frame.name = name;
  frame.index = static_cast<int64_t>(index);
  frame.timestamp_ns = static_cast<int64_t>(static_cast<double>(index) * 1e9 / options_.folder_fps + 0.5);
  frame.width = width;
  frame.height = height;
  frame.source_format = IsPng(bytes_) ? PixelFormat::kRgb24 : PixelFormat::kMjpeg;
  frame.gray = buffers_.gray(buffer);
  frame.rgb = buffers_.rgb(buffer);
  frame.buffer = buffer;
  return frame;
}

void ImageFolderFrameSource::ReleaseFrame(const Frame& frame) { buffers_.Release(frame.buffer); }

std::string ImageFolderFrameSource::Describe() const {
  return "folder " + directory_ + " (" + std::to_string(file_names_.size()) + " images)";
}

}  // namespace reconar
