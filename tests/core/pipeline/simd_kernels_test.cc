#include "core/pipeline/simd_kernels.h"

#include <gtest/gtest.h>

#include <string>

#include "core/features/descriptor_distance.h"
#include "core/features/sift/kernels.h"
#include "core/mvs/pmvs/ncc.h"

namespace reconar {
namespace {

// `reconar --version` lists exactly the three dispatchers, by name, each with the kernel the
// dispatcher itself runs (no registry: present even when nothing else of a module is linked).
TEST(SimdKernels, ReportsEachDispatchersActiveKernelByName) {
  const std::vector<SimdKernelChoice> report = SimdKernelReport();
  ASSERT_EQ(report.size(), 3u);
  EXPECT_EQ(report[0].dispatcher, "descriptor_distance");
  EXPECT_EQ(report[0].kernel, std::string(ActiveDescriptorDistanceKernel().name));
  EXPECT_EQ(report[1].dispatcher, "ncc");
  EXPECT_EQ(report[1].kernel, std::string(ActiveNccKernel().name));
  EXPECT_EQ(report[2].dispatcher, "sift");
  EXPECT_EQ(report[2].kernel, std::string(BestSiftKernels().name));
  for (size_t i = 1; i < report.size(); ++i) EXPECT_LT(report[i - 1].dispatcher, report[i].dispatcher);
}

}  // namespace
}  // namespace reconar
