#pragma once
// Image retrieval with a vocabulary tree (Nistér & Stewénius, "Scalable Recognition with a
// Vocabulary Tree", CVPR 2006): hierarchical k-means over SIFT descriptors gives visual words; an
// inverted file over the words, weighted by tf-idf and scored by the L1 distance of normalised
// bag-of-words vectors, ranks the database images (the map's keyframes) for a query.
//
// The vocabulary is trained on the project's own descriptors (no shipped model). Centroids are
// kept as rounded uint8 descriptors so that quantisation uses the SIMD descriptor distance
// kernels. Quantising and querying take their working memory from caller-owned scratch and make
// no heap allocation.

#include <cstdint>
#include <string>
#include <vector>

#include "core/base/binary_io.h"
#include "core/base/status.h"

namespace reconar {

struct VocabularyTreeOptions {
  int branching = 10;                     // k of each k-means
  int depth = 4;                          // levels below the root: at most branching^depth words
  int kmeans_iterations = 12;             // Lloyd iterations per node (k-means++ seeding)
  int max_training_descriptors = 200000;  // a random subset beyond this
  int min_descriptors_per_node = 0;       // a node with fewer than max(branching, this) descriptors is a leaf
  uint64_t seed = 0x766f6361'62747265ull;
  int num_threads = 1;  // <= 0: one per core; the result does not depend on it

  Status Check() const;
};

class VocabularyTree {
 public:
  VocabularyTree() = default;  // empty: no words, Quantize returns -1

  // Trains on `count` descriptors (count * 128 bytes). InvalidArgument on bad options, a null
  // pointer or count < 1.
  static Result<VocabularyTree> Train(const uint8_t* descriptors, int count, const VocabularyTreeOptions& options);

  // The leaf (visual word, 0 .. num_words()-1) of a descriptor: greedy descent, nearest child
  // centroid at every level. No allocation. -1 for an empty tree.
  int Quantize(const uint8_t* descriptor) const;

  int num_words() const { return num_words_; }
  int num_nodes() const { return static_cast<int>(nodes_.size()); }
  int branching() const { return branching_; }
  size_t memory_bytes() const;

  // The tree in a binary record (part of the map file); Deserialize refuses (InvalidArgument with
  // `what` in the message) any record that is not a well-formed tree: bad counts, child indices
  // out of range or forming cycles, word ids not 0..n-1.
  void Serialize(ByteWriter* writer) const;
  static Result<VocabularyTree> Deserialize(ByteReader* reader, const std::string& what);

 private:
  class Trainer;  // hierarchical k-means (vocabulary_tree.cc)
  struct Node {
    int32_t first_child = -1;  // index of the first of num_children consecutive nodes; -1 for a leaf
    int32_t num_children = 0;
    int32_t word = -1;  // leaves only
  };
  int branching_ = 0;
  int num_words_ = 0;
  std::vector<Node> nodes_;         // nodes_[0] is the root
  std::vector<uint8_t> centroids_;  // 128 bytes per node (the root's unused)
};

// An image's bag of words: its distinct words, ascending, with their L1-normalised tf-idf weights
// (words of zero weight left out).
struct BagOfWords {
  std::vector<int32_t> words;
  std::vector<float> weights;
};

// Per word, log(N / n_w) over N images' word lists (n_w: the images holding the word); 0 for a
// word in no image. Words outside 0..num_words-1 are ignored.
std::vector<float> InverseDocumentFrequency(int num_words, const std::vector<std::vector<int32_t>>& document_words);

// An image's bag of words from its words (any order, repeats count) under `idf`; words outside
// the idf table are ignored. Equal word lists give bit-equal bags.
BagOfWords MakeBagOfWords(std::vector<int32_t> words, const std::vector<float>& idf);

// 2 - |a - b|_1, as InvertedFile::Query scores a database image: 0 (nothing shared) .. 2 (equal).
float BagOfWordsScore(const BagOfWords& a, const BagOfWords& b);

// A database image's score against a query.
struct RetrievalCandidate {
  int image = -1;
  float score = 0.0f;  // 2 - |q - d|_1 of the L1-normalised tf-idf vectors: 0 (nothing shared) .. 2 (equal)
};

// Working memory of one query at a time: the query's words and per-image accumulators. Sized once
// (Reserve) so that queries allocate nothing.
class RetrievalScratch {
 public:
  void Reserve(int max_query_words, int num_images);

 private:
  friend class InvertedFile;
  std::vector<int32_t> words_;       // the query's distinct words, sorted
  std::vector<float> weights_;       // their normalised tf-idf weights
  std::vector<float> accumulators_;  // per image
  std::vector<int32_t> touched_;     // images with a non-zero accumulator
};

// tf-idf inverted file over the words of a vocabulary.
class InvertedFile {
 public:
  InvertedFile() = default;

  // document_words[i] lists image i's words (any order, repeats count as term frequency).
  // InvalidArgument when a word is outside 0..num_words-1.
  static Result<InvertedFile> Build(int num_words, const std::vector<std::vector<int32_t>>& document_words);

  // The best min(max(0, top_k), num_images()) images by score, best first (ties: lower image
  // first, so images sharing no word follow with score 0), written to `out` (whose capacity must
  // hold top_k: no allocation when `scratch` has been reserved). Words outside the vocabulary
  // are ignored.
  void Query(const int32_t* words, int count, int top_k, RetrievalScratch* scratch,
             std::vector<RetrievalCandidate>* out) const;

  int num_images() const { return num_images_; }
  int num_words() const { return static_cast<int>(idf_.size()); }
  size_t memory_bytes() const;

  void Serialize(ByteWriter* writer) const;
  static Result<InvertedFile> Deserialize(ByteReader* reader, const std::string& what);

 private:
  struct Posting {
    int32_t image;
    float weight;  // the image's normalised tf-idf weight of the word
  };
  int num_images_ = 0;
  std::vector<float> idf_;                 // per word: log(N / n_w), 0 for words in no image
  std::vector<uint32_t> posting_offsets_;  // per word, into postings_ (num_words + 1)
  std::vector<Posting> postings_;
};

}  // namespace reconar
