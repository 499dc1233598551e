// Descriptor matching speed and recall, side by side with OpenCV FLANN in the same process.
//   bench_matching [--repeats=5] [--leaf_size=N] [--image_a=PATH] [--image_b=PATH] [benchmark flags]
// Both index the SAME descriptors: OpenCV SIFT on two fountain-P11 views, rounded to uint8 (what
// our kd-forest takes) and converted back to float for FLANN (which needs float; the values are
// integers, so both see identical squared distances). The database is image B, the queries are
// the descriptors of image A, k = 2 (what the ratio test needs), one thread each.
// Reported: build and query thread CPU time (median over alternating repeats: the machines are
// shared and noisy, and CPU time is less disturbed by other processes than wall time),
// recall@1 against exact brute force (the exact nearest distance was found) and agreement of the
// Lowe-ratio (0.8) matches with brute force. Then Google Benchmark timings of build+query.
#include <benchmark/benchmark.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <random>
#include <string>
#include <ctime>
#include <vector>

#include "bench/common/thread_cpu_time.h"
#include "core/features/descriptor_distance.h"
#include "core/features/kdtree.h"
#include "core/features/matcher.h"

#if defined(RECONAR_BENCH_HAVE_OPENCV)
#include <opencv2/core.hpp>
#include <opencv2/features2d.hpp>
#include <opencv2/flann.hpp>
#include <opencv2/imgcodecs.hpp>
#endif

namespace {

constexpr int kDim = reconar::kDescriptorSize;
constexpr double kMatchRatio = 0.8;

struct Config {
  int repeats = 5;
  int leaf_size = reconar::KdForestOptions{}.leaf_size;
  int top_dims = reconar::KdForestOptions{}.num_top_dims;
  int variance_samples = reconar::KdForestOptions{}.variance_samples;
  std::string image_a = std::string(RECONAR_SHARED_DATA_DIR) + "/strecha_fountain-P11/images/0005.jpg";
  std::string image_b = std::string(RECONAR_SHARED_DATA_DIR) + "/strecha_fountain-P11/images/0004.jpg";
};

struct Data {
  std::string source;
  std::vector<uint8_t> queries, database;  // uint8 rows, 128 per descriptor
  int num_queries = 0, num_database = 0;
  std::vector<int> exact_index, exact_d1, exact_d2;  // brute-force 2-NN per query
#if defined(RECONAR_BENCH_HAVE_OPENCV)
  cv::Mat queries_f32, database_f32;
#endif
};

Data* g_data = nullptr;
Config g_config;

using reconar::bench::ThreadCpuSeconds;

double Median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}

// Recall@1 and ratio-match agreement of approximate 2-NN results against brute force.
struct Quality {
  double recall_at_1 = 0.0;
  double match_recall = 0.0;     // brute-force ratio matches reproduced
  double match_precision = 0.0;  // approximate ratio matches that brute force also makes
};

bool PassesRatio(double d1_sq, double d2_sq) { return d1_sq < kMatchRatio * kMatchRatio * d2_sq; }

Quality Evaluate(const Data& data, const std::vector<int>& index, const std::vector<double>& d1,
                 const std::vector<double>& d2) {
  int hits = 0, exact_matches = 0, approx_matches = 0, common = 0;
  for (int q = 0; q < data.num_queries; ++q) {
    if (std::lround(d1[q]) == data.exact_d1[q]) ++hits;
    const bool exact_pass = PassesRatio(data.exact_d1[q], data.exact_d2[q]);
    const bool approx_pass = PassesRatio(d1[q], d2[q]);
    exact_matches += exact_pass;
    approx_matches += approx_pass;
    common += exact_pass && approx_pass && index[q] == data.exact_index[q];
  }
  Quality quality;
  quality.recall_at_1 = static_cast<double>(hits) / data.num_queries;
  quality.match_recall = static_cast<double>(common) / std::max(1, exact_matches);
  quality.match_precision = static_cast<double>(common) / std::max(1, approx_matches);
  return quality;
}

