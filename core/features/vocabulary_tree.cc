#include "core/features/vocabulary_tree.h"

#include <algorithm>
#include <atomic>
#include <climits>
#include <cmath>
#include <cstring>
#include <functional>
#include <memory>

#include "core/base/prng.h"
#include "core/base/thread_pool.h"
#include "core/features/descriptor_distance.h"

namespace reconar {
namespace {

constexpr int kMaxWords = 1 << 24;
constexpr int kMaxNodes = 2 * kMaxWords;  // every inner node has >= 2 children
constexpr int kMaxImages = 1 << 24;
constexpr float kMaxIdf = 17.0f;  // above log(kMaxImages) = 16.6
constexpr size_t kNodeRecordBytes = 3 * sizeof(int32_t) + kDescriptorSize;
// Nodes smaller than this are clustered on the calling thread: a parallel pass costs more.
constexpr int kParallelMinPoints = 8192;
constexpr int kParallelChunk = 2048;

// Ids 0..kBatch-1: the batch kernel over consecutive centroids.
constexpr int kBatch = 64;
struct IotaTable {
  int32_t ids[kBatch];
  constexpr IotaTable() : ids() {
    for (int i = 0; i < kBatch; ++i) ids[i] = i;
  }
};
constexpr IotaTable kIota;

// The nearest of `count` consecutive centroids (ties: the lower index) and its squared distance.
int NearestCentroid(const DescriptorDistanceKernel& kernel, const uint8_t* query, const uint8_t* centroids, int count,
                    int32_t* distance) {
  int32_t batch[kBatch];
  int best = 0;
  int32_t best_distance = INT32_MAX;
  for (int start = 0; start < count; start += kBatch) {
    const int n = std::min(kBatch, count - start);
    kernel.batch(query, centroids + static_cast<int64_t>(start) * kDescriptorSize, kIota.ids, n, batch);
    for (int i = 0; i < n; ++i) {
      if (batch[i] < best_distance) {
        best_distance = batch[i];
        best = start + i;
      }
    }
  }
  *distance = best_distance;
  return best;
}

Status TreeError(const std::string& what, const std::string& reason) {
  return InvalidArgument(what + ": vocabulary tree: " + reason);
}

Status IndexError(const std::string& what, const std::string& reason) {
  return InvalidArgument(what + ": inverted file: " + reason);
}

// Sorts words[0, count), merges repeats into term frequencies and writes, in place, the distinct
// words with a non-zero tf-idf weight and their L1-normalised weights (weights holds count
// floats). Returns how many were kept. Database images and queries both go through here, so equal
// word lists give bit-equal vectors.
int NormaliseBagOfWords(int32_t* words, int count, const float* idf, float* weights) {
  std::sort(words, words + count);
  int kept = 0;
  double total = 0.0;
  for (int i = 0; i < count;) {
    int j = i + 1;
    while (j < count && words[j] == words[i]) ++j;
    const float weight = static_cast<float>(static_cast<double>(j - i) * idf[words[i]]);
    if (weight > 0.0f) {
      words[kept] = words[i];
      weights[kept] = weight;
      total += weight;
      ++kept;
    }
    i = j;
  }
  for (int i = 0; i < kept; ++i) weights[i] = static_cast<float>(weights[i] / total);
  return kept;
}

}  // namespace

Status VocabularyTreeOptions::Check() const {
  if (branching < 2) {
    return InvalidArgument("VocabularyTreeOptions: branching must be >= 2, got " + std::to_string(branching));
  }
  if (depth < 1) return InvalidArgument("VocabularyTreeOptions: depth must be >= 1, got " + std::to_string(depth));
  int64_t words = 1;
  for (int level = 0; level < depth; ++level) {
    words *= branching;
    if (words > kMaxWords) {
      return InvalidArgument("VocabularyTreeOptions: branching^depth = " + std::to_string(branching) + "^" +
                             std::to_string(depth) + " exceeds " + std::to_string(kMaxWords) + " words");
    }
  }
  if (kmeans_iterations < 1) {
    return InvalidArgument("VocabularyTreeOptions: kmeans_iterations must be >= 1, got " +
                           std::to_string(kmeans_iterations));
  }
  if (max_training_descriptors < 1) {
    return InvalidArgument("VocabularyTreeOptions: max_training_descriptors must be >= 1, got " +
                           std::to_string(max_training_descriptors));
  }
  if (min_descriptors_per_node < 0) {
    return InvalidArgument("VocabularyTreeOptions: min_descriptors_per_node must be >= 0, got " +
                           std::to_string(min_descriptors_per_node));
  }
  return Status::Ok();
}

// ---------------------------------------------------------------------------------------------
// Training: hierarchical k-means

// Clusters the training subset top-down. The descriptors of a node are the range [begin, end) of
// ids_; k-means splits it into at most `branching` clusters whose ranges become the children's.
// Each node draws its k-means++ seeds from its own generator (seed and node index), and every
// parallel step writes per-descriptor results, so the tree does not depend on the thread count.
class VocabularyTree::Trainer {
 public:
  Trainer(const uint8_t* descriptors, std::vector<int32_t> ids, const VocabularyTreeOptions& options)
      : descriptors_(descriptors),
        kernel_(ActiveDescriptorDistanceKernel()),
        options_(options),
        ids_(std::move(ids)),
        assignment_(ids_.size()),
        distance_(ids_.size()),
        scratch_ids_(ids_.size()),
        // A node is split only when it has at least `branching` descriptors.
        max_clusters_(std::min(ids_.size(), static_cast<size_t>(options.branching))),
        centroids_(max_clusters_ * kDescriptorSize),
        sums_(max_clusters_ * kDescriptorSize),
        counts_(max_clusters_),
        remap_(max_clusters_),
        offsets_(max_clusters_ + 1) {
    const int threads = ThreadPool::ResolveThreadCount(options.num_threads);
    if (threads > 1) pool_ = std::make_unique<ThreadPool>(threads);
  }

