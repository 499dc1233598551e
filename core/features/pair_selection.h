#pragma once
// Which pairs of images to match. The match stage and the live capture apply the same rule, so
// that `reconar reconstruct` reuses the matches a capture computed:
//   - the first `exhaustive_up_to` images: every pair;
//   - each later image: the `sequential_window` images just before it, plus the `retrieved`
//     earlier images most like it by image retrieval (tf-idf bags of visual words scored as in
//     Nistér & Stewénius, CVPR 2006), with a vocabulary tree trained on the first
//     `exhaustive_up_to` images' descriptors.
// An image's partners depend only on itself and the images before it, so adding images one at a
// time (a capture) and over a finished project (the match stage) give the same pairs.
//
// Retrieval sees at most `retrieval_descriptors` evenly spaced descriptors of each image: that
// bounds the training set and what the first images hold until the vocabulary is trained.
#include <cstdint>
#include <string>
#include <vector>

#include "core/base/status.h"
#include "core/features/vocabulary_tree.h"

namespace reconar {

struct PairSelectionOptions {
  // Exhaustive matching costs n(n-1)/2 pairs: 1225 at 50 images (about 16 s on one core at
  // 13 ms a pair), and it grows quadratically beyond. Past the limit, each image is matched with
  // window + retrieved = 50 earlier images, as many as the image at the limit was: the cost per
  // image stops growing instead of dropping, so that a photo set just past the limit is matched
  // about as thoroughly as one just below it.
  int exhaustive_up_to = 50;
  int sequential_window = 10;  // neighbours in capture (or name) order: the video's overlap
  int retrieved = 40;          // loop closures, revisits and unordered photos the window misses
  int retrieval_descriptors = 4096;
  VocabularyTreeOptions vocabulary;  // num_threads is the caller's

  Status Check() const;
  // The settings as a stage record names them (stage_record.h).
  std::string Describe() const;
};

class PairSelector {
 public:
  static Result<PairSelector> Create(const PairSelectionOptions& options);

  // Adds the next image (index num_images()) with `count` descriptors (count * 128 bytes) and
  // returns the earlier images to match it with, ascending. Trains the vocabulary when the image
  // is the first beyond exhaustive_up_to.
  Result<std::vector<int>> Add(const uint8_t* descriptors, int count);

  int num_images() const { return num_images_; }
  bool trained() const { return num_images_ > options_.exhaustive_up_to; }
  double seconds_training() const { return seconds_training_; }

 private:
  explicit PairSelector(const PairSelectionOptions& options) : options_(options) {}
  std::vector<uint8_t> Subsample(const uint8_t* descriptors, int count) const;
  std::vector<int32_t> Words(const std::vector<uint8_t>& descriptors) const;
  Status Train();

  PairSelectionOptions options_;
  int num_images_ = 0;
  double seconds_training_ = 0.0;
  std::vector<std::vector<uint8_t>> untrained_descriptors_;  // the first images', until training
  VocabularyTree vocabulary_;
  std::vector<float> idf_;        // over the training images
  std::vector<BagOfWords> bags_;  // every image's, once trained
  std::vector<float> scores_;     // scratch of one query
  std::vector<int> candidates_;   // scratch of one query
};

}  // namespace reconar
