#include "core/features/vocabulary_tree.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <set>
#include <string>
#include <vector>

#include "core/base/prng.h"
#include "core/features/descriptor_distance.h"
#include "tests/support/allocation_counter.h"

namespace reconar {
namespace {

uint8_t Clamp8(double v) { return static_cast<uint8_t>(std::clamp(std::lround(v), 0l, 255l)); }

// Two-level synthetic clusters shaped like the tree: `groups` centres uniform in [60, 195] per
// component (typical distance between them ~620), `per_group` sub-centres within +-40 of each
// (distance between sub-centres of a group ~370), descriptors with Gaussian noise of `sigma` per
// component (~57 from their sub-centre for sigma 5).
struct Clusters {
  std::vector<uint8_t> descriptors;
  std::vector<int> cluster;  // sub-cluster of each descriptor
};

Clusters MakeClusters(int groups, int per_group, int points_per_cluster, double sigma, uint64_t seed) {
  SplitMix64 rng(seed);
  std::vector<double> centres;
  for (int g = 0; g < groups; ++g) {
    double group[kDescriptorSize];
    for (double& v : group) v = rng.Uniform(60.0, 195.0);
    for (int s = 0; s < per_group; ++s) {
      for (int d = 0; d < kDescriptorSize; ++d) centres.push_back(group[d] + rng.Uniform(-40.0, 40.0));
    }
  }
  Clusters out;
  const int num_clusters = groups * per_group;
  for (int i = 0; i < num_clusters * points_per_cluster; ++i) {
    const int c = static_cast<int>(rng.UniformInt(static_cast<uint32_t>(num_clusters)));
    out.cluster.push_back(c);
    for (int d = 0; d < kDescriptorSize; ++d) {
      out.descriptors.push_back(Clamp8(centres[static_cast<size_t>(c) * kDescriptorSize + d] + sigma * rng.Gaussian()));
    }
  }
  return out;
}

int Count(const std::vector<uint8_t>& descriptors) { return static_cast<int>(descriptors.size() / kDescriptorSize); }

template <typename T>
std::string Bytes(const T& value) {
  ByteWriter writer;
  value.Serialize(&writer);
  return writer.bytes();
}

// Deserialize(Serialize(value)) reads the whole record and writes it back byte for byte.
template <typename T>
T RoundTrip(const T& value) {
  const std::string bytes = Bytes(value);
  ByteReader reader(bytes);
  Result<T> copy = T::Deserialize(&reader, "map.bin");
  EXPECT_TRUE(copy.ok()) << copy.status().ToString();
  if (!copy.ok()) return T();
  EXPECT_EQ(reader.remaining(), 0u);
  EXPECT_EQ(Bytes(*copy), bytes);
  return std::move(copy).value();
}

// Every proper prefix of the record is refused with `what` and the record's name.
template <typename T>
void ExpectTruncationsRefused(const std::string& bytes, const std::string& prefix) {
  for (size_t size = 0; size < bytes.size(); ++size) {
    ByteReader reader(std::string_view(bytes.data(), size));
    const Result<T> r = T::Deserialize(&reader, "map.bin");
    ASSERT_FALSE(r.ok()) << size;
    ASSERT_NE(r.status().ToString().find(prefix), std::string::npos) << r.status().ToString();
  }
}

VocabularyTree TrainOrDie(const std::vector<uint8_t>& descriptors, const VocabularyTreeOptions& options) {
  Result<VocabularyTree> tree = VocabularyTree::Train(descriptors.data(), Count(descriptors), options);
  EXPECT_TRUE(tree.ok()) << tree.status().ToString();
  return std::move(tree).value();
}

VocabularyTreeOptions Shape(int branching, int depth) {
  VocabularyTreeOptions options;
  options.branching = branching;
  options.depth = depth;
  return options;
}

VocabularyTree TrainOrDie(const std::vector<uint8_t>& descriptors, int branching, int depth) {
  return TrainOrDie(descriptors, Shape(branching, depth));
}

// Up to three bytes of `bytes` (within its first `limit`) changed at random.
std::string Damage(const std::string& bytes, size_t limit, SplitMix64* rng) {
  std::string damaged = bytes;
  const int flips = 1 + static_cast<int>(rng->UniformInt(3));
  for (int f = 0; f < flips; ++f) {
    damaged[rng->UniformInt(static_cast<uint32_t>(limit))] ^= static_cast<char>(1 + rng->UniformInt(255));
  }
  return damaged;
}

// The record as Serialize documents it: branching, words, node count, (first_child,
// num_children, word) per node, then 128 centroid bytes per node.
struct TreeRecord {
  int32_t branching = 0;
  int32_t num_words = 0;
  std::vector<int32_t> first_child, num_children, word;
  std::vector<uint8_t> centroids;
};

TreeRecord Parse(const std::string& bytes) {
  ByteReader reader(bytes);
  TreeRecord record;
  uint32_t n = 0;
  reader.Get(&record.branching);
  reader.Get(&record.num_words);
  reader.Get(&n);
  for (uint32_t i = 0; i < n; ++i) {
    int32_t v[3];
    reader.GetBytes(v, sizeof(v));
    record.first_child.push_back(v[0]);
    record.num_children.push_back(v[1]);
    record.word.push_back(v[2]);
  }
  record.centroids.resize(static_cast<size_t>(n) * kDescriptorSize);
  reader.GetBytes(record.centroids.data(), record.centroids.size());
  EXPECT_TRUE(reader.ok() && reader.remaining() == 0);
  return record;
}

// Greedy descent with the scalar kernel over the parsed record.
int ReferenceQuantize(const TreeRecord& record, const uint8_t* descriptor) {
  const DescriptorDistanceFn distance = ScalarDescriptorDistanceKernel().distance;
  int node = 0;
  while (record.first_child[node] >= 0) {
    int best = -1;
    int32_t best_distance = INT32_MAX;
    for (int c = record.first_child[node]; c < record.first_child[node] + record.num_children[node]; ++c) {
      const int32_t d = distance(descriptor, &record.centroids[static_cast<size_t>(c) * kDescriptorSize]);
      if (d < best_distance) {
        best_distance = d;
        best = c;
      }
    }
    node = best;
  }
  return record.word[node];
}

// Offsets of a node's fields in the record.
size_t NodeField(int node, int field) { return 12 + 12 * static_cast<size_t>(node) + 4 * static_cast<size_t>(field); }

void PutInt(std::string* bytes, size_t offset, int32_t value) { std::memcpy(&(*bytes)[offset], &value, 4); }

// -------------------------------------------------------------------------------------------
// Vocabulary tree

TEST(VocabularyTreeOptionsTest, CheckNamesTheField) {
  EXPECT_TRUE(VocabularyTreeOptions().Check().ok());
  struct Case {
    void (*edit)(VocabularyTreeOptions*);
    const char* field;
  };
  const Case cases[] = {
      {[](VocabularyTreeOptions* o) { o->branching = 1; }, "branching"},
      {[](VocabularyTreeOptions* o) { o->depth = 0; }, "depth"},
      {[](VocabularyTreeOptions* o) { o->depth = 8; }, "branching^depth"},  // 10^8 > 2^24
      {[](VocabularyTreeOptions* o) { o->kmeans_iterations = 0; }, "kmeans_iterations"},
      {[](VocabularyTreeOptions* o) { o->max_training_descriptors = 0; }, "max_training_descriptors"},
      {[](VocabularyTreeOptions* o) { o->min_descriptors_per_node = -1; }, "min_descriptors_per_node"},
  };
  for (const Case& c : cases) {
    VocabularyTreeOptions options;
    c.edit(&options);
    const Status status = options.Check();
    EXPECT_EQ(status.code(), StatusCode::kInvalidArgument) << c.field;
    EXPECT_NE(status.ToString().find(c.field), std::string::npos) << status.ToString();
  }
  VocabularyTreeOptions largest;
  largest.branching = 2;
  largest.depth = 24;
  EXPECT_TRUE(largest.Check().ok());
}

TEST(VocabularyTreeTest, TrainRejectsBadInput) {
  const std::vector<uint8_t> one(kDescriptorSize, 7);
  EXPECT_FALSE(VocabularyTree::Train(nullptr, 10, VocabularyTreeOptions()).ok());
  EXPECT_FALSE(VocabularyTree::Train(one.data(), 0, VocabularyTreeOptions()).ok());
  VocabularyTreeOptions bad;
  bad.branching = 0;
  EXPECT_FALSE(VocabularyTree::Train(one.data(), 1, bad).ok());
}

TEST(VocabularyTreeTest, EmptyAndTinyTrees) {
  const VocabularyTree empty;
  const std::vector<uint8_t> d(kDescriptorSize, 3);
  EXPECT_EQ(empty.Quantize(d.data()), -1);
  EXPECT_EQ(empty.num_words(), 0);
  // Fewer descriptors than the branching: the root is the only word.
  const VocabularyTree tiny = TrainOrDie(std::vector<uint8_t>(5 * kDescriptorSize, 9), VocabularyTreeOptions());
  EXPECT_EQ(tiny.num_nodes(), 1);
  EXPECT_EQ(tiny.num_words(), 1);
  EXPECT_EQ(tiny.Quantize(d.data()), 0);
  VocabularyTreeOptions wide;
  wide.branching = 1 << 24;  // no buffer sized by the branching alone
  wide.depth = 1;
  EXPECT_EQ(TrainOrDie(std::vector<uint8_t>(5 * kDescriptorSize, 9), wide).num_words(), 1);
  // Identical descriptors cannot be split: a leaf however many there are.
  const VocabularyTree same = TrainOrDie(std::vector<uint8_t>(500 * kDescriptorSize, 9), VocabularyTreeOptions());
  EXPECT_EQ(same.num_words(), 1);
}

// (a) A training descriptor and its noisy copies (sigma 5 per component, ~57 apart in L2, far
// below the ~370 between sub-clusters) land in one word unless k-means split the descriptor's
// own cluster and the copy crossed that split.
TEST(VocabularyTreeTest, NoisyCopiesShareTheWord) {
  const Clusters data = MakeClusters(10, 10, 60, 5.0, 11);
  const VocabularyTree tree = TrainOrDie(data.descriptors, 10, 2);
  EXPECT_GE(tree.num_words(), 90);
  SplitMix64 rng(5);
  int same = 0, total = 0;
  uint8_t copy[kDescriptorSize];
  for (int i = 0; i < Count(data.descriptors); i += 7) {
    const uint8_t* d = &data.descriptors[static_cast<size_t>(i) * kDescriptorSize];
    const int word = tree.Quantize(d);
    for (int r = 0; r < 4; ++r) {
      for (int k = 0; k < kDescriptorSize; ++k) copy[k] = Clamp8(d[k] + 5.0 * rng.Gaussian());
      same += tree.Quantize(copy) == word;
      ++total;
    }
  }
  const double fraction = static_cast<double>(same) / total;
  std::printf("noisy copies in the same word: %d / %d = %.4f, %d words\n", same, total, fraction, tree.num_words());
  EXPECT_GE(fraction, 0.9);
  // Each sub-cluster lives mostly in one word.
  std::vector<std::vector<int>> words_of_cluster(100, std::vector<int>(static_cast<size_t>(tree.num_words()), 0));
  for (int i = 0; i < Count(data.descriptors); ++i) {
    ++words_of_cluster[static_cast<size_t>(data.cluster[static_cast<size_t>(i)])]
                      [static_cast<size_t>(tree.Quantize(&data.descriptors[static_cast<size_t>(i) * kDescriptorSize]))];
  }
  int majority = 0;
  for (const auto& counts : words_of_cluster) majority += *std::max_element(counts.begin(), counts.end());
  std::printf("descriptors in their cluster's main word: %.4f\n",
              static_cast<double>(majority) / Count(data.descriptors));
  EXPECT_GE(static_cast<double>(majority) / Count(data.descriptors), 0.9);
}

// (b) Every word is the word of some training descriptor (empty clusters are dropped, and the
// final assignment is to the final centroids), and Quantize is the greedy descent of the record.
TEST(VocabularyTreeTest, EveryWordIsUsedAndQuantizeFollowsTheRecord) {
  const Clusters data = MakeClusters(6, 8, 30, 20.0, 3);
  const VocabularyTree tree = TrainOrDie(data.descriptors, 5, 3);
  ASSERT_GT(tree.num_words(), 25);
  const TreeRecord record = Parse(Bytes(tree));
  EXPECT_EQ(record.branching, 5);
  EXPECT_EQ(record.num_words, tree.num_words());
  std::vector<int> hits(static_cast<size_t>(tree.num_words()), 0);
  for (int i = 0; i < Count(data.descriptors); ++i) {
    const uint8_t* d = &data.descriptors[static_cast<size_t>(i) * kDescriptorSize];
    const int word = tree.Quantize(d);
    ASSERT_GE(word, 0);
    ASSERT_LT(word, tree.num_words());
    ++hits[static_cast<size_t>(word)];
    ASSERT_EQ(word, ReferenceQuantize(record, d));
  }
  EXPECT_EQ(std::count(hits.begin(), hits.end(), 0), 0);
  // Words in depth-first order of the leaves.
  std::vector<int> stack = {0};
  int next = 0;
  while (!stack.empty()) {
    const int node = stack.back();
    stack.pop_back();
    if (record.first_child[static_cast<size_t>(node)] < 0) {
      EXPECT_EQ(record.word[static_cast<size_t>(node)], next++);
      continue;
    }
    EXPECT_LE(record.num_children[static_cast<size_t>(node)], 5);
    for (int c = record.num_children[static_cast<size_t>(node)] - 1; c >= 0; --c) {
      stack.push_back(record.first_child[static_cast<size_t>(node)] + c);
    }
  }
  EXPECT_EQ(next, tree.num_words());
  // Random descriptors too.
  SplitMix64 rng(9);
  uint8_t d[kDescriptorSize];
  for (int q = 0; q < 500; ++q) {
    for (uint8_t& v : d) v = static_cast<uint8_t>(rng.UniformInt(256));
    ASSERT_EQ(tree.Quantize(d), ReferenceQuantize(record, d));
  }
}

// (c) The thread count changes nothing, with and without subsampling.
TEST(VocabularyTreeTest, ThreadCountDoesNotChangeTheTree) {
  const Clusters data = MakeClusters(8, 8, 400, 15.0, 21);  // 25600: the parallel path is taken
  for (const int max_training : {100000, 17000}) {
    VocabularyTreeOptions options = Shape(8, 3);
    options.max_training_descriptors = max_training;
    options.num_threads = 1;
    const std::string one = Bytes(TrainOrDie(data.descriptors, options));
    options.num_threads = 2;
    const std::string two = Bytes(TrainOrDie(data.descriptors, options));
    EXPECT_EQ(one, two) << "max_training_descriptors " << max_training;
    options.seed ^= 1;
    EXPECT_NE(Bytes(TrainOrDie(data.descriptors, options)), one) << "the seed matters";
  }
}

// (d) Serialize -> Deserialize keeps the bytes and the quantisation.
TEST(VocabularyTreeTest, RoundTrip) {
  const Clusters data = MakeClusters(5, 5, 40, 10.0, 4);
  const VocabularyTree tree = TrainOrDie(data.descriptors, 6, 3);
  const VocabularyTree copy = RoundTrip(tree);
  EXPECT_EQ(copy.num_words(), tree.num_words());
  EXPECT_EQ(copy.num_nodes(), tree.num_nodes());
  EXPECT_EQ(copy.branching(), 6);
  for (int i = 0; i < Count(data.descriptors); ++i) {
    const uint8_t* d = &data.descriptors[static_cast<size_t>(i) * kDescriptorSize];
    ASSERT_EQ(copy.Quantize(d), tree.Quantize(d));
  }
  EXPECT_EQ(RoundTrip(VocabularyTree()).num_nodes(), 0);  // the empty tree too
}

// (e) Every truncation is refused; random damage never crashes and what is accepted is a
// tree Quantize can walk.
TEST(VocabularyTreeTest, DeserializeRefusesDamage) {
  const Clusters data = MakeClusters(3, 3, 20, 10.0, 8);
  const VocabularyTree tree = TrainOrDie(data.descriptors, 3, 2);
  const std::string bytes = Bytes(tree);
  ExpectTruncationsRefused<VocabularyTree>(bytes, "map.bin: vocabulary tree: ");
  const size_t structure = 12 + 12 * static_cast<size_t>(tree.num_nodes());  // header and nodes
  SplitMix64 rng(77);
  int accepted = 0;
  for (int m = 0; m < 4000; ++m) {
    // Mostly the header and nodes, where damage matters.
    const std::string damaged = Damage(bytes, rng.UniformInt(4) == 0 ? bytes.size() : structure, &rng);
    ByteReader reader(damaged);
    const Result<VocabularyTree> r = VocabularyTree::Deserialize(&reader, "map.bin");
    if (!r.ok()) continue;
    ++accepted;
    for (int i = 0; i < Count(data.descriptors); i += 5) {
      const int word = r->Quantize(&data.descriptors[static_cast<size_t>(i) * kDescriptorSize]);
      ASSERT_TRUE(word >= 0 && word < r->num_words());
    }
  }
  std::printf("damaged records accepted: %d of 4000\n", accepted);
}

TEST(VocabularyTreeTest, DeserializeNamesTheFault) {
  const Clusters data = MakeClusters(3, 3, 20, 10.0, 8);
  const std::string bytes = Bytes(TrainOrDie(data.descriptors, 3, 2));
  const TreeRecord record = Parse(bytes);
  ASSERT_GT(record.first_child[0], 0);
  const int child = record.first_child[0];
  int leaf = 0;
  while (record.first_child[static_cast<size_t>(leaf)] >= 0) ++leaf;
  auto expect_refused = [](const std::string& damaged, const char* reason) {
    ByteReader reader(damaged);
    const Result<VocabularyTree> r = VocabularyTree::Deserialize(&reader, "x.map");
    ASSERT_FALSE(r.ok()) << reason;
    EXPECT_NE(r.status().ToString().find(reason), std::string::npos) << r.status().ToString();
  };
  std::string b = bytes;
  PutInt(&b, NodeField(child, 0), 0);  // a child pointing back at the root
  PutInt(&b, NodeField(child, 1), 2);
  PutInt(&b, NodeField(child, 2), -1);
  expect_refused(b, "not after it");
  b = bytes;
  PutInt(&b, NodeField(0, 0), static_cast<int32_t>(record.first_child.size()) - 1);
  expect_refused(b, "not after it");
  b = bytes;
  PutInt(&b, NodeField(0, 1), 4);
  expect_refused(b, "branching 3");
  b = bytes;
  PutInt(&b, NodeField(leaf, 2), record.word[static_cast<size_t>(leaf)] == 0 ? 1 : 0);
  expect_refused(b, "repeated");
  b = bytes;
  PutInt(&b, NodeField(leaf, 2), -1);
  expect_refused(b, "outside");
  b = bytes;
  PutInt(&b, 4, record.num_words + 1);
  expect_refused(b, "leaves for");
  b = bytes;
  PutInt(&b, 8, 0x7fffffff);
  expect_refused(b, "node count");
  b = bytes;
  PutInt(&b, 0, 1);
  expect_refused(b, "branching 1");
}

// Training time on 100k descriptors, branching 10, depth 4 (run with
// --gtest_also_run_disabled_tests; the figure goes to the report).
TEST(VocabularyTreeTest, DISABLED_TrainingTime) {
  const Clusters data = MakeClusters(50, 20, 100, 25.0, 1);
  for (const int threads : {1, 2}) {
    VocabularyTreeOptions options;
    options.num_threads = threads;
    const auto start = std::chrono::steady_clock::now();
    const VocabularyTree tree = TrainOrDie(data.descriptors, options);
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    std::printf("trained %d descriptors, branching %d, depth %d, %d threads: %d words, %.2f s (%s kernel)\n",
                Count(data.descriptors), options.branching, options.depth, threads, tree.num_words(), seconds,
                ActiveDescriptorDistanceKernel().name);
  }
}

// -------------------------------------------------------------------------------------------
// Inverted file

InvertedFile BuildOrDie(int num_words, const std::vector<std::vector<int32_t>>& documents) {
  Result<InvertedFile> file = InvertedFile::Build(num_words, documents);
  EXPECT_TRUE(file.ok()) << file.status().ToString();
  return std::move(file).value();
}

std::vector<RetrievalCandidate> Query(const InvertedFile& file, const std::vector<int32_t>& words, int top_k) {
  RetrievalScratch scratch;
  std::vector<RetrievalCandidate> out;
  out.reserve(static_cast<size_t>(std::max(0, top_k)));
  file.Query(words.data(), static_cast<int>(words.size()), top_k, &scratch, &out);
  return out;
}

std::vector<std::vector<int32_t>> RandomDocuments(int num_images, int num_words, int words_per_image, uint64_t seed) {
  SplitMix64 rng(seed);
  std::vector<std::vector<int32_t>> documents(static_cast<size_t>(num_images));
  for (auto& document : documents) {
    for (int i = 0; i < words_per_image; ++i) document.push_back(static_cast<int32_t>(rng.UniformInt(num_words)));
  }
  return documents;
}

// (f)
TEST(InvertedFileTest, SelfQueryScoresTwoAndRanksFirst) {
  const auto documents = RandomDocuments(40, 500, 60, 2);
  const InvertedFile file = BuildOrDie(500, documents);
  EXPECT_EQ(file.num_images(), 40);
  EXPECT_EQ(file.num_words(), 500);
  for (int i = 0; i < 40; ++i) {
    std::vector<int32_t> shuffled = documents[static_cast<size_t>(i)];
    std::reverse(shuffled.begin(), shuffled.end());  // order does not matter
    const auto out = Query(file, shuffled, 5);
    ASSERT_EQ(out.size(), 5u);
    EXPECT_EQ(out[0].image, i);
    EXPECT_NEAR(out[0].score, 2.0f, 1e-5f);
    for (size_t k = 1; k < out.size(); ++k) {
      EXPECT_LT(out[k].score, out[0].score);
      EXPECT_LE(out[k].score, out[k - 1].score);
      EXPECT_GE(out[k].score, 0.0f);
    }
  }
}

// The score is 2 - |q - d|_1 of the normalised tf-idf vectors, computed here densely.
TEST(InvertedFileTest, ScoreIsTheL1Formula) {
  const auto documents = RandomDocuments(12, 40, 15, 5);
  const InvertedFile file = BuildOrDie(40, documents);
  std::vector<int> df(40, 0);
  for (const auto& d : documents) {
    for (const int32_t w : std::set<int32_t>(d.begin(), d.end())) ++df[static_cast<size_t>(w)];
  }
  auto vector_of = [&](const std::vector<int32_t>& words) {
    std::vector<double> v(40, 0.0);
    for (const int32_t w : words) v[static_cast<size_t>(w)] += df[w] > 0 ? std::log(12.0 / df[w]) : 0.0;
    double sum = 0.0;
    for (const double x : v) sum += x;
    for (double& x : v) x /= sum;
    return v;
  };
  const std::vector<int32_t> query = {1, 1, 5, 7, 9, 20, 21, 33, 38, 38, 38};
  const std::vector<double> q = vector_of(query);
  const auto out = Query(file, query, 12);
  ASSERT_EQ(out.size(), 12u);
  for (const RetrievalCandidate& c : out) {
    const std::vector<double> d = vector_of(documents[static_cast<size_t>(c.image)]);
    double l1 = 0.0;
    for (int w = 0; w < 40; ++w) l1 += std::abs(q[static_cast<size_t>(w)] - d[static_cast<size_t>(w)]);
    EXPECT_NEAR(c.score, 2.0 - l1, 1e-5) << c.image;
  }
}

TEST(InvertedFileTest, BagOfWordsScoreIsTheQueryScore) {
  // The pair rule scores bags of words pairwise (BagOfWordsScore); the inverted file accumulates
  // the same terms in the same word order, so the two agree bit for bit.
  const auto documents = RandomDocuments(12, 40, 15, 6);
  const InvertedFile file = BuildOrDie(40, documents);
  const std::vector<float> idf = InverseDocumentFrequency(40, documents);
  const std::vector<int32_t> query = {2, 3, 3, 8, 11, 17, 17, 30, 39, 45, -1};  // 45, -1: outside
  const BagOfWords query_bag = MakeBagOfWords(query, idf);
  EXPECT_EQ(query_bag.words.size(), query_bag.weights.size());
  EXPECT_TRUE(std::is_sorted(query_bag.words.begin(), query_bag.words.end()));
  const auto out = Query(file, query, 12);
  ASSERT_EQ(out.size(), 12u);
  for (const RetrievalCandidate& c : out) {
    const BagOfWords document = MakeBagOfWords(documents[static_cast<size_t>(c.image)], idf);
    EXPECT_EQ(BagOfWordsScore(query_bag, document), c.score) << c.image;
    EXPECT_EQ(BagOfWordsScore(document, query_bag), c.score) << c.image;
  }
  EXPECT_FLOAT_EQ(BagOfWordsScore(query_bag, query_bag), 2.0f);
  EXPECT_EQ(BagOfWordsScore(query_bag, BagOfWords{}), 0.0f);
}

TEST(InvertedFileTest, NoSharedWordTiesAndOutOfRangeWords) {
  // Images 0 and 2 are equal; image 1 shares nothing with them; word 3 is in every image (idf 0).
  const InvertedFile file = BuildOrDie(10, {{0, 1, 3}, {4, 5, 3}, {0, 1, 3}, {6, 3}});
  auto out = Query(file, {7, 8}, 4);  // words of no image
  ASSERT_EQ(out.size(), 4u);
  for (int i = 0; i < 4; ++i) {
    EXPECT_EQ(out[static_cast<size_t>(i)].image, i);
    EXPECT_EQ(out[static_cast<size_t>(i)].score, 0.0f);
  }
  out = Query(file, {0, 1, -5, 10, 1000000}, 3);  // out-of-range words ignored
  ASSERT_EQ(out.size(), 3u);
  EXPECT_EQ(out[0].image, 0);  // tie with image 2: the lower first
  EXPECT_EQ(out[1].image, 2);
  EXPECT_NEAR(out[0].score, 2.0f, 1e-5f);
  EXPECT_EQ(out[0].score, out[1].score);
  EXPECT_EQ(out[2].image, 1);
  EXPECT_EQ(out[2].score, 0.0f);
  EXPECT_TRUE(Query(file, {0, 1}, 0).empty());
  EXPECT_TRUE(Query(file, {0, 1}, -3).empty());
  EXPECT_EQ(Query(file, {0, 1}, 100).size(), 4u);
  EXPECT_TRUE(Query(InvertedFile(), {0, 1}, 3).empty());
}

TEST(InvertedFileTest, BuildRejectsWordsOutsideTheVocabulary) {
  EXPECT_FALSE(InvertedFile::Build(10, {{0, 1}, {10}}).ok());
  EXPECT_FALSE(InvertedFile::Build(10, {{-1}}).ok());
  EXPECT_FALSE(InvertedFile::Build(-1, {}).ok());
  EXPECT_TRUE(InvertedFile::Build(0, {{}, {}}).ok());
}

TEST(InvertedFileTest, RoundTripAndDamage) {
  const auto documents = RandomDocuments(20, 60, 25, 7);
  const InvertedFile file = BuildOrDie(60, documents);
  const std::string bytes = Bytes(file);
  {
    const InvertedFile copy = RoundTrip(file);
    for (const auto& d : documents) {
      const auto a = Query(file, d, 6);
      const auto b = Query(copy, d, 6);
      ASSERT_EQ(a.size(), b.size());
      for (size_t k = 0; k < a.size(); ++k) {
        EXPECT_EQ(a[k].image, b[k].image);
        EXPECT_EQ(a[k].score, b[k].score);
      }
    }
  }
  EXPECT_EQ(RoundTrip(InvertedFile()).num_images(), 0);
  ExpectTruncationsRefused<InvertedFile>(bytes, "map.bin: inverted file: ");
  // An idf beyond log(2^24 images) would overflow the query's float weights.
  for (const float idf : {1e30f, -1.0f, std::nanf("")}) {
    std::string damaged = bytes;
    std::memcpy(&damaged[8], &idf, 4);  // word 0, after num_images and num_words
    ByteReader reader(damaged);
    EXPECT_FALSE(InvertedFile::Deserialize(&reader, "map.bin").ok()) << idf;
  }
  SplitMix64 rng(13);
  int accepted = 0;
  for (int m = 0; m < 4000; ++m) {
    const std::string damaged = Damage(bytes, bytes.size(), &rng);
    ByteReader reader(damaged);
    const Result<InvertedFile> r = InvertedFile::Deserialize(&reader, "map.bin");
    if (!r.ok()) continue;
    ++accepted;
    const auto out = Query(*r, documents[static_cast<size_t>(m % 20)], 3);
    for (const RetrievalCandidate& c : out) ASSERT_TRUE(c.image >= 0 && c.image < r->num_images());
  }
  std::printf("damaged inverted files accepted: %d of 4000\n", accepted);
}

// (g) After Reserve, queries and quantisation make no heap allocation.
TEST(RetrievalAllocationTest, QueryAndQuantizeDoNotAllocate) {
  const Clusters data = MakeClusters(4, 4, 30, 10.0, 6);
  const VocabularyTree tree = TrainOrDie(data.descriptors, 4, 3);
  std::vector<std::vector<int32_t>> documents(8);
  for (int i = 0; i < Count(data.descriptors); ++i) {
    documents[static_cast<size_t>(i % 8)].push_back(
        tree.Quantize(&data.descriptors[static_cast<size_t>(i) * kDescriptorSize]));
  }
  const InvertedFile file = BuildOrDie(tree.num_words(), documents);
  const int query_size = 60;
  RetrievalScratch scratch;
  scratch.Reserve(query_size, file.num_images());
  std::vector<RetrievalCandidate> out;
  out.reserve(5);
  std::vector<int32_t> words(query_size);
  long allocations = -1;
  int found_first = 0;
  {
    testing::NoAllocationScope scope;
    for (int q = 0; q < 8; ++q) {
      for (int i = 0; i < query_size; ++i) {
        words[static_cast<size_t>(i)] =
            tree.Quantize(&data.descriptors[static_cast<size_t>(q + 8 * i) * kDescriptorSize]);  // image q's
      }
      file.Query(words.data(), query_size, 5, &scratch, &out);
      found_first += !out.empty() && out[0].image == q;
    }
    allocations = scope.allocations();
  }
  EXPECT_EQ(allocations, 0);
  EXPECT_EQ(found_first, 8);
  // The counter does see operator new (so the zero above means something), e.g. a query whose
  // `out` has no room.
  std::vector<RetrievalCandidate> unreserved;
  {
    testing::NoAllocationScope scope;
    file.Query(words.data(), query_size, 5, &scratch, &unreserved);
    allocations = scope.allocations();
  }
  EXPECT_GT(allocations, 0);
}

}  // namespace
}  // namespace reconar
