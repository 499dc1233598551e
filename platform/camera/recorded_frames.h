#pragma once
// Recorded raw camera frames: a ".frames" file holds buffers exactly as a device delivered them
// (YUYV, NV12, MJPEG, GREY, RGB3), so a session can be replayed through the same conversion code.
//
// File format (every integer little-endian):
//   header  16 bytes  "RECONAR-FRAMES 1"
//   then per frame a 36-byte record header followed by the payload:
//     4  tag              "FRAM"
//     4  u32 fourcc       V4L2 fourcc: 'YUYV', 'NV12', 'MJPG', 'GREY', 'RGB3'
//     4  u32 width        pixels
//     4  u32 height       pixels
//     4  u32 bytes_per_line  row pitch of plane 0 (NV12: Y and UV planes alike); 0 for MJPG
//     4  u32 quantisation 0 = limited range (BT.601 16..235), 1 = full range
//     8  i64 timestamp_ns capture time (CLOCK_MONOTONIC for V4L2/libcamera)
//     4  u32 payload_size bytes that follow (NV12: Y plane, then UV plane, bytes_per_line apart)
//     payload
// The file ends after the last payload. Anything else is kCorruptData naming the file and the
// frame index.
#include <cstdint>
#include <cstdio>
#include <memory>
#include <string>

#include "core/base/status.h"
#include "platform/camera/frame_buffers.h"
#include "platform/camera/frame_source.h"
#include "platform/camera/raw_frame.h"

namespace reconar {

inline constexpr char kRecordedFramesMagic[] = "RECONAR-FRAMES 1";  // without its terminator: 16 bytes
inline constexpr size_t kRecordedFramesHeaderBytes = 16;
inline constexpr size_t kRecordedFrameRecordBytes = 36;

// One record of a .frames file: its raw buffer, pointing into the file's bytes, and capture time.
struct RecordedFrameRecord {
  RawFrame raw;
  int64_t timestamp_ns = 0;
  size_t end_offset = 0;  // where the next record starts
};

// Reads the record at `offset` (past the file's header, at most `size`) of a .frames file's
// `bytes`. kCorruptData with the reason when the record is damaged; the caller names the file
// and the frame.
Result<RecordedFrameRecord> ReadRecordedFrameRecord(const uint8_t* bytes, size_t size, size_t offset);

// Writes a .frames file atomically: frames go to "<path>.tmp-<pid>", Finish() fsyncs and renames
// it over <path>. A writer destroyed without Finish() removes its temporary file.
class RecordedFramesWriter {
 public:
  static Result<std::unique_ptr<RecordedFramesWriter>> Create(const std::string& path);
  ~RecordedFramesWriter();
  RecordedFramesWriter(const RecordedFramesWriter&) = delete;
  RecordedFramesWriter& operator=(const RecordedFramesWriter&) = delete;

  // Appends one raw buffer (NV12 with a separate chroma plane is stored as Y plane then UV plane).
  Status Append(const RawFrame& frame, int64_t timestamp_ns);
  Status Finish();
  int64_t frames_written() const { return frames_written_; }
  const std::string& path() const { return path_; }

 private:
  RecordedFramesWriter(std::string path, std::string temp_path, std::FILE* file);
  Status Write(const void* data, size_t size);

  std::string path_;
  std::string temp_path_;
  std::FILE* file_ = nullptr;
  int64_t frames_written_ = 0;
};

// Plays a .frames file. The file is memory-mapped: NV12 and GREY gray views (and RGB3 rgb views)
// point straight into the mapping. Damage is reported when playback reaches it, so every frame
// before it is still delivered.
class RecordedFrameSource final : public FrameSource {
 public:
  // kNotFound for a missing file, kCorruptData when the header is not "RECONAR-FRAMES 1".
  static Result<std::unique_ptr<RecordedFrameSource>> Open(const std::string& path,
                                                           const FrameSourceOptions& options = {});
  ~RecordedFrameSource() override;

  std::string Describe() const override;
  int buffer_count() const override { return buffers_.count(); }

 private:
  Result<Frame> NextFrame() override;
  void ReleaseFrame(const Frame& frame) override;
  RecordedFrameSource(std::string path, const uint8_t* map, size_t size, const FrameSourceOptions& options);
  Status FrameError(StatusCode code, const std::string& reason) const;

  std::string path_;
  std::string base_name_;
  const uint8_t* map_ = nullptr;
  size_t size_ = 0;
  size_t offset_ = kRecordedFramesHeaderBytes;
  int64_t next_index_ = 0;
  RawFrameConverter converter_;
  camera_internal::FrameBuffers buffers_;
};

}  // namespace reconar
