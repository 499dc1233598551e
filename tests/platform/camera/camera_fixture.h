#pragma once
// Shared by the camera tests: the committed recording, access to its raw records, view equality.
#include <cstdint>
#include <string>

#include "core/base/image.h"

namespace reconar::testing {

// tests/platform/camera/data/tag_320x240.frames (see data/README.txt): MJPG, NV12, YUYV.
std::string CameraFixturePath();

// Little-endian u32 at `at`.
uint32_t U32At(const std::string& bytes, size_t at);
// Byte offset of record `index` (its 36-byte header) in a .frames file's bytes.
size_t RecordOffset(const std::string& file, int index);
// The payload of record `index`.
std::string RecordPayload(const std::string& file, int index);

// "<gtest temp dir>/camera_<name>", emptied and created.
std::string FreshCameraTestDirectory(const std::string& name);

bool SameViews(const ImageView<const uint8_t>& a, const ImageView<const uint8_t>& b);

}  // namespace reconar::testing
