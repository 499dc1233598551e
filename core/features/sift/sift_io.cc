#include "core/features/sift/sift_io.h"

#include <cerrno>
#include <cinttypes>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <sstream>

#include "core/base/atomic_file.h"

namespace reconar {
namespace {

constexpr char kMagic[8] = {'R', 'C', 'N', 'R', 'F', 'E', 'A', 'T'};
constexpr uint32_t kVersion = 1;
constexpr uint32_t kDescriptorBytes = 128;

struct PackedKeypoint {
  float x, y, scale, orientation, response;
  int32_t octave;
};
static_assert(sizeof(PackedKeypoint) == 24, "feature file layout");

template <typename T>
void Append(std::string* out, const T& value) {
  out->append(reinterpret_cast<const char*>(&value), sizeof(T));
}

constexpr size_t kHeader = sizeof(kMagic) + 5 * sizeof(uint32_t);

// Checks the first kHeader bytes of a file of file_size bytes (head holds min(kHeader, file_size)).
Result<FeatureFileHeader> ParseHeader(const std::string& path, const char* head, uint64_t file_size) {
  if (file_size < kHeader || std::memcmp(head, kMagic, sizeof(kMagic)) != 0) {
    return FileError(StatusCode::kCorruptData, path, "not a reconar feature file");
  }
  uint32_t header[5];
  std::memcpy(header, head + sizeof(kMagic), sizeof(header));
  if (header[0] != kVersion) {
    return FileError(StatusCode::kUnsupported, path, "feature file version " + std::to_string(header[0]));
  }
  if (header[4] != kDescriptorBytes) {
    return FileError(StatusCode::kCorruptData, path, "descriptor size " + std::to_string(header[4]));
  }
  const uint64_t count = header[3];
  const uint64_t expected = kHeader + count * (sizeof(PackedKeypoint) + kDescriptorBytes);
  if (file_size != expected) {
    return FileError(StatusCode::kCorruptData, path,
                     "truncated or padded: " + std::to_string(file_size) + " bytes, expected " +
                         std::to_string(expected));
  }
  FeatureFileHeader parsed;
  parsed.image_width = static_cast<int>(header[1]);
  parsed.image_height = static_cast<int>(header[2]);
  parsed.count = static_cast<size_t>(count);
  return parsed;
}

}  // namespace

Status WriteFeatureFile(const std::string& path, const FeatureFile& file) {
  const SiftFeatures& f = file.features;
  if (f.descriptors.size() != f.keypoints.size() * kDescriptorBytes) {
    return Internal(path + ": descriptor count does not match keypoint count");
  }
  std::string bytes;
  bytes.reserve(32 + f.keypoints.size() * (sizeof(PackedKeypoint) + kDescriptorBytes));
  bytes.append(kMagic, sizeof(kMagic));
  Append(&bytes, kVersion);
  Append(&bytes, static_cast<uint32_t>(file.image_width));
  Append(&bytes, static_cast<uint32_t>(file.image_height));
  Append(&bytes, static_cast<uint32_t>(f.keypoints.size()));
  Append(&bytes, kDescriptorBytes);
  for (const SiftKeypoint& kp : f.keypoints) {
    Append(&bytes, PackedKeypoint{kp.x, kp.y, kp.scale, kp.orientation, kp.response, kp.octave});
  }
  bytes.append(reinterpret_cast<const char*>(f.descriptors.data()), f.descriptors.size());
  return WriteFileAtomically(path, bytes);
}

Result<FeatureFile> ReadFeatureFile(const std::string& path) {
  RECONAR_ASSIGN_OR_RETURN(const std::string bytes, ReadFileToString(path));
  RECONAR_ASSIGN_OR_RETURN(const FeatureFileHeader header, ParseHeader(path, bytes.data(), bytes.size()));
  const size_t count = header.count;
  FeatureFile file;
  file.image_width = header.image_width;
  file.image_height = header.image_height;
  file.features.keypoints.resize(count);
  const char* cursor = bytes.data() + kHeader;
  for (SiftKeypoint& kp : file.features.keypoints) {
    PackedKeypoint packed;
    std::memcpy(&packed, cursor, sizeof(packed));
    cursor += sizeof(packed);
    kp = SiftKeypoint{packed.x, packed.y, packed.scale, packed.orientation, packed.response, packed.octave};
  }
  file.features.descriptors.assign(reinterpret_cast<const uint8_t*>(cursor),
                                   reinterpret_cast<const uint8_t*>(cursor) + count * kDescriptorBytes);
  return file;
}

Result<FeatureFileHeader> ReadFeatureFileHeader(const std::string& path) {
  std::FILE* file = std::fopen(path.c_str(), "rb");
  if (file == nullptr) {
    const int err = errno;
    return FileError(err == ENOENT ? StatusCode::kNotFound : StatusCode::kIoError, path,
                     std::string("cannot open: ") + std::strerror(err));
  }
  char head[kHeader] = {};
  const size_t read = std::fread(head, 1, sizeof(head), file);
  const bool sized = std::fseek(file, 0, SEEK_END) == 0;
  const long size = sized ? std::ftell(file) : -1;
  const bool failed = std::ferror(file) != 0 || size < 0;
  std::fclose(file);
  if (failed) return FileError(StatusCode::kIoError, path, "read failed");
  if (read < kHeader && static_cast<uint64_t>(size) >= kHeader) {
    return FileError(StatusCode::kIoError, path, "read failed");
  }
  return ParseHeader(path, head, static_cast<uint64_t>(size));
}

Status WriteLoweKeyFile(const std::string& path, const SiftFeatures& features) {
  std::string text;
  text.reserve(features.keypoints.size() * 560 + 16);
  text += std::to_string(features.keypoints.size()) + " 128\n";
  char line[128];
  for (size_t i = 0; i < features.keypoints.size(); ++i) {
    const SiftKeypoint& kp = features.keypoints[i];
    const double orientation = kp.orientation > M_PI ? kp.orientation - 2 * M_PI : kp.orientation;
    std::snprintf(line, sizeof(line), "%.2f %.2f %.2f %.3f\n", kp.y, kp.x, kp.scale, orientation);
    text += line;
    const uint8_t* d = features.descriptor(i);
    for (int k = 0; k < 128; ++k) {
      text += std::to_string(d[k]);
      text += (k % 20 == 19 || k == 127) ? '\n' : ' ';
    }
  }
  return WriteFileAtomically(path, text);
}

Result<SiftFeatures> ReadLoweKeyFile(const std::string& path) {
  RECONAR_ASSIGN_OR_RETURN(const std::string text, ReadFileToString(path));
  std::istringstream in(text);
  long long count = -1;
  int length = 0;
  if (!(in >> count >> length) || count < 0 || length != 128) {
    return FileError(StatusCode::kCorruptData, path, "bad .key header (expected \"N 128\")");
  }
  SiftFeatures features;
  features.keypoints.resize(static_cast<size_t>(count));
  features.descriptors.resize(static_cast<size_t>(count) * 128);
  for (long long i = 0; i < count; ++i) {
    SiftKeypoint& kp = features.keypoints[i];
    if (!(in >> kp.y >> kp.x >> kp.scale >> kp.orientation)) {
      return FileError(StatusCode::kCorruptData, path, "truncated at keypoint " + std::to_string(i));
    }
    if (kp.orientation < 0) kp.orientation += static_cast<float>(2 * M_PI);
    for (int k = 0; k < 128; ++k) {
      int v = -1;
      if (!(in >> v) || v < 0 || v > 255) {
        return FileError(StatusCode::kCorruptData, path, "bad descriptor value at keypoint " + std::to_string(i));
      }
      features.descriptors[i * 128 + k] = static_cast<uint8_t>(v);
    }
  }
  return features;
}

}  // namespace reconar