  void Run(VocabularyTree* tree) {
    struct Task {
      int32_t node;
      int32_t begin;
      int32_t end;
      int level;
    };
    tree->branching_ = options_.branching;
    tree->nodes_.assign(1, Node{});
    tree->centroids_.assign(kDescriptorSize, 0);
    const int min_split = std::max(options_.branching, options_.min_descriptors_per_node);
    std::vector<Task> stack = {{0, 0, static_cast<int32_t>(ids_.size()), 0}};
    while (!stack.empty()) {
      const Task task = stack.back();
      stack.pop_back();
      if (task.level >= options_.depth || task.end - task.begin < min_split) continue;
      const int k = Cluster(task.node, task.begin, task.end - task.begin);
      if (k < 2) continue;
      // Counting sort of the node's ids by cluster (stable): child c gets [begin + offset[c], ...).
      std::vector<int32_t>& offset = offsets_;
      offset[0] = task.begin;
      for (int c = 0; c < k; ++c) offset[c + 1] = offset[c] + static_cast<int32_t>(counts_[c]);
      for (int c = 0; c < k; ++c) counts_[c] = 0;
      for (int32_t p = task.begin; p < task.end; ++p) {
        const int c = assignment_[p];
        scratch_ids_[offset[c] + counts_[c]++] = ids_[p];
      }
      std::copy(scratch_ids_.begin() + task.begin, scratch_ids_.begin() + task.end, ids_.begin() + task.begin);

      const int32_t first = static_cast<int32_t>(tree->nodes_.size());
      tree->nodes_[task.node].first_child = first;
      tree->nodes_[task.node].num_children = k;
      tree->nodes_.resize(tree->nodes_.size() + static_cast<size_t>(k));
      tree->centroids_.insert(tree->centroids_.end(), centroids_.begin(),
                              centroids_.begin() + static_cast<int64_t>(k) * kDescriptorSize);
      for (int c = k - 1; c >= 0; --c) stack.push_back({first + c, offset[c], offset[c + 1], task.level + 1});
    }
    // Words in depth-first order, children in order.
    int32_t next_word = 0;
    std::vector<int32_t> order = {0};
    while (!order.empty()) {
      Node& node = tree->nodes_[order.back()];
      order.pop_back();
      if (node.first_child < 0) {
        node.word = next_word++;
        continue;
      }
      for (int c = node.num_children - 1; c >= 0; --c) order.push_back(node.first_child + c);
    }
    tree->num_words_ = next_word;
    tree->nodes_.shrink_to_fit();
    tree->centroids_.shrink_to_fit();
  }

