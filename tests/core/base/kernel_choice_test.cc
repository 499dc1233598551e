#include "core/base/kernel_choice.h"

#include <gtest/gtest.h>

#include <cstdlib>
#include <string>
#include <vector>

#include "core/base/cpu_features.h"

namespace reconar {
namespace {

const std::vector<std::string> kAvailable = {"scalar", "sse2", "avx2"};

TEST(KernelChoice, OverrideVariableIsTheUpperCasedDispatcherName) {
  EXPECT_EQ(KernelOverrideVariable("ncc"), "RECONAR_NCC_KERNEL");
  EXPECT_EQ(KernelOverrideVariable("descriptor"), "RECONAR_DESCRIPTOR_KERNEL");
  EXPECT_EQ(KernelOverrideVariable("warp"), "RECONAR_WARP_KERNEL");
  EXPECT_EQ(KernelOverrideVariable("sift"), "RECONAR_SIFT_KERNEL");
}

TEST(KernelChoice, WithoutAnOverrideTheWidestRuns) {
  std::string warning = "stale";
  for (const char* requested : {static_cast<const char*>(nullptr), ""}) {
    const KernelChoice choice = ChooseKernelName("ncc", kAvailable, requested, &warning);
    EXPECT_EQ(choice.dispatcher, "ncc");
    EXPECT_EQ(choice.available, kAvailable);
    EXPECT_EQ(choice.kernel(), "avx2");
    EXPECT_FALSE(choice.overridden);
    EXPECT_EQ(warning, "");
  }
}

TEST(KernelChoice, AnOverrideNamingAnAvailableKernelChoosesIt) {
  std::string warning;
  for (const std::string& name : kAvailable) {
    const KernelChoice choice = ChooseKernelName("ncc", kAvailable, name.c_str(), &warning);
    EXPECT_EQ(choice.kernel(), name);
    EXPECT_TRUE(choice.overridden);
    EXPECT_EQ(warning, "");
  }
}

// A misspelt name, another case or a kernel of another instruction set: the widest runs and the
// warning names the variable, its value and what it could have named.
TEST(KernelChoice, AnOverrideNamingNoAvailableKernelFallsBackWithAWarning) {
  for (const char* requested : {"scaler", "AVX2", "neon"}) {
    std::string warning;
    const KernelChoice choice = ChooseKernelName("ncc", kAvailable, requested, &warning);
    EXPECT_EQ(choice.kernel(), "avx2");
    EXPECT_FALSE(choice.overridden);
    EXPECT_EQ(warning, std::string("RECONAR_NCC_KERNEL=") + requested +
                           " names none of this machine's ncc kernels (scalar sse2 avx2); running avx2");
  }
}

struct FakeKernel {
  const char* name;
  int id;
};

TEST(KernelChoice, KernelsThisCpuRunsKeepsOrderAndDropsWhatTheCpuLacks) {
  const std::vector<FakeKernel> runs =
      KernelsThisCpuRuns<FakeKernel>({{"scalar", 0}, {"sse2", 1}, {"avx2", 2}, {"avx512", 3}, {"neon", 4}});
  const CpuFeatures& cpu = HostCpuFeatures();
  std::vector<int> expected = {0};
  if (cpu.sse2) expected.push_back(1);
  if (cpu.avx2 && cpu.fma) expected.push_back(2);
  if (cpu.avx512f && cpu.avx2 && cpu.fma) expected.push_back(3);
  if (cpu.neon) expected.push_back(4);
  std::vector<int> got;
  for (const FakeKernel& kernel : runs) got.push_back(kernel.id);
  EXPECT_EQ(got, expected);
}

TEST(KernelChoice, ChooseKernelReadsTheDispatchersVariable) {
  const std::vector<FakeKernel> available = {{"scalar", 0}, {"sse2", 1}, {"avx2", 2}};
  ASSERT_EQ(setenv("RECONAR_KERNEL_CHOICE_TEST_KERNEL", "sse2", 1), 0);
  const KernelDispatch<FakeKernel> forced = ChooseKernel("kernel_choice_test", available);
  EXPECT_EQ(forced.kernel.id, 1);
  EXPECT_EQ(forced.choice.kernel(), "sse2");
  EXPECT_TRUE(forced.choice.overridden);
  ASSERT_EQ(unsetenv("RECONAR_KERNEL_CHOICE_TEST_KERNEL"), 0);
  const KernelDispatch<FakeKernel> widest = ChooseKernel("kernel_choice_test", available);
  EXPECT_EQ(widest.kernel.id, 2);
  EXPECT_FALSE(widest.choice.overridden);
}

TEST(KernelChoiceDeathTest, AKernelNameOfNoInstructionSetIsAProgrammingError) {
  EXPECT_DEATH(CpuRunsKernel("sse9"), "no instruction set for a kernel named 'sse9'");
}

}  // namespace
}  // namespace reconar
