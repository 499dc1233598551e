#pragma once
// ImageFolderFrameSource: the .jpg/.jpeg/.png files of one directory (not recursive), in name
// order with numbers by value (core/base/file_order.h: frame_9 before frame_10), played as frames.
// JPEG goes through the same JpegFrameDecoder as MJPEG camera buffers; PNG through libpng's simplified API (8-bit RGB;
// alpha dropped). Both decode into the source's preallocated buffers. Frame i has timestamp i * 1e9 /
// options.folder_fps. (platform/ may not use core/io, hence its own small decoding here.)
#include <memory>
#include <string>
#include <vector>

#include "core/base/status.h"
#include "platform/camera/frame_buffers.h"
#include "platform/camera/frame_source.h"
#include "platform/camera/jpeg_frame_decoder.h"

namespace reconar {

class ImageFolderFrameSource final : public FrameSource {
 public:
  // kNotFound when the directory does not exist or holds no .jpg/.jpeg/.png file.
  static Result<std::unique_ptr<ImageFolderFrameSource>> Open(const std::string& directory,
                                                              const FrameSourceOptions& options = {});

  // Decode errors (kCorruptData/kUnsupported) name the file; the next call moves on to the next file.
  std::string Describe() const override;
  int buffer_count() const override { return buffers_.count(); }

  const std::vector<std::string>& file_names() const { return file_names_; }

 private:
  Result<Frame> NextFrame() override;
  void ReleaseFrame(const Frame& frame) override;
  ImageFolderFrameSource(std::string directory, std::vector<std::string> file_names, const FrameSourceOptions& options);
  Status DecodeInto(const std::string& path, int buffer);

  std::string directory_;
  std::vector<std::string> file_names_;
  FrameSourceOptions options_;
  size_t next_ = 0;
  std::string bytes_;  // the current file
  JpegFrameDecoder jpeg_;
  camera_internal::FrameBuffers buffers_;
};

}  // namespace reconar