struct RunResult {
  double build_s = 0.0, query_s = 0.0;
  std::vector<int> index;
  std::vector<double> d1, d2;
};

RunResult RunOurs(const Data& data, int checks) {
  RunResult r;
  reconar::KdForestOptions options;
  options.num_trees = 4;
  options.leaf_size = g_config.leaf_size;
  options.num_top_dims = g_config.top_dims;
  options.variance_samples = g_config.variance_samples;
  options.max_leaf_checks = checks;
  double start = ThreadCpuSeconds();
  reconar::Result<reconar::KdForest> forest = reconar::KdForest::Build(data.database.data(), data.num_database, options);
  if (!forest.ok()) {
    std::fprintf(stderr, "%s\n", forest.status().ToString().c_str());
    std::exit(1);
  }
  r.build_s = ThreadCpuSeconds() - start;
  start = ThreadCpuSeconds();
  reconar::KdSearchScratch scratch(*forest);
  std::vector<int> indices(2 * static_cast<size_t>(data.num_queries));
  std::vector<int> distances(2 * static_cast<size_t>(data.num_queries));
  for (int q = 0; q < data.num_queries; ++q) {
    forest->Search(&data.queries[static_cast<size_t>(q) * kDim], 2, checks, &indices[2 * static_cast<size_t>(q)],
                   &distances[2 * static_cast<size_t>(q)], &scratch);
  }
  r.query_s = ThreadCpuSeconds() - start;
  r.index.resize(static_cast<size_t>(data.num_queries));
  r.d1.resize(static_cast<size_t>(data.num_queries));
  r.d2.resize(static_cast<size_t>(data.num_queries));
  for (int q = 0; q < data.num_queries; ++q) {
    r.index[q] = indices[2 * static_cast<size_t>(q)];
    r.d1[q] = distances[2 * static_cast<size_t>(q)];
    r.d2[q] = distances[2 * static_cast<size_t>(q) + 1];
  }
  return r;
}

#if defined(RECONAR_BENCH_HAVE_OPENCV)
RunResult RunFlann(const Data& data, int checks) {
  RunResult r;
  double start = ThreadCpuSeconds();
  cv::flann::Index index(data.database_f32, cv::flann::KDTreeIndexParams(4));
  r.build_s = ThreadCpuSeconds() - start;
  start = ThreadCpuSeconds();
  cv::Mat indices, distances;
  index.knnSearch(data.queries_f32, indices, distances, 2, cv::flann::SearchParams(checks));
  r.query_s = ThreadCpuSeconds() - start;
  r.index.resize(static_cast<size_t>(data.num_queries));
  r.d1.resize(static_cast<size_t>(data.num_queries));
  r.d2.resize(static_cast<size_t>(data.num_queries));
  for (int q = 0; q < data.num_queries; ++q) {
    r.index[q] = indices.at<int>(q, 0);
    r.d1[q] = distances.at<float>(q, 0);
    r.d2[q] = distances.at<float>(q, 1);
  }
  return r;
}

bool LoadSift(const std::string& path, std::vector<uint8_t>* out, int* count, cv::Mat* as_float) {
  cv::Mat image = cv::imread(path, cv::IMREAD_GRAYSCALE);
  if (image.empty()) {
    std::fprintf(stderr, "%s: cannot read image\n", path.c_str());
    return false;
  }
  std::vector<cv::KeyPoint> keypoints;
  cv::Mat descriptors;
  cv::SIFT::create()->detectAndCompute(image, cv::noArray(), keypoints, descriptors);
  cv::Mat as_u8;
  descriptors.convertTo(as_u8, CV_8U);  // rounds and saturates; SIFT values are already 0..255
  as_u8.convertTo(*as_float, CV_32F);   // FLANN gets exactly the same values
  *count = as_u8.rows;
  out->assign(as_u8.data, as_u8.data + static_cast<size_t>(as_u8.rows) * kDim);
  return true;
}
#endif