 private:
  const uint8_t* Descriptor(int32_t position) const {
    return descriptors_ + static_cast<int64_t>(ids_[position]) * kDescriptorSize;
  }

  // fn(begin, end) over [begin, begin + n) in chunks, in parallel when the node is large.
  void ForRanges(int32_t begin, int32_t n, const std::function<void(int32_t, int32_t)>& fn) {
    if (pool_ == nullptr || n < kParallelMinPoints) {
      fn(begin, begin + n);
      return;
    }
    const size_t chunks = (static_cast<size_t>(n) + kParallelChunk - 1) / kParallelChunk;
    pool_->ParallelFor(0, chunks, [&](size_t chunk, int) {
      const int32_t lo = begin + static_cast<int32_t>(chunk) * kParallelChunk;
      fn(lo, std::min(begin + n, lo + kParallelChunk));
    });
  }

  // Assigns every descriptor of [begin, begin + n) to its nearest of the first k centroids;
  // returns whether any assignment changed.
  bool Assign(int32_t begin, int32_t n, int k) {
    std::atomic<bool> changed{false};
    ForRanges(begin, n, [&](int32_t lo, int32_t hi) {
      bool local = false;
      for (int32_t p = lo; p < hi; ++p) {
        const int c = NearestCentroid(kernel_, Descriptor(p), centroids_.data(), k, &distance_[p]);
        local |= c != assignment_[p];
        assignment_[p] = c;
      }
      if (local) changed.store(true, std::memory_order_relaxed);
    });
    return changed.load();
  }

  void SetCentroid(int c, int32_t position) {
    std::memcpy(&centroids_[static_cast<size_t>(c) * kDescriptorSize], Descriptor(position), kDescriptorSize);
  }

  // k-means++ (Arthur & Vassilvitskii 2007): each further seed is drawn with probability
  // proportional to its squared distance to the nearest seed so far. Stops early when every
  // descriptor coincides with a seed. Returns the number of seeds.
  int Seed(int32_t begin, int32_t n, SplitMix64* rng) {
    SetCentroid(0, begin + static_cast<int32_t>(rng->UniformInt(static_cast<uint32_t>(n))));
    const uint8_t* first = centroids_.data();
    ForRanges(begin, n, [&](int32_t lo, int32_t hi) {
      for (int32_t p = lo; p < hi; ++p) distance_[p] = kernel_.distance(Descriptor(p), first);
    });
    int k = 1;
    for (; k < options_.branching; ++k) {
      uint64_t total = 0;
      for (int32_t p = begin; p < begin + n; ++p) total += static_cast<uint64_t>(distance_[p]);
      if (total == 0) break;
      const uint64_t target = rng->Next() % total;
      uint64_t cumulative = 0;
      int32_t chosen = begin + n - 1;
      for (int32_t p = begin; p < begin + n; ++p) {
        cumulative += static_cast<uint64_t>(distance_[p]);
        if (cumulative > target) {
          chosen = p;
          break;
        }
      }
      SetCentroid(k, chosen);
      const uint8_t* seed = &centroids_[static_cast<size_t>(k) * kDescriptorSize];
      ForRanges(begin, n, [&](int32_t lo, int32_t hi) {
        for (int32_t p = lo; p < hi; ++p) distance_[p] = std::min(distance_[p], kernel_.distance(Descriptor(p), seed));
      });
    }
    return k;
  }

  // Centroids as the rounded means of their clusters. An empty cluster takes the descriptor
  // farthest from its centroid (ties: the first), which then leaves the farthest candidates.
  void Update(int32_t begin, int32_t n, int k) {
    std::fill(sums_.begin(), sums_.begin() + static_cast<int64_t>(k) * kDescriptorSize, 0);
    std::fill(counts_.begin(), counts_.begin() + k, 0);
    for (int32_t p = begin; p < begin + n; ++p) {
      const int c = assignment_[p];
      ++counts_[c];
      uint64_t* sum = &sums_[static_cast<size_t>(c) * kDescriptorSize];
      const uint8_t* row = Descriptor(p);
      for (int d = 0; d < kDescriptorSize; ++d) sum[d] += row[d];
    }
    for (int c = 0; c < k; ++c) {
      uint8_t* centroid = &centroids_[static_cast<size_t>(c) * kDescriptorSize];
      const uint64_t count = counts_[c];
      if (count > 0) {
        const uint64_t* sum = &sums_[static_cast<size_t>(c) * kDescriptorSize];
        for (int d = 0; d < kDescriptorSize; ++d) centroid[d] = static_cast<uint8_t>((sum[d] + count / 2) / count);
        continue;
      }
      int32_t farthest = begin;
      for (int32_t p = begin; p < begin + n; ++p) {
        if (distance_[p] > distance_[farthest]) farthest = p;
      }
      SetCentroid(c, farthest);
      distance_[farthest] = 0;
    }
  }

