#include "core/mvs/dense_memory.h"

#include <algorithm>
#include <functional>
#include <string>

#include "core/mvs/undistort.h"

namespace reconar {

size_t EstimateDenseBytes(const DenseMemoryInput& input, int level, int cluster_size) {
  std::vector<double> pixels;
  double largest_full = 0.0;
  for (const auto& [width, height] : input.image_sizes) {
    pixels.push_back(static_cast<double>(width >> level) * static_cast<double>(height >> level));
    largest_full = std::max(largest_full, static_cast<double>(width) * static_cast<double>(height));
  }
  std::sort(pixels.begin(), pixels.end(), std::greater<double>());
  const double per_pixel = kViewBytesPerPixel + input.work_bytes_per_pixel;
  double bytes = static_cast<double>(input.baseline_bytes);
  for (size_t i = 0; i < pixels.size() && static_cast<int>(i) < cluster_size; ++i) bytes += per_pixel * pixels[i];
  const double scale = 1.0 / static_cast<double>(1 << (2 * level));
  bytes += static_cast<double>(std::max(1, input.num_threads)) * largest_full * 3.0 * (1.0 + scale);
  return static_cast<size_t>(bytes);
}

int FinestLevelWithinSize(const std::vector<std::pair<int, int>>& image_sizes, int max_image_size) {
  if (max_image_size <= 0) return 0;
  int longest = 0;
  for (const auto& [width, height] : image_sizes) longest = std::max({longest, width, height});
  int level = 0;
  while (level < kMaxDenseLevel && (longest >> level) > max_image_size) ++level;
  return level;
}

Result<DenseLevelChoice> ChooseDenseLevel(const DenseMemoryInput& input, int requested_level, size_t budget_bytes,
                                          int min_cluster_size) {
  if (requested_level < -1 || requested_level > kMaxDenseLevel) {
    return InvalidArgument("dense level must be -1 (auto) or 0.." + std::to_string(kMaxDenseLevel));
  }
  const int images = static_cast<int>(input.image_sizes.size());
  const int wanted = std::max(1, std::min(input.max_cluster_size, images));
  DenseLevelChoice choice;
  if (requested_level < 0)
    choice.finest_level_within_size = FinestLevelWithinSize(input.image_sizes, input.max_image_size);
  const int first = requested_level < 0 ? choice.finest_level_within_size : requested_level;
  const int last = requested_level < 0 ? kMaxDenseLevel : requested_level;
  for (int level = first; level <= last; ++level) {
    const size_t bytes = EstimateDenseBytes(input, level, wanted);
    if (bytes <= budget_bytes) {
      choice.level = level;
      choice.max_cluster_size = input.max_cluster_size;
      choice.estimated_bytes = bytes;
      return choice;
    }
  }
  for (int size = wanted - 1; size >= std::max(1, min_cluster_size); --size) {
    const size_t bytes = EstimateDenseBytes(input, last, size);
    if (bytes <= budget_bytes) {
      choice.level = last;
      choice.max_cluster_size = size;
      choice.estimated_bytes = bytes;
      choice.reduced_cluster_size = true;
      return choice;
    }
  }
  const size_t needed = EstimateDenseBytes(input, last, std::max(1, std::min(min_cluster_size, images)));
  return ResourceExhausted("dense: a cluster of " + std::to_string(min_cluster_size) + " views at level " +
                           std::to_string(last) + " needs about " + std::to_string(needed >> 20) +
                           " MiB, more than the memory budget of " + std::to_string(budget_bytes >> 20) + " MiB");
}

DenseLevelChoice GrowClusterToBudget(const DenseMemoryInput& input, const DenseLevelChoice& choice,
                                     size_t budget_bytes) {
  DenseLevelChoice grown = choice;
  if (choice.reduced_cluster_size) return grown;
  const int images = static_cast<int>(input.image_sizes.size());
  for (int size = images; size > choice.max_cluster_size; --size) {
    const size_t bytes = EstimateDenseBytes(input, choice.level, size);
    if (bytes <= budget_bytes) {
      grown.max_cluster_size = size;
      grown.estimated_bytes = bytes;
      break;
    }
  }
  return grown;
}

}  // namespace reconar