#if !defined(RECONAR_BENCH_HAVE_OPENCV)
// Without OpenCV: SIFT-like synthetic clusters, queries as noisy copies.
void MakeSynthetic(Data* data) {
  std::mt19937 rng(1);
  std::exponential_distribution<double> component(1.0 / 25.0);
  std::normal_distribution<double> noise(0.0, 12.0);
  auto clamp8 = [](double v) { return static_cast<uint8_t>(std::clamp(std::lround(v), 0l, 255l)); };
  data->num_database = 10000;
  data->num_queries = 10000;
  std::vector<double> centers(500 * kDim);
  for (double& c : centers) c = std::min(160.0, component(rng));
  data->database.resize(static_cast<size_t>(data->num_database) * kDim);
  for (int i = 0; i < data->num_database; ++i) {
    const double* c = &centers[static_cast<size_t>(rng() % 500) * kDim];
    for (int d = 0; d < kDim; ++d) data->database[static_cast<size_t>(i) * kDim + d] = clamp8(c[d] + noise(rng));
  }
  data->queries.resize(data->database.size());
  for (int i = 0; i < data->num_queries; ++i) {
    const uint8_t* src = &data->database[static_cast<size_t>(rng() % data->num_database) * kDim];
    for (int d = 0; d < kDim; ++d) data->queries[static_cast<size_t>(i) * kDim + d] = clamp8(src[d] + noise(rng));
  }
  data->source = "synthetic clustered descriptors (OpenCV not found)";
}
#endif

bool LoadData(Data* data) {
#if defined(RECONAR_BENCH_HAVE_OPENCV)
  cv::setNumThreads(1);
  if (!LoadSift(g_config.image_a, &data->queries, &data->num_queries, &data->queries_f32) ||
      !LoadSift(g_config.image_b, &data->database, &data->num_database, &data->database_f32)) {
    return false;
  }
  data->source = "OpenCV " CV_VERSION " SIFT: queries " + g_config.image_a + ", database " + g_config.image_b;
#else
  MakeSynthetic(data);
#endif
  // Exact 2-NN by brute force (the reference for recall).
  data->exact_index.resize(static_cast<size_t>(data->num_queries));
  data->exact_d1.resize(static_cast<size_t>(data->num_queries));
  data->exact_d2.resize(static_cast<size_t>(data->num_queries));
  for (int q = 0; q < data->num_queries; ++q) {
    int idx[2], dist[2];
    reconar::BruteForceKnn(&data->queries[static_cast<size_t>(q) * kDim], data->database.data(), data->num_database,
                           2, idx, dist);
    data->exact_index[q] = idx[0];
    data->exact_d1[q] = dist[0];
    data->exact_d2[q] = dist[1];
  }
  return true;
}

// Running mean over `runs` results.
void Accumulate(const Quality& q, int runs, Quality* mean) {
  mean->recall_at_1 += q.recall_at_1 / runs;
  mean->match_recall += q.match_recall / runs;
  mean->match_precision += q.match_precision / runs;
}