  // k-means of the node's descriptors [begin, begin + n) into centroids_ and assignment_ (the
  // final assignment is to the final, rounded centroids, as Quantize descends). Empty clusters
  // are dropped; counts_ holds the cluster sizes. Returns the number of clusters.
  int Cluster(int32_t node, int32_t begin, int32_t n) {
    SplitMix64 rng(options_.seed ^ (0xd1b54a32d192ed03ull * (static_cast<uint64_t>(node) + 1)));
    const int k = Seed(begin, n, &rng);
    if (k < 2) return k;
    std::fill(assignment_.begin() + begin, assignment_.begin() + begin + n, -1);
    Assign(begin, n, k);
    for (int iteration = 0; iteration < options_.kmeans_iterations; ++iteration) {
      Update(begin, n, k);
      if (!Assign(begin, n, k)) break;
    }
    std::fill(counts_.begin(), counts_.begin() + k, 0);
    for (int32_t p = begin; p < begin + n; ++p) ++counts_[assignment_[p]];
    int kept = 0;
    for (int c = 0; c < k; ++c) {
      if (counts_[c] == 0) continue;
      remap_[c] = kept;
      if (kept != c) {
        std::memcpy(&centroids_[static_cast<size_t>(kept) * kDescriptorSize],
                    &centroids_[static_cast<size_t>(c) * kDescriptorSize], kDescriptorSize);
        counts_[kept] = counts_[c];
      }
      ++kept;
    }
    if (kept != k) {
      for (int32_t p = begin; p < begin + n; ++p) assignment_[p] = remap_[assignment_[p]];
    }
    return kept;
  }

