#include "tests/core/sfm/sample_localization_map.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cstring>
#include <random>

#include "core/base/binary_io.h"
#include "core/base/check.h"

namespace reconar::testing {

LocalizationMap SampleLocalizationMap(int num_points, int num_keyframes, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  std::uniform_int_distribution<int> byte(0, 255);
  std::uniform_int_distribution<int> noise(-6, 6);
  LocalizationMap map;
  map.frame = "metres, world tag 0";
  map.metric = true;
  for (int i = 0; i < num_points; ++i) {
    map.points.emplace_back(3.0 * unit(rng), 2.0 * unit(rng), 5.0 + unit(rng));
    map.colors.push_back(
        {static_cast<uint8_t>(byte(rng)), static_cast<uint8_t>(byte(rng)), static_cast<uint8_t>(byte(rng))});
    for (int d = 0; d < 128; ++d) map.point_descriptors.push_back(static_cast<uint8_t>(byte(rng) / 2));
  }
  std::vector<uint8_t> all_descriptors;
  for (int k = 0; k < num_keyframes; ++k) {
    MapKeyframe keyframe;
    keyframe.name = "IMG_" + std::to_string(1000 + k) + ".JPG";
    keyframe.width = 640;
    keyframe.height = 480;
    keyframe.camera.focal = 500.0 + 10.0 * k;
    keyframe.camera.cx = 320.5;
    keyframe.camera.cy = 239.25;
    keyframe.camera.k1 = -0.01 * k;
    keyframe.camera.k2 = 0.001;
    keyframe.camera.aspect = 1.0;
    keyframe.cam_from_world.rotation =
        Eigen::Quaterniond(1.0, 0.1 * unit(rng), 0.1 * unit(rng), 0.1 * unit(rng)).normalized().toRotationMatrix();
    keyframe.cam_from_world.translation = Eigen::Vector3d(unit(rng), unit(rng), unit(rng));
    for (int i = 0; i < num_points; ++i) {
      if (std::uniform_real_distribution<double>(0.0, 1.0)(rng) > 0.6) continue;
      keyframe.keypoints.emplace_back(static_cast<float>(320.0 + 300.0 * unit(rng)),
                                      static_cast<float>(240.0 + 220.0 * unit(rng)));
      keyframe.point_ids.push_back(i);
      for (int d = 0; d < 128; ++d) {
        const int value = map.point_descriptors[128 * i + d] + noise(rng);
        keyframe.descriptors.push_back(static_cast<uint8_t>(std::clamp(value, 0, 255)));
      }
    }
    all_descriptors.insert(all_descriptors.end(), keyframe.descriptors.begin(), keyframe.descriptors.end());
    map.keyframes.push_back(std::move(keyframe));
  }
  VocabularyTreeOptions options;
  options.branching = 4;
  options.depth = 2;
  options.kmeans_iterations = 4;
  options.seed = seed;
  Result<VocabularyTree> vocabulary =
      VocabularyTree::Train(all_descriptors.data(), static_cast<int>(all_descriptors.size() / 128), options);
  RECONAR_CHECK(vocabulary.ok()) << vocabulary.status().ToString();
  map.vocabulary = std::move(vocabulary).value();
  std::vector<std::vector<int32_t>> words(map.keyframes.size());
  for (size_t k = 0; k < map.keyframes.size(); ++k) {
    const std::vector<uint8_t>& descriptors = map.keyframes[k].descriptors;
    for (size_t j = 0; j < descriptors.size(); j += 128) words[k].push_back(map.vocabulary.Quantize(&descriptors[j]));
  }
  Result<InvertedFile> index = InvertedFile::Build(map.vocabulary.num_words(), words);
  RECONAR_CHECK(index.ok()) << index.status().ToString();
  map.keyframe_index = std::move(index).value();
  return map;
}

void RepairMapHeader(std::string* file_bytes) {
  constexpr size_t kHeaderBytes = 24;
  if (file_bytes->size() < kHeaderBytes) return;
  const uint64_t payload_bytes = file_bytes->size() - kHeaderBytes;
  const uint32_t crc = Crc32(file_bytes->data() + kHeaderBytes, payload_bytes);
  std::memcpy(&(*file_bytes)[12], &payload_bytes, sizeof(payload_bytes));
  std::memcpy(&(*file_bytes)[20], &crc, sizeof(crc));
}

}  // namespace reconar::testing
