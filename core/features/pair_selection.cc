#include "core/features/pair_selection.h"

#include <algorithm>
#include <chrono>
#include <sstream>

#include "core/features/descriptor_distance.h"

namespace reconar {

Status PairSelectionOptions::Check() const {
  if (exhaustive_up_to < 2) {
    return InvalidArgument("PairSelectionOptions: exhaustive_up_to must be >= 2, got " +
                           std::to_string(exhaustive_up_to));
  }
  if (sequential_window < 0 || retrieved < 0) {
    return InvalidArgument("PairSelectionOptions: sequential_window and retrieved must be >= 0, got " +
                           std::to_string(sequential_window) + " and " + std::to_string(retrieved));
  }
  if (retrieval_descriptors < 1) {
    return InvalidArgument("PairSelectionOptions: retrieval_descriptors must be >= 1, got " +
                           std::to_string(retrieval_descriptors));
  }
  return vocabulary.Check();
}

std::string PairSelectionOptions::Describe() const {
  std::ostringstream out;
  out << "exhaustive<=" << exhaustive_up_to << ",window=" << sequential_window << ",retrieved=" << retrieved
      << ",descriptors=" << retrieval_descriptors << ",tree=" << vocabulary.branching << '^' << vocabulary.depth << '/'
      << vocabulary.kmeans_iterations << '/' << vocabulary.max_training_descriptors << '/' << std::hex
      << vocabulary.seed;
  return out.str();
}

Result<PairSelector> PairSelector::Create(const PairSelectionOptions& options) {
  RECONAR_RETURN_IF_ERROR(options.Check());
  return PairSelector(options);
}

std::vector<uint8_t> PairSelector::Subsample(const uint8_t* descriptors, int count) const {
  const int64_t kept = std::min<int64_t>(count, options_.retrieval_descriptors);
  std::vector<uint8_t> subset(static_cast<size_t>(kept) * kDescriptorSize);
  for (int64_t k = 0; k < kept; ++k) {
    const int64_t index = k * count / kept;
    std::copy_n(descriptors + index * kDescriptorSize, kDescriptorSize,
                subset.data() + static_cast<size_t>(k) * kDescriptorSize);
  }
  return subset;
}

std::vector<int32_t> PairSelector::Words(const std::vector<uint8_t>& descriptors) const {
  std::vector<int32_t> words;
  words.reserve(descriptors.size() / kDescriptorSize);
  for (size_t offset = 0; offset < descriptors.size(); offset += kDescriptorSize) {
    const int word = vocabulary_.Quantize(&descriptors[offset]);
    if (word >= 0) words.push_back(word);
  }
  return words;
}

Status PairSelector::Train() {
  const auto start = std::chrono::steady_clock::now();
  std::vector<uint8_t> training;
  for (const std::vector<uint8_t>& image : untrained_descriptors_)
    training.insert(training.end(), image.begin(), image.end());
  const int count = static_cast<int>(training.size() / kDescriptorSize);
  // Images without descriptors leave an empty vocabulary: retrieval then finds nothing.
  if (count > 0) {
    RECONAR_ASSIGN_OR_RETURN(vocabulary_, VocabularyTree::Train(training.data(), count, options_.vocabulary));
  }
  std::vector<std::vector<int32_t>> words;
  words.reserve(untrained_descriptors_.size());
  for (const std::vector<uint8_t>& image : untrained_descriptors_) words.push_back(Words(image));
  idf_ = InverseDocumentFrequency(vocabulary_.num_words(), words);
  for (std::vector<int32_t>& image_words : words) bags_.push_back(MakeBagOfWords(std::move(image_words), idf_));
  untrained_descriptors_ = {};
  seconds_training_ = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return Status::Ok();
}

Result<std::vector<int>> PairSelector::Add(const uint8_t* descriptors, int count) {
  if (count < 0 || (count > 0 && descriptors == nullptr)) {
    return InvalidArgument("PairSelector: image " + std::to_string(num_images_) + " has " + std::to_string(count) +
                           " descriptors at " + (descriptors ? "a valid pointer" : "a null pointer"));
  }
  const int image = num_images_;
  std::vector<int> partners;
  if (image < options_.exhaustive_up_to) {
    untrained_descriptors_.push_back(Subsample(descriptors, count));
    for (int other = 0; other < image; ++other) partners.push_back(other);
    ++num_images_;
    return partners;
  }
  if (image == options_.exhaustive_up_to) RECONAR_RETURN_IF_ERROR(Train());
  bags_.push_back(MakeBagOfWords(Words(Subsample(descriptors, count)), idf_));
  ++num_images_;

  const int window_start = std::max(0, image - options_.sequential_window);
  // The best-scoring earlier images outside the window (ties: the earlier image); nothing shared,
  // nothing retrieved.
  const BagOfWords& query = bags_.back();
  scores_.assign(static_cast<size_t>(window_start), 0.0f);
  candidates_.clear();
  for (int other = 0; other < window_start; ++other) {
    scores_[static_cast<size_t>(other)] = BagOfWordsScore(query, bags_[static_cast<size_t>(other)]);
    if (scores_[static_cast<size_t>(other)] > 0.0f) candidates_.push_back(other);
  }
  const size_t kept = std::min(candidates_.size(), static_cast<size_t>(options_.retrieved));
  std::partial_sort(candidates_.begin(), candidates_.begin() + static_cast<int64_t>(kept), candidates_.end(),
                    [this](int a, int b) {
                      const float score_a = scores_[static_cast<size_t>(a)], score_b = scores_[static_cast<size_t>(b)];
                      return score_a > score_b || (score_a == score_b && a < b);
                    });
  partners.assign(candidates_.begin(), candidates_.begin() + static_cast<int64_t>(kept));
  std::sort(partners.begin(), partners.end());
  for (int other = window_start; other < image; ++other) partners.push_back(other);
  return partners;
}

}  // namespace reconar
