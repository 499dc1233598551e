#include "core/base/kernel_choice.h"

#include <algorithm>
#include <cctype>
#include <cstdlib>

#include "core/base/check.h"
#include "core/base/cpu_features.h"
#include "core/base/log.h"

namespace reconar {

bool CpuRunsKernel(std::string_view kernel) {
  const CpuFeatures& cpu = HostCpuFeatures();
  if (kernel == "scalar") return true;
  if (kernel == "sse2") return cpu.sse2;
  if (kernel == "avx2") return cpu.avx2 && cpu.fma;
  if (kernel == "avx512") return cpu.avx512f && cpu.avx2 && cpu.fma;
  if (kernel == "neon") return cpu.neon;
  RECONAR_CHECK(false) << "no instruction set for a kernel named '" << std::string(kernel) << "'";
  return false;
}

std::string KernelOverrideVariable(std::string_view dispatcher) {
  std::string variable = "RECONAR_";
  for (const char c : dispatcher) variable += static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
  return variable + "_KERNEL";
}

KernelChoice ChooseKernelName(std::string_view dispatcher, std::vector<std::string> available,
                              const char* requested, std::string* warning) {
  RECONAR_CHECK(!available.empty()) << std::string(dispatcher) << " has no kernel";
  warning->clear();
  KernelChoice choice{std::string(dispatcher), std::move(available)};
  choice.chosen = choice.available.size() - 1;
  if (requested == nullptr || *requested == '\0') return choice;
  const auto named = std::find(choice.available.begin(), choice.available.end(), requested);
  if (named != choice.available.end()) {
    choice.chosen = static_cast<size_t>(named - choice.available.begin());
    choice.overridden = true;
    return choice;
  }
  std::string names;
  for (const std::string& name : choice.available) names += (names.empty() ? "" : " ") + name;
  *warning = KernelOverrideVariable(dispatcher) + "=" + requested + " names none of this machine's " +
             std::string(dispatcher) + " kernels (" + names + "); running " + choice.kernel();
  return choice;
}

KernelChoice ChooseKernelFromEnvironment(std::string_view dispatcher, std::vector<std::string> available) {
  std::string warning;
  KernelChoice choice = ChooseKernelName(dispatcher, std::move(available),
                                         std::getenv(KernelOverrideVariable(dispatcher).c_str()), &warning);
  if (!warning.empty()) LogWarning(warning);
  return choice;
}

}  // namespace reconar
