#pragma once
// Feature files.
// - Our binary format (.rfeat, little-endian), one per image in <project>/features/:
//     char magic[8] = "RCNRFEAT"; uint32 version = 1; uint32 image_width, image_height;
//     uint32 count; uint32 descriptor_bytes = 128;
//     count x {float x, y, scale, orientation, response; int32 octave};
//     count x 128 descriptor bytes.
// - Lowe's ASCII .key format, read by Bundler and PMVS: "N 128", then per feature a line
//   "row col scale orientation" (orientation in radians in (-pi, pi]) and 128 integers, 20 per line.
#include <string>

#include "core/base/status.h"
#include "core/features/sift/sift.h"

namespace reconar {

struct FeatureFile {
  int image_width = 0;
  int image_height = 0;
  SiftFeatures features;
};

// What a feature file's header says; ReadFeatureFileHeader reads only these 32 bytes.
struct FeatureFileHeader {
  int image_width = 0;
  int image_height = 0;
  size_t count = 0;  // keypoints (and descriptors)
};

Status WriteFeatureFile(const std::string& path, const FeatureFile& file);
Result<FeatureFile> ReadFeatureFile(const std::string& path);
// The header alone, checked as ReadFeatureFile checks it (magic, version, descriptor size, and
// the file's size against the count), for passes that need only the sizes (the matcher's
// memory plan).
Result<FeatureFileHeader> ReadFeatureFileHeader(const std::string& path);

Status WriteLoweKeyFile(const std::string& path, const SiftFeatures& features);
Result<SiftFeatures> ReadLoweKeyFile(const std::string& path);

}  // namespace reconar
