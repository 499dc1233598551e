#include "core/base/cpu_features.h"

namespace reconar {
namespace {

CpuFeatures DetectCpuFeatures() {
  CpuFeatures features;
#if defined(__x86_64__) || defined(__i386__)
  __builtin_cpu_init();
  features.sse2 = __builtin_cpu_supports("sse2");
  features.avx2 = __builtin_cpu_supports("avx2");
  features.fma = __builtin_cpu_supports("fma");
  features.avx512f = __builtin_cpu_supports("avx512f");
#elif defined(__aarch64__)
  features.neon = true;
#endif
  return features;
}

}  // namespace

const CpuFeatures& HostCpuFeatures() {
  static const CpuFeatures features = DetectCpuFeatures();
  return features;
}

std::string CpuFeatureNames(const CpuFeatures& features) {
  std::string names;
  const auto add = [&names](bool supported, const char* name) {
    if (!supported) return;
    if (!names.empty()) names += ' ';
    names += name;
  };
  add(features.sse2, "sse2");
  add(features.avx2, "avx2");
  add(features.fma, "fma");
  add(features.avx512f, "avx512f");
  add(features.neon, "neon");
  return names.empty() ? "none" : names;
}

}  // namespace reconar
