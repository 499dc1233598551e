#include "core/features/sift/sift_io.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "core/base/atomic_file.h"

namespace reconar {
namespace {

SiftFeatures MakeFeatures(int count) {
  SiftFeatures f;
  for (int i = 0; i < count; ++i) {
    f.keypoints.push_back({1.5f * i, 2.25f * i + 0.5f, 1.0f + i, 0.1f * i, 0.01f * i, i % 3 - 1});
    for (int k = 0; k < 128; ++k) f.descriptors.push_back(static_cast<uint8_t>((i * 31 + k * 7) % 256));
  }
  return f;
}

std::string TempPath(const std::string& name) {
  const auto dir = std::filesystem::temp_directory_path() / ("reconar_sift_io_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  return (dir / name).string();
}

TEST(FeatureFile, RoundTrips) {
  FeatureFile file{640, 480, MakeFeatures(17)};
  const std::string path = TempPath("a.rfeat");
  ASSERT_TRUE(WriteFeatureFile(path, file).ok());
  auto back = ReadFeatureFile(path);
  ASSERT_TRUE(back.ok()) << back.status().ToString();
  EXPECT_EQ(back->image_width, 640);
  EXPECT_EQ(back->image_height, 480);
  ASSERT_EQ(back->features.keypoints.size(), 17u);
  EXPECT_EQ(back->features.descriptors, file.features.descriptors);
  EXPECT_EQ(back->features.keypoints[5].y, file.features.keypoints[5].y);
  EXPECT_EQ(back->features.keypoints[5].octave, file.features.keypoints[5].octave);
}

TEST(FeatureFile, TruncatedOrForeignFilesAreRefusedByName) {
  FeatureFile file{64, 48, MakeFeatures(3)};
  const std::string path = TempPath("b.rfeat");
  ASSERT_TRUE(WriteFeatureFile(path, file).ok());
  std::filesystem::resize_file(path, std::filesystem::file_size(path) - 10);
  auto truncated = ReadFeatureFile(path);
  ASSERT_FALSE(truncated.ok());
  EXPECT_EQ(truncated.status().code(), StatusCode::kCorruptData);
  EXPECT_NE(truncated.status().message().find(path), std::string::npos);

  ASSERT_TRUE(WriteFileAtomically(path, std::string("hello world, not features")).ok());
  EXPECT_EQ(ReadFeatureFile(path).status().code(), StatusCode::kCorruptData);
  EXPECT_EQ(ReadFeatureFile(TempPath("missing.rfeat")).status().code(), StatusCode::kNotFound);
}

TEST(FeatureFile, HeaderAloneGivesSizeAndCountAndIsCheckedTheSameWay) {
  const std::string path = TempPath("h.rfeat");
  for (const int count : {0, 1, 17}) {
    ASSERT_TRUE(WriteFeatureFile(path, FeatureFile{640, 480, MakeFeatures(count)}).ok());
    auto header = ReadFeatureFileHeader(path);
    ASSERT_TRUE(header.ok()) << header.status().ToString();
    EXPECT_EQ(header->image_width, 640);
    EXPECT_EQ(header->image_height, 480);
    EXPECT_EQ(header->count, static_cast<size_t>(count));
  }
  std::filesystem::resize_file(path, std::filesystem::file_size(path) - 10);
  EXPECT_EQ(ReadFeatureFileHeader(path).status().code(), StatusCode::kCorruptData);
  EXPECT_EQ(ReadFeatureFileHeader(path).status().message(), ReadFeatureFile(path).status().message());
  ASSERT_TRUE(WriteFileAtomically(path, std::string("short")).ok());
  EXPECT_EQ(ReadFeatureFileHeader(path).status().code(), StatusCode::kCorruptData);
  ASSERT_TRUE(WriteFileAtomically(path, std::string("hello world, not features, but long enough")).ok());
  EXPECT_EQ(ReadFeatureFileHeader(path).status().code(), StatusCode::kCorruptData);
  const auto missing = ReadFeatureFileHeader(TempPath("missing.rfeat"));
  EXPECT_EQ(missing.status().code(), StatusCode::kNotFound);
  EXPECT_NE(missing.status().message().find("missing.rfeat"), std::string::npos);
}

TEST(LoweKeyFile, RoundTripsWithRowColumnOrder) {
  const SiftFeatures features = MakeFeatures(4);
  const std::string path = TempPath("c.key");
  ASSERT_TRUE(WriteLoweKeyFile(path, features).ok());
  auto text = ReadFileToString(path);
  ASSERT_TRUE(text.ok());
  EXPECT_EQ(text->rfind("4 128\n", 0), 0u);
  // Second keypoint: row (y) first, then column (x).
  EXPECT_NE(text->find("\n2.75 1.50 2.00 0.100\n"), std::string::npos) << *text;
  auto back = ReadLoweKeyFile(path);
  ASSERT_TRUE(back.ok()) << back.status().ToString();
  EXPECT_EQ(back->descriptors, features.descriptors);
  EXPECT_NEAR(back->keypoints[3].x, features.keypoints[3].x, 0.01);
  EXPECT_NEAR(back->keypoints[3].y, features.keypoints[3].y, 0.01);
}

TEST(LoweKeyFile, RejectsMalformed) {
  const std::string path = TempPath("d.key");
  ASSERT_TRUE(WriteFileAtomically(path, std::string("2 128\n1 2 3 4\n5 6\n")).ok());
  auto result = ReadLoweKeyFile(path);
  ASSERT_FALSE(result.ok());
  EXPECT_NE(result.status().message().find(path), std::string::npos);
}

}  // namespace
}  // namespace reconar
