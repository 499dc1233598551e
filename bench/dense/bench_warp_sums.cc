// Speed of PatchMatch's inner kernel (core/mvs/patchmatch/warp_sums.h): every kernel this CPU
// runs, the scalar reference first, on the same calls: the 32-sample disc window of the default
// options (radius 5, step 2) warped by random near-identity homographies into a random 1536 x 1024
// image, as in a PatchMatch sweep. Prints ns per call and per sample and the speed-up on scalar.
// Usage: bench_warp_sums [calls]   (default 2,000,000)
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <vector>

#include "core/base/prng.h"
#include "core/mvs/patchmatch/warp_sums.h"

namespace reconar {
namespace {

struct Call {
  WarpHomography h;
};

int Run(int calls) {
  constexpr int kWidth = 1536, kHeight = 1024, kRadius = 5, kStep = 2;
  SplitMix64 random(11);
  std::vector<float> image(static_cast<size_t>(kWidth) * kHeight);
  for (float& v : image) v = static_cast<float>(random.Uniform(0.0, 1.0));
  std::vector<float> ox, oy, w, r;
  for (int y = -kRadius; y <= kRadius; y += kStep) {
    for (int x = -kRadius; x <= kRadius; x += kStep) {
      if (x * x + y * y > (kRadius + 0.5 * kStep) * (kRadius + 0.5 * kStep)) continue;
      ox.push_back(static_cast<float>(x));
      oy.push_back(static_cast<float>(y));
      w.push_back(static_cast<float>(random.Uniform(0.1, 1.0)));
      r.push_back(static_cast<float>(random.Uniform(-0.5, 0.5)));
    }
  }
  const int count = static_cast<int>(ox.size());
  const int padded = PaddedWarpCount(count);
  for (int j = count; j < padded; ++j) {
    ox.push_back(ox[0]);
    oy.push_back(oy[0]);
    w.push_back(0.0f);
    r.push_back(0.0f);
  }
  const WarpWindow window{ox.data(), oy.data(), w.data(), r.data(), padded};
  // 4096 homographies, reused cyclically: centre anywhere at least 20 px from the border, mild
  // affine and projective parts (a plane seen from a neighbouring view).
  std::vector<WarpHomography> warps(4096);
  for (WarpHomography& h : warps) {
    const float x = static_cast<float>(random.Uniform(20.0, kWidth - 21.0));
    const float y = static_cast<float>(random.Uniform(20.0, kHeight - 21.0));
    const float a = static_cast<float>(random.Uniform(-0.2, 0.2)), b = static_cast<float>(random.Uniform(-0.2, 0.2));
    const float c = static_cast<float>(random.Uniform(-0.2, 0.2)), d = static_cast<float>(random.Uniform(-0.2, 0.2));
    h = WarpHomography{x, y, 1.0f, 1.0f + a, c, 1e-4f, b, 1.0f + d, -1e-4f};
  }
  std::printf("warp sums: %d samples per call (%d padded), %d calls per kernel\n", count, padded, calls);
  double scalar_ns = 0.0;
  float checksum = 0.0f;
  for (const WarpSumsKernel& kernel : AvailableWarpSumsKernels()) {
    const auto start = std::chrono::steady_clock::now();
    for (int i = 0; i < calls; ++i) {
      const WarpSums s = kernel.sums(warps[static_cast<size_t>(i) & 4095], window, image.data(), kWidth);
      checksum += s.sum_products;
    }
    const double ns =
        std::chrono::duration<double, std::nano>(std::chrono::steady_clock::now() - start).count() / calls;
    if (scalar_ns == 0.0) scalar_ns = ns;
    std::printf("%-8s %7.1f ns per call  %5.2f ns per sample  %5.2fx scalar\n", kernel.name, ns, ns / count,
                scalar_ns / ns);
  }
  std::printf("(checksum %g)\n", static_cast<double>(checksum));
  return 0;
}

}  // namespace
}  // namespace reconar

int main(int argc, char** argv) {
  const int calls = argc > 1 ? std::atoi(argv[1]) : 2'000'000;
  if (calls <= 0) {
    std::fprintf(stderr, "usage: bench_warp_sums [calls]\n");
    return 2;
  }
  return reconar::Run(calls);
}
