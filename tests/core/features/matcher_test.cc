#include "core/features/matcher.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>
#include <set>
#include <utility>
#include <vector>

namespace reconar {
namespace {

uint8_t Clamp8(double v) { return static_cast<uint8_t>(std::clamp(std::lround(v), 0l, 255l)); }

// An image pair with known correspondences: B holds `count_b` SIFT-like descriptors; A holds
// noisy copies of the first `num_true` of them (in shuffled order) followed by unrelated ones.
struct SyntheticPair {
  std::vector<uint8_t> a, b;
  int count_a = 0, count_b = 0;
  std::vector<int> true_b_for_a;  // -1 for distractors
};

SyntheticPair MakePair(int count_b, int num_true, int num_distractors, double sigma, uint32_t seed) {
  std::mt19937 rng(seed);
  std::exponential_distribution<double> component(1.0 / 25.0);
  std::normal_distribution<double> noise(0.0, sigma);
  SyntheticPair p;
  p.count_b = count_b;
  p.count_a = num_true + num_distractors;
  p.b.resize(static_cast<size_t>(count_b) * kDescriptorSize);
  for (auto& v : p.b) v = Clamp8(std::min(160.0, component(rng)));
  std::vector<int> order(static_cast<size_t>(count_b));
  for (int i = 0; i < count_b; ++i) order[static_cast<size_t>(i)] = i;
  std::shuffle(order.begin(), order.end(), rng);
  p.a.resize(static_cast<size_t>(p.count_a) * kDescriptorSize);
  p.true_b_for_a.assign(static_cast<size_t>(p.count_a), -1);
  for (int i = 0; i < p.count_a; ++i) {
    uint8_t* dst = &p.a[static_cast<size_t>(i) * kDescriptorSize];
    if (i < num_true) {
      const int b = order[static_cast<size_t>(i)];
      p.true_b_for_a[static_cast<size_t>(i)] = b;
      for (int d = 0; d < kDescriptorSize; ++d) dst[d] = Clamp8(p.b[static_cast<size_t>(b) * kDescriptorSize + d] + noise(rng));
    } else {
      for (int d = 0; d < kDescriptorSize; ++d) dst[d] = Clamp8(std::min(160.0, component(rng)));
    }
  }
  return p;
}

// Descriptors that are zero except in a few dimensions.
std::vector<uint8_t> Sparse(const std::vector<std::vector<std::pair<int, int>>>& rows) {
  std::vector<uint8_t> data(rows.size() * kDescriptorSize, 0);
  for (size_t r = 0; r < rows.size(); ++r) {
    for (const auto& [dim, value] : rows[r]) data[r * kDescriptorSize + static_cast<size_t>(dim)] = static_cast<uint8_t>(value);
  }
  return data;
}

TEST(MatcherTest, FindsTrueCorrespondences) {
  const SyntheticPair p = MakePair(4000, 2000, 2000, 8.0, 1);
  MatchReport report;
  Result<std::vector<FeatureMatch>> matches =
      MatchDescriptors(p.a.data(), p.count_a, p.b.data(), p.count_b, MatchOptions{}, &report);
  ASSERT_TRUE(matches.ok()) << matches.status().ToString();
  int correct = 0;
  for (const FeatureMatch& m : *matches) correct += p.true_b_for_a[static_cast<size_t>(m.index_a)] == m.index_b;
  const double precision = static_cast<double>(correct) / std::max<size_t>(1, matches->size());
  const double recall = correct / 2000.0;
  std::printf("synthetic pair: %zu matches, precision %.4f, recall %.4f (ratio passed %d, many-to-one dropped %d)\n",
              matches->size(), precision, recall, report.num_ratio_passed, report.num_many_to_one_dropped);
  EXPECT_GE(precision, 0.99);
  EXPECT_GE(recall, 0.90);
  EXPECT_EQ(report.num_queries, p.count_a);
  EXPECT_EQ(report.num_matches, static_cast<int>(matches->size()));
  EXPECT_EQ(report.forests_built, 1);
  for (size_t i = 1; i < matches->size(); ++i) EXPECT_LT((*matches)[i - 1].index_a, (*matches)[i].index_a);
}

// A harder pair: B in SIFT-like clusters of ~500 with ambiguous neighbours, A = noisy copies of
// some of B plus unrelated descriptors from the same clusters.
SyntheticPair MakeClusteredPair(int count_b, int num_true, int num_distractors, uint32_t seed) {
  std::mt19937 rng(seed);
  std::exponential_distribution<double> component(1.0 / 25.0);
  std::normal_distribution<double> spread(0.0, 30.0);
  std::normal_distribution<double> noise(0.0, 20.0);
  const int num_clusters = std::max(1, count_b / 500);
  std::vector<double> centers(static_cast<size_t>(num_clusters) * kDescriptorSize);
  for (auto& c : centers) c = std::min(160.0, component(rng));
  std::uniform_int_distribution<int> pick(0, num_clusters - 1);
  auto sample = [&](uint8_t* dst) {
    const double* center = &centers[static_cast<size_t>(pick(rng)) * kDescriptorSize];
    for (int d = 0; d < kDescriptorSize; ++d) dst[d] = Clamp8(center[d] + spread(rng));
  };
  SyntheticPair p;
  p.count_b = count_b;
  p.count_a = num_true + num_distractors;
  p.b.resize(static_cast<size_t>(count_b) * kDescriptorSize);
  for (int i = 0; i < count_b; ++i) sample(&p.b[static_cast<size_t>(i) * kDescriptorSize]);
  p.a.resize(static_cast<size_t>(p.count_a) * kDescriptorSize);
  p.true_b_for_a.assign(static_cast<size_t>(p.count_a), -1);
  std::uniform_int_distribution<int> pick_b(0, count_b - 1);
  for (int i = 0; i < p.count_a; ++i) {
    uint8_t* dst = &p.a[static_cast<size_t>(i) * kDescriptorSize];
    if (i < num_true) {
      const int b = pick_b(rng);
      p.true_b_for_a[static_cast<size_t>(i)] = b;
      for (int d = 0; d < kDescriptorSize; ++d) dst[d] = Clamp8(p.b[static_cast<size_t>(b) * kDescriptorSize + d] + noise(rng));
    } else {
      sample(dst);
    }
  }
  return p;
}

TEST(MatcherTest, AgreesWithBruteForceMatching) {
  for (const int n : {100, 5000, 20000}) {
    const int queries = std::min(n, 1500);
    const SyntheticPair p = MakeClusteredPair(n, queries * 2 / 3, queries / 3, 100 + n);
    MatchOptions options;
    options.max_ratio = 0.8;
    options.num_threads = 2;
    Result<std::vector<FeatureMatch>> approx = MatchDescriptors(p.a.data(), p.count_a, p.b.data(), p.count_b, options);
    Result<std::vector<FeatureMatch>> exact = BruteForceMatch(p.a.data(), p.count_a, p.b.data(), p.count_b, options);
    ASSERT_TRUE(approx.ok() && exact.ok());
    std::set<std::pair<int, int>> exact_set;
    for (const FeatureMatch& m : *exact) exact_set.insert({m.index_a, m.index_b});
    int common = 0;
    for (const FeatureMatch& m : *approx) common += exact_set.count({m.index_a, m.index_b}) != 0;
    const double recall = static_cast<double>(common) / std::max<size_t>(1, exact->size());
    const double precision = static_cast<double>(common) / std::max<size_t>(1, approx->size());
    std::printf("n=%d, %d queries: brute force %zu matches, kd-forest %zu, recall %.4f precision %.4f\n", n,
                p.count_a, exact->size(), approx->size(), recall, precision);
    EXPECT_GE(recall, 0.95) << n;
    EXPECT_GE(precision, 0.95) << n;
  }
}

TEST(MatcherTest, RatioTestIsStrictOnDistances) {
  // Query at the origin; b0 at distance 30, b1 at distance 50 or 51.
  const std::vector<uint8_t> a = Sparse({{}});
  MatchOptions options;  // max_ratio 0.6: 30 < 0.6 * 50 is false, 30 < 0.6 * 51 is true
  std::vector<uint8_t> b = Sparse({{{0, 30}}, {{1, 50}}});
  Result<std::vector<FeatureMatch>> m = MatchDescriptors(a.data(), 1, b.data(), 2, options);
  ASSERT_TRUE(m.ok());
  EXPECT_TRUE(m->empty());
  b = Sparse({{{0, 30}}, {{1, 51}}});
  m = MatchDescriptors(a.data(), 1, b.data(), 2, options);
  ASSERT_TRUE(m.ok());
  ASSERT_EQ(m->size(), 1u);
  EXPECT_EQ((*m)[0], (FeatureMatch{0, 0}));
  // Two equally close neighbours are ambiguous even at ratio 1.
  options.max_ratio = 1.0;
  b = Sparse({{{0, 30}}, {{1, 30}}});
  m = MatchDescriptors(a.data(), 1, b.data(), 2, options);
  ASSERT_TRUE(m.ok());
  EXPECT_TRUE(m->empty());
  // Brute force applies the same rule.
  m = BruteForceMatch(a.data(), 1, b.data(), 2, options);
  ASSERT_TRUE(m.ok());
  EXPECT_TRUE(m->empty());
}

TEST(MatcherTest, ManyToOneKeepsTheClosestA) {
  const std::vector<uint8_t> a = Sparse({{{0, 100}, {1, 10}}, {{0, 100}, {1, 5}}});
  const std::vector<uint8_t> b = Sparse({{{0, 100}}, {{0, 100}, {1, 100}}});
  for (const bool brute : {false, true}) {
    MatchReport report;
    Result<std::vector<FeatureMatch>> m = brute ? BruteForceMatch(a.data(), 2, b.data(), 2, MatchOptions{}, &report)
                                                : MatchDescriptors(a.data(), 2, b.data(), 2, MatchOptions{}, &report);
    ASSERT_TRUE(m.ok());
    ASSERT_EQ(m->size(), 1u);
    EXPECT_EQ((*m)[0], (FeatureMatch{1, 0}));
    EXPECT_EQ(report.num_ratio_passed, 2);
    EXPECT_EQ(report.num_many_to_one_dropped, 1);
  }
}

TEST(MatcherTest, CrossCheckDropsNonMutualMatches) {
  // a1's nearest is b1 (10, ratio 0.5) and b0's nearest in A is a1 (20 < 25), so (a0, b0) is not mutual.
  const std::vector<uint8_t> a = Sparse({{{0, 100}, {1, 75}}, {{0, 100}, {1, 120}}});
  const std::vector<uint8_t> b = Sparse({{{0, 100}, {1, 100}}, {{0, 100}, {1, 130}}});
  MatchOptions options;
  Result<std::vector<FeatureMatch>> plain = MatchDescriptors(a.data(), 2, b.data(), 2, options);
  ASSERT_TRUE(plain.ok());
  EXPECT_EQ(*plain, (std::vector<FeatureMatch>{{0, 0}, {1, 1}}));
  options.cross_check = true;
  for (const bool brute : {false, true}) {
    MatchReport report;
    Result<std::vector<FeatureMatch>> mutual = brute ? BruteForceMatch(a.data(), 2, b.data(), 2, options, &report)
                                                     : MatchDescriptors(a.data(), 2, b.data(), 2, options, &report);
    ASSERT_TRUE(mutual.ok());
    EXPECT_EQ(*mutual, (std::vector<FeatureMatch>{{1, 1}}));
    EXPECT_EQ(report.num_cross_check_dropped, 1);
    if (!brute) {
      EXPECT_EQ(report.forests_built, 2);
    }
  }
}

TEST(MatcherTest, CrossCheckOnLargerData) {
  const SyntheticPair p = MakePair(3000, 1500, 1500, 8.0, 7);
  MatchOptions options;
  options.cross_check = true;
  Result<std::vector<FeatureMatch>> mutual = MatchDescriptors(p.a.data(), p.count_a, p.b.data(), p.count_b, options);
  options.cross_check = false;
  Result<std::vector<FeatureMatch>> plain = MatchDescriptors(p.a.data(), p.count_a, p.b.data(), p.count_b, options);
  ASSERT_TRUE(mutual.ok() && plain.ok());
  EXPECT_LE(mutual->size(), plain->size());
  EXPECT_GE(mutual->size(), plain->size() * 9 / 10);
  std::set<int> seen_b;
  for (const FeatureMatch& m : *mutual) EXPECT_TRUE(seen_b.insert(m.index_b).second) << "b used twice";
}

TEST(MatcherTest, EmptyAndTinyInputsGiveNoMatches) {
  const std::vector<uint8_t> d = Sparse({{{0, 10}}, {{1, 10}}, {{2, 10}}});
  for (const bool cross : {false, true}) {
    MatchOptions options;
    options.cross_check = cross;
    for (const auto& [ca, cb] : std::vector<std::pair<int, int>>{{0, 0}, {0, 3}, {3, 0}, {3, 1}, {1, 1}}) {
      MatchReport report;
      Result<std::vector<FeatureMatch>> m = MatchDescriptors(ca ? d.data() : nullptr, ca, cb ? d.data() : nullptr, cb,
                                                             options, &report);
      ASSERT_TRUE(m.ok()) << ca << " " << cb;
      EXPECT_TRUE(m->empty());
      EXPECT_EQ(report.num_matches, 0);
      Result<std::vector<FeatureMatch>> bf = BruteForceMatch(d.data(), ca, d.data(), cb, options);
      ASSERT_TRUE(bf.ok());
      EXPECT_TRUE(bf->empty());
    }
  }
}

TEST(MatcherTest, RejectsBadInput) {
  const std::vector<uint8_t> d(kDescriptorSize * 2, 1);
  EXPECT_EQ(MatchDescriptors(d.data(), -1, d.data(), 2, MatchOptions{}).status().code(), StatusCode::kInvalidArgument);
  EXPECT_EQ(MatchDescriptors(nullptr, 2, d.data(), 2, MatchOptions{}).status().code(), StatusCode::kInvalidArgument);
  MatchOptions bad;
  bad.max_ratio = 0.0;
  EXPECT_EQ(MatchDescriptors(d.data(), 2, d.data(), 2, bad).status().code(), StatusCode::kInvalidArgument);
  bad = MatchOptions{};
  bad.num_trees = 0;
  EXPECT_FALSE(bad.Check().ok());
  EXPECT_FALSE(Matcher::Create(bad).ok());
}

TEST(MatcherTest, DeterministicAcrossRunsAndThreadCounts) {
  const SyntheticPair p = MakeClusteredPair(5000, 1500, 1000, 3);
  MatchOptions options;
  options.cross_check = true;
  Result<std::vector<FeatureMatch>> first = MatchDescriptors(p.a.data(), p.count_a, p.b.data(), p.count_b, options);
  ASSERT_TRUE(first.ok());
  for (const int threads : {1, 2, 4, 0}) {
    options.num_threads = threads;
    Result<std::vector<FeatureMatch>> again = MatchDescriptors(p.a.data(), p.count_a, p.b.data(), p.count_b, options);
    ASSERT_TRUE(again.ok());
    EXPECT_EQ(*again, *first) << threads << " threads";
  }
}

TEST(MatcherTest, ReusableMatcherBuildsEachForestOnce) {
  const SyntheticPair p01 = MakePair(3000, 1500, 500, 8.0, 5);
  const SyntheticPair p2 = MakePair(2000, 1000, 500, 8.0, 6);
  MatchOptions options;
  options.num_threads = 2;
  Result<std::unique_ptr<Matcher>> matcher = Matcher::Create(options);
  ASSERT_TRUE(matcher.ok());
  Matcher& m = **matcher;
  ASSERT_TRUE(m.AddImage(0, p01.a.data(), p01.count_a).ok());
  ASSERT_TRUE(m.AddImage(1, p01.b.data(), p01.count_b).ok());
  ASSERT_TRUE(m.AddImage(2, p2.b.data(), p2.count_b).ok());
  EXPECT_EQ(m.Match(0, 7).status().code(), StatusCode::kNotFound);

  int built = 0;
  const std::pair<int, int> pairs[] = {{0, 1}, {0, 2}, {1, 2}, {2, 0}, {0, 1}};
  for (const auto& [ia, ib] : pairs) {
    MatchReport report;
    Result<std::vector<FeatureMatch>> got = m.Match(ia, ib, &report);
    ASSERT_TRUE(got.ok());
    built += report.forests_built;
    const uint8_t* da = ia == 0 ? p01.a.data() : ia == 1 ? p01.b.data() : p2.b.data();
    const int ca = ia == 0 ? p01.count_a : ia == 1 ? p01.count_b : p2.count_b;
    const uint8_t* db = ib == 0 ? p01.a.data() : ib == 1 ? p01.b.data() : p2.b.data();
    const int cb = ib == 0 ? p01.count_a : ib == 1 ? p01.count_b : p2.count_b;
    Result<std::vector<FeatureMatch>> want = MatchDescriptors(da, ca, db, cb, options);
    ASSERT_TRUE(want.ok());
    EXPECT_EQ(*got, *want) << ia << "-" << ib;
  }
  EXPECT_EQ(built, 3) << "one forest per image";
  EXPECT_GT(m.forest_memory_bytes(), 0u);
  m.RemoveImage(2);
  EXPECT_FALSE(m.HasImage(2));
}

}  // namespace
}  // namespace reconar
