// The intrinsics text file (core/io/intrinsics_file.h): an exact round trip, and every malformed
// file refused with the file and line named.
#include "core/io/intrinsics_file.h"

#include <gtest/gtest.h>

#include <cstdio>
#include <string>

#include "core/base/atomic_file.h"

namespace reconar {
namespace {

TEST(IntrinsicsFileTest, RoundTripsExactly) {
  const std::string path = ::testing::TempDir() + "/intrinsics_file_test.txt";
  // width, height, fx, fy, cx, cy, k1, k2: digits that need all 17 to read back.
  const CameraIntrinsics k{816, 612, 765.0000000000001, 764.18, 393.72, 304.66, -0.12, -1.25e-7};
  ASSERT_TRUE(WriteIntrinsics(path, k).ok());
  Result<CameraIntrinsics> read = ReadIntrinsics(path);
  ASSERT_TRUE(read.ok()) << read.status().ToString();
  EXPECT_EQ(read->fx, k.fx);
  EXPECT_EQ(read->fy, k.fy);
  EXPECT_EQ(read->cx, k.cx);
  EXPECT_EQ(read->cy, k.cy);
  EXPECT_EQ(read->k1, k.k1);
  EXPECT_EQ(read->k2, k.k2);
  EXPECT_EQ(read->width, k.width);
  EXPECT_EQ(read->height, k.height);
  std::remove(path.c_str());
}

TEST(IntrinsicsFileTest, RejectsMalformedFiles) {
  const std::string path = ::testing::TempDir() + "/intrinsics_file_test_bad.txt";
  EXPECT_EQ(ReadIntrinsics(path + ".missing").status().code(), StatusCode::kNotFound);
  const char* bad[] = {
      "# only comments\n",
      "765 764 393 304 0 0 816\n",            // 7 fields
      "765 764 393 304 0 0 816 612 1\n",      // 9 fields
      "765 764 393 304 0 zero 816 612\n",     // not a number
      "765 764 393 304 0 0 816.5 612\n",      // non-integer width
      "-765 764 393 304 0 0 816 612\n",       // fx <= 0
      "765 764 393 304 0 0 816 612\n1 1 1 1 0 0 1 1\n",  // two data lines
  };
  for (const char* text : bad) {
    ASSERT_TRUE(WriteFileAtomically(path, text).ok());
    Result<CameraIntrinsics> read = ReadIntrinsics(path);
    EXPECT_EQ(read.status().code(), StatusCode::kCorruptData) << text;
    EXPECT_NE(read.status().message().find(path), std::string::npos);
  }
  ASSERT_TRUE(WriteFileAtomically(path, "# c\n\n  765 764 393.5 304 -0.1 0.01 816 612  \n# end\n").ok());
  Result<CameraIntrinsics> read = ReadIntrinsics(path);
  ASSERT_TRUE(read.ok()) << read.status().ToString();
  EXPECT_EQ(read->cx, 393.5);
  EXPECT_EQ(read->k1, -0.1);
  CameraIntrinsics invalid;
  EXPECT_EQ(WriteIntrinsics(path, invalid).code(), StatusCode::kInvalidArgument);
  std::remove(path.c_str());
}

}  // namespace
}  // namespace reconar
