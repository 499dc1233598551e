#include "core/features/kdtree.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <climits>
#include <cmath>
#include <cstdio>
#include <random>
#include <set>
#include <utility>
#include <vector>

#include "core/base/arena.h"

namespace reconar {
namespace {

uint8_t Clamp8(double v) { return static_cast<uint8_t>(std::clamp(std::lround(v), 0l, 255l)); }

// SIFT-like synthetic data: cluster centres with skewed components (mostly small, a few large,
// like SIFT's), ~500 points per cluster with a spread comparable to the gaps between them, so
// nearest neighbours are ambiguous (mean NN/2nd-NN distance ratio ~0.74 for the queries below).
std::vector<uint8_t> ClusteredDescriptors(int count, uint32_t seed, double spread = 30.0) {
  std::mt19937 rng(seed);
  std::exponential_distribution<double> component(1.0 / 25.0);
  std::normal_distribution<double> noise(0.0, spread);
  const int num_clusters = std::max(1, count / 500);
  std::vector<double> centers(static_cast<size_t>(num_clusters) * kDescriptorSize);
  for (auto& c : centers) c = std::min(160.0, component(rng));
  std::uniform_int_distribution<int> pick(0, num_clusters - 1);
  std::vector<uint8_t> data(static_cast<size_t>(count) * kDescriptorSize);
  for (int i = 0; i < count; ++i) {
    const double* center = &centers[static_cast<size_t>(pick(rng)) * kDescriptorSize];
    for (int d = 0; d < kDescriptorSize; ++d) data[static_cast<size_t>(i) * kDescriptorSize + d] = Clamp8(center[d] + noise(rng));
  }
  return data;
}

// Noisy copies of random database points: each has a true (but not necessarily nearest) neighbour.
std::vector<uint8_t> NoisyQueries(const std::vector<uint8_t>& database, int count, double sigma, uint32_t seed) {
  std::mt19937 rng(seed);
  const int n = static_cast<int>(database.size() / kDescriptorSize);
  std::uniform_int_distribution<int> pick(0, n - 1);
  std::normal_distribution<double> noise(0.0, sigma);
  std::vector<uint8_t> queries(static_cast<size_t>(count) * kDescriptorSize);
  for (int q = 0; q < count; ++q) {
    const uint8_t* src = &database[static_cast<size_t>(pick(rng)) * kDescriptorSize];
    for (int d = 0; d < kDescriptorSize; ++d) queries[static_cast<size_t>(q) * kDescriptorSize + d] = Clamp8(src[d] + noise(rng));
  }
  return queries;
}

struct RecallResult {
  double recall_at_1 = 0.0;  // found the exact nearest distance
  double mean_checks = 0.0;
};

RecallResult MeasureRecall(const KdForest& forest, const std::vector<uint8_t>& database,
                           const std::vector<uint8_t>& queries, int max_checks) {
  KdSearchScratch scratch(forest);
  const int num_queries = static_cast<int>(queries.size() / kDescriptorSize);
  const int n = static_cast<int>(database.size() / kDescriptorSize);
  int hits = 0;
  long total_checks = 0;
  for (int q = 0; q < num_queries; ++q) {
    const uint8_t* query = &queries[static_cast<size_t>(q) * kDescriptorSize];
    int idx[2], dist[2], ref_idx[2], ref_dist[2];
    KdSearchStats stats;
    EXPECT_EQ(forest.Search(query, 2, max_checks, idx, dist, &scratch, &stats), std::min(2, n));
    BruteForceKnn(query, database.data(), n, 2, ref_idx, ref_dist);
    if (dist[0] == ref_dist[0]) ++hits;
    total_checks += stats.checks;
  }
  return {static_cast<double>(hits) / num_queries, static_cast<double>(total_checks) / num_queries};
}

class KdForestRecallTest : public ::testing::TestWithParam<int> {};

TEST_P(KdForestRecallTest, RecallAgainstBruteForceWith200Checks) {
  const int n = GetParam();
  const std::vector<uint8_t> database = ClusteredDescriptors(n, 1000 + n);
  const std::vector<uint8_t> queries = NoisyQueries(database, 1000, 30.0, 2000 + n);
  Result<KdForest> forest = KdForest::Build(database.data(), n, KdForestOptions{});
  ASSERT_TRUE(forest.ok()) << forest.status().ToString();
  const RecallResult r = MeasureRecall(*forest, database, queries, 200);
  std::printf("n=%d trees=%d nodes=%d depth=%d: recall@1 %.4f, mean checks %.1f\n", n, forest->num_trees(),
              forest->num_nodes(), forest->max_depth(), r.recall_at_1, r.mean_checks);
  RecordProperty("recall_at_1_x10000", static_cast<int>(r.recall_at_1 * 10000));
  EXPECT_GE(r.recall_at_1, n <= 100 ? 0.99 : n <= 5000 ? 0.95 : 0.90);
  EXPECT_LE(r.mean_checks, 200.0);
}

INSTANTIATE_TEST_SUITE_P(Sizes, KdForestRecallTest, ::testing::Values(100, 5000, 20000));

TEST(KdForestTest, RecallGrowsWithChecks) {
  const int n = 5000;
  const std::vector<uint8_t> database = ClusteredDescriptors(n, 11);
  const std::vector<uint8_t> queries = NoisyQueries(database, 500, 30.0, 12);
  Result<KdForest> forest = KdForest::Build(database.data(), n, KdForestOptions{});
  ASSERT_TRUE(forest.ok());
  const double low = MeasureRecall(*forest, database, queries, 16).recall_at_1;
  const double mid = MeasureRecall(*forest, database, queries, 200).recall_at_1;
  const double high = MeasureRecall(*forest, database, queries, 5000).recall_at_1;
  std::printf("recall@1 with 16 / 200 / 5000 checks: %.3f / %.3f / %.3f\n", low, mid, high);
  EXPECT_LE(low, mid);
  EXPECT_LE(mid, high);
  EXPECT_GE(high, 0.995);
}

TEST(KdForestTest, OtherLeafSizesAndTreeCounts) {
  const int n = 5000;
  const std::vector<uint8_t> database = ClusteredDescriptors(n, 71);
  const std::vector<uint8_t> queries = NoisyQueries(database, 300, 30.0, 72);
  for (const auto& [leaf_size, trees] : std::vector<std::pair<int, int>>{{1, 1}, {4, 4}, {8, 4}, {16, 8}}) {
    KdForestOptions options;
    options.leaf_size = leaf_size;
    options.num_trees = trees;
    Result<KdForest> forest = KdForest::Build(database.data(), n, options);
    ASSERT_TRUE(forest.ok());
    EXPECT_EQ(forest->num_trees(), trees);
    const RecallResult r = MeasureRecall(*forest, database, queries, 200);
    std::printf("leaf_size %d, %d trees: recall@1 %.3f\n", leaf_size, trees, r.recall_at_1);
    EXPECT_GE(r.recall_at_1, 0.8) << leaf_size << " " << trees;
  }
}

TEST(KdForestTest, ResultsSortedDistinctAndExactDistances) {
  const int n = 3000;
  const std::vector<uint8_t> database = ClusteredDescriptors(n, 21);
  const std::vector<uint8_t> queries = NoisyQueries(database, 200, 8.0, 22);
  Result<KdForest> forest = KdForest::Build(database.data(), n, KdForestOptions{});
  ASSERT_TRUE(forest.ok());
  KdSearchScratch scratch(*forest);
  const int k = 10;
  for (int q = 0; q < 200; ++q) {
    const uint8_t* query = &queries[static_cast<size_t>(q) * kDescriptorSize];
    int idx[k], dist[k];
    KdSearchStats stats;
    ASSERT_EQ(forest->Search(query, k, 100, idx, dist, &scratch, &stats), k);
    EXPECT_LE(stats.checks, 100);
    std::set<int> distinct(idx, idx + k);
    EXPECT_EQ(distinct.size(), static_cast<size_t>(k)) << "a point was reported twice";
    for (int i = 0; i < k; ++i) {
      ASSERT_GE(idx[i], 0);
      ASSERT_LT(idx[i], n);
      EXPECT_EQ(dist[i], DescriptorSquaredDistance(query, &database[static_cast<size_t>(idx[i]) * kDescriptorSize]));
      if (i > 0) {
        EXPECT_LE(dist[i - 1], dist[i]);
      }
    }
  }
}

TEST(KdForestTest, BorrowsDescriptorsWithoutCopying) {
  const int n = 4000;
  const std::vector<uint8_t> database = ClusteredDescriptors(n, 31);
  Result<KdForest> forest = KdForest::Build(database.data(), n, KdForestOptions{});
  ASSERT_TRUE(forest.ok());
  EXPECT_EQ(forest->descriptors(), database.data());
  EXPECT_EQ(forest->size(), n);
  // Index memory: per tree one int per point plus nodes; far less than the 128 B per point.
  EXPECT_LT(forest->memory_bytes(), static_cast<size_t>(n) * kDescriptorSize / 2);
}

TEST(KdForestTest, DeterministicForASeed) {
  const int n = 2000;
  const std::vector<uint8_t> database = ClusteredDescriptors(n, 41);
  const std::vector<uint8_t> queries = NoisyQueries(database, 300, 10.0, 42);
  KdForestOptions options;
  Result<KdForest> f1 = KdForest::Build(database.data(), n, options);
  Result<KdForest> f2 = KdForest::Build(database.data(), n, options);
  options.seed += 1;
  Result<KdForest> f3 = KdForest::Build(database.data(), n, options);
  ASSERT_TRUE(f1.ok() && f2.ok() && f3.ok());
  KdSearchScratch s1(*f1), s2(*f2), s3(*f3);
  int differences_other_seed = 0;
  for (int q = 0; q < 300; ++q) {
    const uint8_t* query = &queries[static_cast<size_t>(q) * kDescriptorSize];
    int i1[2], d1[2], i2[2], d2[2], i3[2], d3[2];
    KdSearchStats st1, st2, st3;
    f1->Search(query, 2, 32, i1, d1, &s1, &st1);
    f2->Search(query, 2, 32, i2, d2, &s2, &st2);
    f3->Search(query, 2, 32, i3, d3, &s3, &st3);
    ASSERT_EQ(std::vector<int>(i1, i1 + 2), std::vector<int>(i2, i2 + 2));
    ASSERT_EQ(st1.checks, st2.checks);
    if (st1.checks != st3.checks || i1[0] != i3[0] || i1[1] != i3[1]) ++differences_other_seed;
  }
  EXPECT_GT(differences_other_seed, 0) << "the seed should change the trees";
}

TEST(KdForestTest, EmptyAndTinyForests) {
  Result<KdForest> empty = KdForest::Build(nullptr, 0, KdForestOptions{});
  ASSERT_TRUE(empty.ok());
  uint8_t query[kDescriptorSize] = {};
  int idx[2] = {7, 7}, dist[2] = {7, 7};
  EXPECT_EQ(empty->Search(query, 2, 200, idx, dist, nullptr), 0);
  EXPECT_EQ(idx[0], -1);
  EXPECT_EQ(dist[1], INT32_MAX);

  std::vector<uint8_t> one(kDescriptorSize, 9);
  Result<KdForest> single = KdForest::Build(one.data(), 1, KdForestOptions{});
  ASSERT_TRUE(single.ok());
  KdSearchScratch scratch(*single);
  EXPECT_EQ(single->Search(query, 2, 200, idx, dist, &scratch), 1);
  EXPECT_EQ(idx[0], 0);
  EXPECT_EQ(dist[0], 128 * 81);
  EXPECT_EQ(idx[1], -1);
}

TEST(KdForestTest, IdenticalPointsBecomeOneLeaf) {
  // 500 copies of one descriptor and 50 others: splits cannot separate the copies.
  const int n = 550;
  std::vector<uint8_t> data = ClusteredDescriptors(n, 51);
  for (int i = 0; i < 500; ++i) std::fill_n(&data[static_cast<size_t>(i) * kDescriptorSize], kDescriptorSize, 40);
  KdForestOptions options;
  options.leaf_size = 1;
  Result<KdForest> forest = KdForest::Build(data.data(), n, options);
  ASSERT_TRUE(forest.ok());
  EXPECT_GE(forest->max_leaf_points(), 500);
  KdSearchScratch scratch(*forest);
  std::vector<uint8_t> query(kDescriptorSize, 41);
  int idx[3], dist[3];
  ASSERT_EQ(forest->Search(query.data(), 3, 200, idx, dist, &scratch), 3);
  EXPECT_EQ(dist[0], 128);
  EXPECT_EQ(dist[2], 128);
  EXPECT_LT(idx[0], 500);
}

TEST(KdForestTest, ScratchFromArenaAndTooSmallArena) {
  const int n = 1000;
  const std::vector<uint8_t> database = ClusteredDescriptors(n, 61);
  Result<KdForest> forest = KdForest::Build(database.data(), n, KdForestOptions{});
  ASSERT_TRUE(forest.ok());
  Arena small(64);
  KdSearchScratch scratch;
  const Status too_small = scratch.InitFromArena(*forest, &small);
  EXPECT_EQ(too_small.code(), StatusCode::kResourceExhausted);
  EXPECT_EQ(small.used(), 0u);
  EXPECT_FALSE(scratch.Fits(*forest));

  Arena arena(KdSearchScratch::RequiredBytes(*forest));
  ASSERT_TRUE(scratch.InitFromArena(*forest, &arena).ok());
  EXPECT_TRUE(scratch.Fits(*forest));
  // Many searches reuse the same scratch (visited stamps advance instead of being cleared).
  for (int q = 0; q < n; ++q) {
    int idx[1], dist[1];
    ASSERT_EQ(forest->Search(&database[static_cast<size_t>(q) * kDescriptorSize], 1, 200, idx, dist, &scratch), 1);
    EXPECT_EQ(dist[0], 0);
  }
}

TEST(KdForestTest, RejectsBadInput) {
  KdForestOptions options;
  options.num_trees = 0;
  EXPECT_EQ(KdForest::Build(nullptr, 0, options).status().code(), StatusCode::kInvalidArgument);
  options = KdForestOptions{};
  options.leaf_size = 0;
  EXPECT_FALSE(options.Check().ok());
  EXPECT_EQ(KdForest::Build(nullptr, 5, KdForestOptions{}).status().code(), StatusCode::kInvalidArgument);
  std::vector<uint8_t> data(kDescriptorSize);
  EXPECT_EQ(KdForest::Build(data.data(), -1, KdForestOptions{}).status().code(), StatusCode::kInvalidArgument);
}

TEST(BruteForceKnnTest, TiesKeepLowerIndex) {
  std::vector<uint8_t> data(3 * kDescriptorSize, 10);
  data[0] = 12;  // row 0 at distance 4 from the query; rows 1 and 2 at 0
  std::vector<uint8_t> query(kDescriptorSize, 10);
  int idx[3], dist[3];
  ASSERT_EQ(BruteForceKnn(query.data(), data.data(), 3, 3, idx, dist), 3);
  EXPECT_EQ(idx[0], 1);
  EXPECT_EQ(idx[1], 2);
  EXPECT_EQ(idx[2], 0);
  EXPECT_EQ(dist[2], 4);
}

}  // namespace
}  // namespace reconar