  const uint8_t* descriptors_;
  const DescriptorDistanceKernel& kernel_;
  const VocabularyTreeOptions options_;
  std::unique_ptr<ThreadPool> pool_;
  std::vector<int32_t> ids_;          // training descriptors, grouped by node
  std::vector<int32_t> assignment_;   // per position in ids_: cluster within the current node
  std::vector<int32_t> distance_;     // per position: squared distance to that cluster's centroid
  std::vector<int32_t> scratch_ids_;  // partition buffer
  const size_t max_clusters_;
  std::vector<uint8_t> centroids_;  // the current node's k centroids
  std::vector<uint64_t> sums_;
  std::vector<uint64_t> counts_;
  std::vector<int32_t> remap_;    // cluster -> kept cluster
  std::vector<int32_t> offsets_;  // the children's ranges in ids_
};

Result<VocabularyTree> VocabularyTree::Train(const uint8_t* descriptors, int count,
                                             const VocabularyTreeOptions& options) {
  RECONAR_RETURN_IF_ERROR(options.Check());
  if (descriptors == nullptr) return InvalidArgument("VocabularyTree::Train: null descriptors");
  if (count < 1) return InvalidArgument("VocabularyTree::Train: needs descriptors, got " + std::to_string(count));
  // Selection sampling (Knuth, TAOCP vol. 2, algorithm S): a uniform subset, in ascending order.
  const int sample = std::min(count, options.max_training_descriptors);
  std::vector<int32_t> ids;
  ids.reserve(static_cast<size_t>(sample));
  SplitMix64 rng(options.seed);
  for (int i = 0; i < count && static_cast<int>(ids.size()) < sample; ++i) {
    const uint32_t needed = static_cast<uint32_t>(sample - static_cast<int>(ids.size()));
    if (sample == count || rng.UniformInt(static_cast<uint32_t>(count - i)) < needed) ids.push_back(i);
  }
  VocabularyTree tree;
  Trainer(descriptors, std::move(ids), options).Run(&tree);
  return tree;
}

// ---------------------------------------------------------------------------------------------
// Quantisation and the record

int VocabularyTree::Quantize(const uint8_t* descriptor) const {
  if (nodes_.empty()) return -1;
  const DescriptorDistanceKernel& kernel = ActiveDescriptorDistanceKernel();
  const Node* node = &nodes_[0];
  while (node->first_child >= 0) {
    int32_t distance;
    const int child = NearestCentroid(kernel, descriptor,
                                      centroids_.data() + static_cast<int64_t>(node->first_child) * kDescriptorSize,
                                      node->num_children, &distance);
    node = &nodes_[static_cast<size_t>(node->first_child + child)];
  }
  return node->word;
}

size_t VocabularyTree::memory_bytes() const {
  return sizeof(*this) + nodes_.capacity() * sizeof(Node) + centroids_.capacity();
}

void VocabularyTree::Serialize(ByteWriter* writer) const {
  writer->Put(static_cast<int32_t>(branching_));
  writer->Put(static_cast<int32_t>(num_words_));
  writer->Put(static_cast<uint32_t>(nodes_.size()));
  for (const Node& node : nodes_) {
    writer->Put(node.first_child);
    writer->Put(node.num_children);
    writer->Put(node.word);
  }
  writer->PutBytes(centroids_.data(), centroids_.size());
}

Result<VocabularyTree> VocabularyTree::Deserialize(ByteReader* reader, const std::string& what) {
  int32_t branching = 0;
  int32_t num_words = 0;
  uint32_t num_nodes = 0;
  if (!reader->Get(&branching) || !reader->Get(&num_words) ||
      !reader->GetCount(kNodeRecordBytes, kMaxNodes, &num_nodes)) {
    return TreeError(what, "truncated header or node count beyond the record");
  }
  VocabularyTree tree;
  if (num_nodes == 0) {
    if (branching != 0 || num_words != 0) return TreeError(what, "an empty tree with branching or words");
    return tree;
  }
  if (branching < 2 || branching > kMaxWords) {
    return TreeError(what, "branching " + std::to_string(branching) + " outside 2.." + std::to_string(kMaxWords));
  }
  if (num_words < 1 || static_cast<uint32_t>(num_words) > num_nodes) {
    return TreeError(what, std::to_string(num_words) + " words for " + std::to_string(num_nodes) + " nodes");
  }
  tree.nodes_.resize(num_nodes);
  for (Node& node : tree.nodes_) {
    reader->Get(&node.first_child);
    reader->Get(&node.num_children);
    reader->Get(&node.word);
  }
  tree.centroids_.resize(static_cast<size_t>(num_nodes) * kDescriptorSize);
  reader->GetBytes(tree.centroids_.data(), tree.centroids_.size());
  if (!reader->ok()) return TreeError(what, "truncated nodes");

  // Children lie after their parent (no cycles) and every node but the root has exactly one
  // parent, so the nodes form one tree rooted at 0; its leaves carry the words 0..n-1 once each.
  std::vector<uint8_t> has_parent(num_nodes, 0);
  std::vector<uint8_t> word_seen(static_cast<size_t>(num_words), 0);
  int64_t leaves = 0;
  for (uint32_t i = 0; i < num_nodes; ++i) {
    const Node& node = tree.nodes_[i];
    const std::string where = "node " + std::to_string(i) + ": ";
    if (node.first_child < 0) {
      if (node.first_child != -1 || node.num_children != 0) return TreeError(what, where + "malformed leaf");
      if (node.word < 0 || node.word >= num_words) {
        return TreeError(what,
                         where + "word " + std::to_string(node.word) + " outside 0.." + std::to_string(num_words - 1));
      }
      if (word_seen[static_cast<size_t>(node.word)]++) {
        return TreeError(what, where + "word " + std::to_string(node.word) + " repeated");
      }
      ++leaves;
      continue;
    }
    if (node.word != -1) return TreeError(what, where + "inner node with a word");
    if (node.num_children < 2 || node.num_children > branching) {
      return TreeError(what,
                       where + std::to_string(node.num_children) + " children, branching " + std::to_string(branching));
    }
    if (static_cast<uint32_t>(node.first_child) <= i ||
        static_cast<int64_t>(node.first_child) + node.num_children > static_cast<int64_t>(num_nodes)) {
      return TreeError(what, where + "children " + std::to_string(node.first_child) + ".." +
                                 std::to_string(static_cast<int64_t>(node.first_child) + node.num_children - 1) +
                                 " not after it within " + std::to_string(num_nodes) + " nodes");
    }
    for (int32_t c = node.first_child; c < node.first_child + node.num_children; ++c) {
      if (has_parent[static_cast<size_t>(c)]++)
        return TreeError(what, "node " + std::to_string(c) + " has two parents");
    }
  }
  for (uint32_t i = 1; i < num_nodes; ++i) {
    if (!has_parent[i]) return TreeError(what, "node " + std::to_string(i) + " is not in the tree");
  }
  if (leaves != num_words) {
    return TreeError(what, std::to_string(leaves) + " leaves for " + std::to_string(num_words) + " words");
  }
  tree.branching_ = branching;
  tree.num_words_ = num_words;
  return tree;
}

// ---------------------------------------------------------------------------------------------
// Bags of words

std::vector<float> InverseDocumentFrequency(int num_words, const std::vector<std::vector<int32_t>>& document_words) {
  std::vector<int32_t> document_frequency(static_cast<size_t>(std::max(0, num_words)), 0);
  std::vector<int32_t> words;
  for (const std::vector<int32_t>& document : document_words) {
    words = document;
    std::sort(words.begin(), words.end());
    const auto end = std::unique(words.begin(), words.end());
    for (auto it = words.begin(); it != end; ++it) {
      if (*it >= 0 && *it < num_words) ++document_frequency[static_cast<size_t>(*it)];
    }
  }
  const double num_images = static_cast<double>(document_words.size());
  std::vector<float> idf(document_frequency.size(), 0.0f);
  for (size_t w = 0; w < idf.size(); ++w) {
    const int32_t n = document_frequency[w];
    if (n > 0) idf[w] = static_cast<float>(std::log(num_images / static_cast<double>(n)));
  }
  return idf;
}

BagOfWords MakeBagOfWords(std::vector<int32_t> words, const std::vector<float>& idf) {
  const int32_t num_words = static_cast<int32_t>(idf.size());
  words.erase(std::remove_if(words.begin(), words.end(), [num_words](int32_t w) { return w < 0 || w >= num_words; }),
              words.end());
  BagOfWords bag;
  bag.weights.resize(words.size());
  const int kept = NormaliseBagOfWords(words.data(), static_cast<int>(words.size()), idf.data(), bag.weights.data());
  words.resize(static_cast<size_t>(kept));
  bag.weights.resize(static_cast<size_t>(kept));
  bag.words = std::move(words);
  return bag;
}

float BagOfWordsScore(const BagOfWords& a, const BagOfWords& b) {
  // The sum InvertedFile::Query accumulates over the postings, here by merging two sorted lists.
  float score = 0.0f;
  size_t i = 0, j = 0;
  while (i < a.words.size() && j < b.words.size()) {
    if (a.words[i] < b.words[j]) {
      ++i;
    } else if (b.words[j] < a.words[i]) {
      ++j;
    } else {
      score += 2.0f * std::min(a.weights[i++], b.weights[j++]);
    }
  }
  return score;
}

// ---------------------------------------------------------------------------------------------
// Inverted file

void RetrievalScratch::Reserve(int max_query_words, int num_images) {
  words_.reserve(static_cast<size_t>(std::max(0, max_query_words)));
  weights_.reserve(static_cast<size_t>(std::max(0, max_query_words)));
  if (num_images > 0 && accumulators_.size() < static_cast<size_t>(num_images)) {
    accumulators_.resize(static_cast<size_t>(num_images), 0.0f);
  }
  touched_.reserve(static_cast<size_t>(std::max(0, num_images)));
}

Result<InvertedFile> InvertedFile::Build(int num_words, const std::vector<std::vector<int32_t>>& document_words) {
  if (num_words < 0 || num_words > kMaxWords) {
    return InvalidArgument("InvertedFile: num_words " + std::to_string(num_words) + " outside 0.." +
                           std::to_string(kMaxWords));
  }
  if (document_words.size() > static_cast<size_t>(kMaxImages)) {
    return InvalidArgument("InvertedFile: " + std::to_string(document_words.size()) + " images exceed " +
                           std::to_string(kMaxImages));
  }
  const int num_images = static_cast<int>(document_words.size());
  for (int i = 0; i < num_images; ++i) {
    for (const int32_t w : document_words[static_cast<size_t>(i)]) {
      if (w < 0 || w >= num_words) {
        return InvalidArgument("InvertedFile: image " + std::to_string(i) + " has word " + std::to_string(w) +
                               " outside 0.." + std::to_string(num_words - 1));
      }
    }
  }
  InvertedFile file;
  file.num_images_ = num_images;
  file.idf_ = InverseDocumentFrequency(num_words, document_words);
  // Each image's bag of words, then the postings grouped by word in image order.
  std::vector<int32_t> bag_words;
  std::vector<float> bag_weights;
  std::vector<size_t> bag_begin(static_cast<size_t>(num_images) + 1, 0);
  for (int i = 0; i < num_images; ++i) {
    const BagOfWords bag = MakeBagOfWords(document_words[static_cast<size_t>(i)], file.idf_);
    bag_words.insert(bag_words.end(), bag.words.begin(), bag.words.end());
    bag_weights.insert(bag_weights.end(), bag.weights.begin(), bag.weights.end());
    bag_begin[static_cast<size_t>(i) + 1] = bag_words.size();
  }
  if (bag_words.size() > UINT32_MAX) return InvalidArgument("InvertedFile: more than 2^32 postings");
  file.posting_offsets_.assign(static_cast<size_t>(num_words) + 1, 0);
  for (const int32_t w : bag_words) ++file.posting_offsets_[static_cast<size_t>(w) + 1];
  for (int w = 0; w < num_words; ++w) file.posting_offsets_[w + 1] += file.posting_offsets_[w];
  file.postings_.resize(bag_words.size());
  std::vector<uint32_t> fill(file.posting_offsets_.begin(), file.posting_offsets_.end() - 1);
  for (int i = 0; i < num_images; ++i) {
    for (size_t b = bag_begin[static_cast<size_t>(i)]; b < bag_begin[static_cast<size_t>(i) + 1]; ++b) {
      file.postings_[fill[static_cast<size_t>(bag_words[b])]++] = Posting{i, bag_weights[b]};
    }
  }
  return file;
}

void InvertedFile::Query(const int32_t* words, int count, int top_k, RetrievalScratch* scratch,
                         std::vector<RetrievalCandidate>* out) const {
  out->clear();
  if (top_k <= 0 || num_images_ == 0) return;
  const int32_t num_words = static_cast<int32_t>(idf_.size());
  scratch->words_.clear();
  for (int i = 0; i < count; ++i) {
    if (words[i] >= 0 && words[i] < num_words) scratch->words_.push_back(words[i]);
  }
  scratch->weights_.resize(scratch->words_.size());
  const int distinct = NormaliseBagOfWords(scratch->words_.data(), static_cast<int>(scratch->words_.size()),
                                           idf_.data(), scratch->weights_.data());
  if (scratch->accumulators_.size() < static_cast<size_t>(num_images_)) {
    scratch->accumulators_.resize(static_cast<size_t>(num_images_), 0.0f);
  }
  float* score = scratch->accumulators_.data();
  std::vector<int32_t>& touched = scratch->touched_;
  touched.clear();
  // For L1-normalised q and d, |q - d|_1 = 2 - sum over shared words of (|q_w| + |d_w| - |q_w - d_w|),
  // and with positive weights each term is 2 min(q_w, d_w) (Nistér & Stewénius, sec. 4): only
  // the postings of the query's words are visited. Every term is positive, so a zero score marks
  // an image not yet touched.
  for (int i = 0; i < distinct; ++i) {
    const int32_t w = scratch->words_[static_cast<size_t>(i)];
    const float q = scratch->weights_[static_cast<size_t>(i)];
    for (uint32_t p = posting_offsets_[static_cast<size_t>(w)]; p < posting_offsets_[static_cast<size_t>(w) + 1]; ++p) {
      const Posting& posting = postings_[p];
      if (score[posting.image] == 0.0f) touched.push_back(posting.image);
      score[posting.image] += 2.0f * std::min(q, posting.weight);
    }
  }
  const size_t k = std::min(static_cast<size_t>(top_k), touched.size());
  std::partial_sort(touched.begin(), touched.begin() + static_cast<int64_t>(k), touched.end(),
                    [score](int32_t a, int32_t b) { return score[a] > score[b] || (score[a] == score[b] && a < b); });
  for (size_t i = 0; i < k; ++i) out->push_back({touched[i], score[touched[i]]});
  for (int image = 0; image < num_images_ && out->size() < static_cast<size_t>(top_k); ++image) {
    if (score[image] == 0.0f) out->push_back({image, 0.0f});
  }
  for (const int32_t image : touched) score[image] = 0.0f;
}

size_t InvertedFile::memory_bytes() const {
  return sizeof(*this) + idf_.capacity() * sizeof(float) + posting_offsets_.capacity() * sizeof(uint32_t) +
         postings_.capacity() * sizeof(Posting);
}

void InvertedFile::Serialize(ByteWriter* writer) const {
  static_assert(sizeof(Posting) == 8, "postings are written as they lie in memory");
  writer->Put(static_cast<int32_t>(num_images_));
  writer->Put(static_cast<uint32_t>(idf_.size()));
  writer->PutBytes(idf_.data(), idf_.size() * sizeof(float));
  if (posting_offsets_.empty()) {
    writer->Put(uint32_t{0});
  } else {
    writer->PutBytes(posting_offsets_.data(), posting_offsets_.size() * sizeof(uint32_t));
  }
  writer->Put(static_cast<uint32_t>(postings_.size()));
  writer->PutBytes(postings_.data(), postings_.size() * sizeof(Posting));
}

Result<InvertedFile> InvertedFile::Deserialize(ByteReader* reader, const std::string& what) {
  int32_t num_images = 0;
  uint32_t num_words = 0;
  // Each word holds an idf and an offset: 8 bytes.
  if (!reader->Get(&num_images) || !reader->GetCount(2 * sizeof(uint32_t), kMaxWords, &num_words)) {
    return IndexError(what, "truncated header or word count beyond the record");
  }
  if (num_images < 0 || num_images > kMaxImages) {
    return IndexError(what, std::to_string(num_images) + " images outside 0.." + std::to_string(kMaxImages));
  }
  InvertedFile file;
  file.num_images_ = num_images;
  file.idf_.resize(num_words);
  file.posting_offsets_.resize(static_cast<size_t>(num_words) + 1);
  reader->GetBytes(file.idf_.data(), file.idf_.size() * sizeof(float));
  reader->GetBytes(file.posting_offsets_.data(), file.posting_offsets_.size() * sizeof(uint32_t));
  uint32_t num_postings = 0;
  if (!reader->GetCount(sizeof(Posting), UINT32_MAX, &num_postings)) {
    return IndexError(what, "truncated words or posting count beyond the record");
  }
  file.postings_.resize(num_postings);
  if (!reader->GetBytes(file.postings_.data(), file.postings_.size() * sizeof(Posting))) {
    return IndexError(what, "truncated postings");
  }
  for (uint32_t w = 0; w < num_words; ++w) {
    if (!(file.idf_[w] >= 0.0f && file.idf_[w] <= kMaxIdf)) {
      return IndexError(what, "word " + std::to_string(w) + " has idf " + std::to_string(file.idf_[w]));
    }
  }
  if (file.posting_offsets_[0] != 0 || file.posting_offsets_[num_words] != num_postings) {
    return IndexError(what, "posting offsets do not span the " + std::to_string(num_postings) + " postings");
  }
  for (uint32_t w = 0; w < num_words; ++w) {
    if (file.posting_offsets_[w + 1] < file.posting_offsets_[w]) {
      return IndexError(what, "posting offsets of word " + std::to_string(w) + " decrease");
    }
  }
  for (uint32_t w = 0; w < num_words; ++w) {
    const uint32_t begin = file.posting_offsets_[w];
    const uint32_t end = file.posting_offsets_[w + 1];
    for (uint32_t p = begin; p < end; ++p) {
      const Posting& posting = file.postings_[p];
      if (posting.image < 0 || posting.image >= num_images ||
          (p > begin && posting.image <= file.postings_[p - 1].image)) {
        return IndexError(what, "word " + std::to_string(w) + ": posting image " + std::to_string(posting.image) +
                                    " out of range or order");
      }
      if (!(posting.weight > 0.0f && posting.weight <= 1.0f)) {
        return IndexError(what, "word " + std::to_string(w) + ": posting weight " + std::to_string(posting.weight) +
                                    " outside (0, 1]");
      }
    }
  }
  return file;
}

}  // namespace reconar
