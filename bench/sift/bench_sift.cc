// SIFT speed, side by side with OpenCV 4.x SIFT in the same process, one thread each.
//   bench_sift IMAGE [repeats=3] [first_octave=-1]
// Both get the same 8-bit gray image (decoded once by OpenCV); our timing includes the
// conversion to float, OpenCV's includes its own. Runs alternate to share machine noise.
#include <opencv2/core.hpp>
#include <opencv2/features2d.hpp>
#include <opencv2/imgcodecs.hpp>

#include <time.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <vector>

#include "bench/common/thread_cpu_time.h"
#include "core/features/sift/sift.h"

using Clock = std::chrono::steady_clock;

using reconar::bench::ThreadCpuSeconds;

static double Median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}

int main(int argc, char** argv) {
  if (argc < 2) {
    std::fprintf(stderr, "usage: %s IMAGE [repeats=3] [first_octave=-1]\n", argv[0]);
    return 2;
  }
  const int repeats = argc > 2 ? std::atoi(argv[2]) : 3;
  const int first_octave = argc > 3 ? std::atoi(argv[3]) : -1;
  cv::Mat gray8 = cv::imread(argv[1], cv::IMREAD_GRAYSCALE);
  if (gray8.empty()) {
    std::fprintf(stderr, "%s: cannot read image\n", argv[1]);
    return 2;
  }
  cv::setNumThreads(1);
  cv::Ptr<cv::SIFT> opencv_sift = cv::SIFT::create();
  reconar::SiftOptions options;
  options.first_octave = first_octave;
  options.arena_bytes = reconar::SiftExtractor::RequiredArenaBytes(gray8.cols, gray8.rows, options);
  reconar::SiftExtractor ours(options);
  reconar::Image<float> gray(gray8.cols, gray8.rows);

  std::vector<double> t_ours, t_cv, cpu_ours, cpu_cv;
  size_t n_ours = 0, n_cv = 0;
  reconar::SiftReport report;
  for (int r = 0; r < repeats; ++r) {
    auto start = Clock::now();
    double cpu_start = ThreadCpuSeconds();
    for (int y = 0; y < gray8.rows; ++y) {
      const uint8_t* in = gray8.ptr<uint8_t>(y);
      float* out = gray.row(y);
      for (int x = 0; x < gray8.cols; ++x) out[x] = in[x] * (1.0f / 255.0f);
    }
    auto result = ours.Extract(gray.view(), &report);
    t_ours.push_back(std::chrono::duration<double>(Clock::now() - start).count());
    cpu_ours.push_back(ThreadCpuSeconds() - cpu_start);
    if (!result.ok()) {
      std::fprintf(stderr, "reconar SIFT failed: %s\n", result.status().ToString().c_str());
      return 1;
    }
    n_ours = result->keypoints.size();

    start = Clock::now();
    cpu_start = ThreadCpuSeconds();
    std::vector<cv::KeyPoint> keypoints;
    cv::Mat descriptors;
    opencv_sift->detectAndCompute(gray8, cv::noArray(), keypoints, descriptors);
    t_cv.push_back(std::chrono::duration<double>(Clock::now() - start).count());
    cpu_cv.push_back(ThreadCpuSeconds() - cpu_start);
    n_cv = keypoints.size();
  }
  const double ours_s = Median(t_ours), cv_s = Median(t_cv);
  std::printf("image %s (%dx%d), %d repeats, median wall time, one thread\n", argv[1], gray8.cols, gray8.rows,
              repeats);
  std::printf("  reconar SIFT (first octave %d, kernels %s): %.3f s, %zu features\n", first_octave,
              report.kernels, ours_s, n_ours);
  std::printf("    pyramid %.3f s, detection %.3f s, orientation %.3f s, descriptor %.3f s\n",
              report.seconds_pyramid, report.seconds_detection, report.seconds_orientation,
              report.seconds_descriptor);
  std::printf("    candidates %d, arena peak %.1f MiB of %.1f MiB\n", report.num_candidates,
              report.arena_peak_bytes / 1048576.0, options.arena_bytes / 1048576.0);
  std::printf("  OpenCV %s SIFT (default, upsampling): %.3f s, %zu features\n", CV_VERSION, cv_s, n_cv);
  std::printf("  time ratio reconar/OpenCV = %.3f wall, %.3f thread CPU (%.3f s / %.3f s); feature ratio = %.2f\n",
              ours_s / cv_s, Median(cpu_ours) / Median(cpu_cv), Median(cpu_ours), Median(cpu_cv),
              static_cast<double>(n_ours) / static_cast<double>(n_cv));
  return 0;
}