void PrintComparisonTable(const Data& data) {
  std::printf("\n%s\n%d queries x %d database descriptors, k=2, 4 trees, one thread each\n", data.source.c_str(),
              data.num_queries, data.num_database);
  std::printf("ours: KdForest leaf_size %d, distance kernel %s; FLANN: cv::flann::Index KDTreeIndexParams(4)\n",
              g_config.leaf_size, reconar::ActiveDescriptorDistanceKernel().name);
  std::printf("thread CPU ms, median of %d alternating runs; recall@1 (exact nearest distance found) and the\n"
              "share of brute-force ratio-0.8 matches found: mean over the runs\n",
              g_config.repeats);
  std::printf("checks |   ours build + query = total |  FLANN build + query = total | ours/FLANN | recall@1 ours  FLANN"
              " | ratio-0.8 matches found ours  FLANN\n");
  for (const int checks : {64, 128, 200, 400}) {
    std::vector<double> ours_build, ours_query, flann_build, flann_query;
    Quality ours_q, flann_q;
    for (int r = 0; r < g_config.repeats; ++r) {
      const RunResult ours = RunOurs(data, checks);
      ours_build.push_back(ours.build_s);
      ours_query.push_back(ours.query_s);
      Accumulate(Evaluate(data, ours.index, ours.d1, ours.d2), g_config.repeats, &ours_q);
#if defined(RECONAR_BENCH_HAVE_OPENCV)
      const RunResult flann = RunFlann(data, checks);
      flann_build.push_back(flann.build_s);
      flann_query.push_back(flann.query_s);
      Accumulate(Evaluate(data, flann.index, flann.d1, flann.d2), g_config.repeats, &flann_q);  // FLANN reseeds
#else
      flann_build.push_back(std::nan(""));
      flann_query.push_back(std::nan(""));
#endif
    }
    const double ob = Median(ours_build) * 1e3, oq = Median(ours_query) * 1e3;
    const double fb = Median(flann_build) * 1e3, fq = Median(flann_query) * 1e3;
    std::printf("%6d | %6.1f + %6.1f = %7.1f   | %6.1f + %6.1f = %7.1f   | %10.3f |        %.4f %.4f"
                " |                     %.4f %.4f\n",
                checks, ob, oq, ob + oq, fb, fq, fb + fq, (ob + oq) / (fb + fq), ours_q.recall_at_1,
                flann_q.recall_at_1, ours_q.match_recall, flann_q.match_recall);
  }
  std::printf("\n");
}

// Times build + query of one method (RunOurs or RunFlann) and reports its recall.
template <RunResult (*Run)(const Data&, int)>
void BM_BuildQuery(benchmark::State& state) {
  const int checks = static_cast<int>(state.range(0));
  Quality q;
  for (auto _ : state) {
    RunResult r = Run(*g_data, checks);
    benchmark::DoNotOptimize(r.index.data());
    state.PauseTiming();
    q = Evaluate(*g_data, r.index, r.d1, r.d2);
    state.ResumeTiming();
  }
  state.counters["recall@1"] = q.recall_at_1;
  state.counters["queries/s"] = benchmark::Counter(g_data->num_queries, benchmark::Counter::kIsIterationInvariantRate);
}

// Strips our own --name=value flags from argv before Google Benchmark sees them.
void ParseOwnFlags(int* argc, char** argv) {
  int out = 1;
  for (int i = 1; i < *argc; ++i) {
    const std::string arg = argv[i];
    auto value = [&](const char* name) -> const char* {
      const size_t n = std::strlen(name);
      return arg.compare(0, n, name) == 0 ? argv[i] + n : nullptr;
    };
    if (const char* v = value("--repeats=")) {
      g_config.repeats = std::max(1, std::atoi(v));
    } else if (const char* v2 = value("--leaf_size=")) {
      g_config.leaf_size = std::max(1, std::atoi(v2));
    } else if (const char* v5 = value("--top_dims=")) {
      g_config.top_dims = std::max(1, std::atoi(v5));
    } else if (const char* v6 = value("--variance_samples=")) {
      g_config.variance_samples = std::max(1, std::atoi(v6));
    } else if (const char* v3 = value("--image_a=")) {
      g_config.image_a = v3;
    } else if (const char* v4 = value("--image_b=")) {
      g_config.image_b = v4;
    } else {
      argv[out++] = argv[i];
    }
  }
  *argc = out;
}

}  // namespace

int main(int argc, char** argv) {
  ParseOwnFlags(&argc, argv);
  benchmark::Initialize(&argc, argv);
  Data data;
  if (!LoadData(&data)) return 2;
  g_data = &data;
  PrintComparisonTable(data);

  benchmark::RegisterBenchmark("KdForest/build+query", BM_BuildQuery<RunOurs>)->Arg(200)->Unit(benchmark::kMillisecond);
#if defined(RECONAR_BENCH_HAVE_OPENCV)
  benchmark::RegisterBenchmark("FlannKdTree/build+query", BM_BuildQuery<RunFlann>)->Arg(200)->Unit(benchmark::kMillisecond);
#endif
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
