#include "core/base/memory_usage.h"

#include <gtest/gtest.h>

#include <cstring>
#include <memory>

namespace reconar {
namespace {

TEST(MemoryUsage, PeakFollowsATouchedAllocationAndResets) {
  const MemoryUsage before = CurrentMemoryUsage();
  if (!before.known) GTEST_SKIP() << "/proc/self/status is not available";
  EXPECT_GT(before.resident_bytes, 0u);
  EXPECT_GE(before.peak_resident_bytes, before.resident_bytes);
  const size_t size = 64u << 20;
  {
    std::unique_ptr<char[]> block(new char[size]);
    std::memset(block.get(), 1, size);  // touch every page so that it is resident
    EXPECT_GE(PeakResidentBytes(), before.resident_bytes + size * 9 / 10);
    EXPECT_EQ(block[size - 1], 1);
  }
  const size_t peak_with_block = PeakResidentBytes();
  if (!ResetPeakResidentBytes()) GTEST_SKIP() << "the kernel refused the VmHWM reset";
  const MemoryUsage after = CurrentMemoryUsage();
  // The block is gone (large blocks are unmapped on free), so the reset peak is well below it.
  EXPECT_LT(after.peak_resident_bytes + size / 2, peak_with_block);
  EXPECT_GE(after.peak_resident_bytes, after.resident_bytes);
}

}  // namespace
}  // namespace reconar
