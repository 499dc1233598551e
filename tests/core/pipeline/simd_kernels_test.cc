#include "core/pipeline/simd_kernels.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdlib>
#include <string>

#include "core/features/descriptor_distance.h"
#include "core/features/sift/kernels_dispatch.h"
#include "core/mvs/patchmatch/warp_sums.h"
#include "core/mvs/pmvs/ncc.h"

namespace reconar {
namespace {

// `reconar --version` lists exactly the four dispatchers, by name, each with the kernel the
// dispatcher itself runs (no registry: present even when nothing else of a module is linked).
TEST(SimdKernels, ReportsEachDispatchersActiveKernelByName) {
  const std::vector<KernelChoice> report = SimdKernelReport();
  ASSERT_EQ(report.size(), 4u);
  EXPECT_EQ(report[0].dispatcher, "descriptor");
  EXPECT_EQ(report[0].kernel(), std::string(ActiveDescriptorDistanceKernel().name));
  EXPECT_EQ(report[1].dispatcher, "ncc");
  EXPECT_EQ(report[1].kernel(), std::string(ActiveNccKernel().name));
  EXPECT_EQ(report[2].dispatcher, "sift");
  EXPECT_EQ(report[2].kernel(), std::string(ActiveSiftKernels().name));
  EXPECT_EQ(report[3].dispatcher, "warp");
  EXPECT_EQ(report[3].kernel(), std::string(ActiveWarpSumsKernel().name));
  for (size_t i = 1; i < report.size(); ++i) EXPECT_LT(report[i - 1].dispatcher, report[i].dispatcher);
}

// Each dispatcher runs the kernel its RECONAR_<DISPATCHER>_KERNEL variable names, or its widest
// when the variable is unset or names none of its kernels. CMake runs this test a second time with
// the variables set (pipeline_simd_kernels_override_test).
TEST(SimdKernels, EachDispatcherFollowsItsOverrideVariable) {
  for (const KernelChoice& choice : SimdKernelReport()) {
    EXPECT_EQ(choice.available.front(), "scalar") << choice.dispatcher;
    const char* requested = std::getenv(KernelOverrideVariable(choice.dispatcher).c_str());
    const bool names_one = requested != nullptr && std::find(choice.available.begin(), choice.available.end(),
                                                             requested) != choice.available.end();
    EXPECT_EQ(choice.overridden, names_one) << choice.dispatcher;
    EXPECT_EQ(choice.kernel(), names_one ? std::string(requested) : choice.available.back()) << choice.dispatcher;
  }
}

}  // namespace
}  // namespace reconar
