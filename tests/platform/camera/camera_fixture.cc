#include "tests/platform/camera/camera_fixture.h"

#include <gtest/gtest.h>

#include <cstring>
#include <filesystem>

#include "platform/camera/recorded_frames.h"

namespace reconar::testing {

std::string CameraFixturePath() {
  return std::string(RECONAR_SOURCE_DIR) + "/tests/platform/camera/data/tag_320x240.frames";
}

uint32_t U32At(const std::string& bytes, size_t at) {
  uint32_t value = 0;
  for (int i = 3; i >= 0; --i) value = value << 8 | static_cast<uint8_t>(bytes[at + static_cast<size_t>(i)]);
  return value;
}

size_t RecordOffset(const std::string& file, int index) {
  size_t at = kRecordedFramesHeaderBytes;
  for (int i = 0; i < index; ++i) at += kRecordedFrameRecordBytes + U32At(file, at + 32);
  return at;
}

std::string RecordPayload(const std::string& file, int index) {
  const size_t at = RecordOffset(file, index);
  return file.substr(at + kRecordedFrameRecordBytes, U32At(file, at + 32));
}

std::string FreshCameraTestDirectory(const std::string& name) {
  const std::string path = ::testing::TempDir() + "camera_" + name;
  std::filesystem::remove_all(path);
  std::filesystem::create_directories(path);
  return path;
}

bool SameViews(const ImageView<const uint8_t>& a, const ImageView<const uint8_t>& b) {
  if (a.width != b.width || a.height != b.height) return false;
  for (int y = 0; y < a.height; ++y) {
    if (std::memcmp(a.row(y), b.row(y), static_cast<size_t>(a.width)) != 0) return false;
  }
  return true;
}

}  // namespace reconar::testing
