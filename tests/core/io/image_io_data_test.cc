// End-to-end checks of the image readers on the public datasets in RECONAR_SHARED_DATA_DIR.
// A missing data file is a failure, not a skip.
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>

#include "core/io/focal_prior.h"
#include "core/io/image_io.h"
#include "tests/core/io/test_matchers.h"

namespace reconar {
namespace {


std::string DataPath(const std::string& relative) {
  const std::string path = std::string(RECONAR_SHARED_DATA_DIR) + "/" + relative;
  EXPECT_TRUE(std::filesystem::exists(path)) << "missing dataset file " << path;
  return path;
}

std::string ReadAll(const std::string& path) {
  std::ifstream file(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(file), {});
}

struct Stats {
  double mean = 0;
  double stddev = 0;
};

Stats ComputeStats(const Image<uint8_t>& image) {
  const size_t n = image.size_bytes();
  double sum = 0;
  double sum_sq = 0;
  for (size_t i = 0; i < n; ++i) {
    sum += image.data()[i];
    sum_sq += static_cast<double>(image.data()[i]) * image.data()[i];
  }
  Stats s;
  s.mean = sum / n;
  s.stddev = std::sqrt(std::max(0.0, sum_sq / n - s.mean * s.mean));
  return s;
}

TEST(ImageIoDataTest, DecodesStrechaFountainJpeg) {
  const std::string path = DataPath("strecha_fountain-P11/images/0000.jpg");
  const auto start = std::chrono::steady_clock::now();
  auto decoded = ReadImage(path);
  const double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  ASSERT_TRUE(decoded.ok()) << decoded.status().ToString();
  std::printf("decoded %s in %.1f ms\n", path.c_str(), ms);
  EXPECT_EQ(decoded->rgb.width(), 3072);
  EXPECT_EQ(decoded->rgb.height(), 2048);
  EXPECT_EQ(decoded->rgb.channels(), 3);
  EXPECT_FALSE(decoded->exif.present);
  EXPECT_TRUE(decoded->warnings.empty());
  const Stats stats = ComputeStats(decoded->rgb);
  EXPECT_GT(stats.mean, 40);
  EXPECT_LT(stats.mean, 210);
  EXPECT_GT(stats.stddev, 20);
  // Rows differ: the bottom half was not filled with libjpeg's grey padding.
  const uint8_t* last = decoded->rgb.row(2047);
  int grey = 0;
  for (int x = 0; x < 3072 * 3; ++x) grey += last[x] == 128;
  EXPECT_LT(grey, 3072 * 3 / 2);

  const Image<float> gray = ToGrayFloat(decoded->rgb);
  EXPECT_EQ(gray.width(), 3072);
  EXPECT_EQ(gray.channels(), 1);

  const FocalPrior prior = EstimateFocalPrior(decoded->exif, 3072, 2048);
  EXPECT_EQ(prior.source, FocalPrior::Source::kDefault);
}

TEST(ImageIoDataTest, DecodesMiddleburyPng) {
  auto decoded = ReadImage(DataPath("middlebury_templeRing/templeR0001.png"));
  ASSERT_TRUE(decoded.ok()) << decoded.status().ToString();
  EXPECT_EQ(decoded->rgb.width(), 640);
  EXPECT_EQ(decoded->rgb.height(), 480);
  const Stats stats = ComputeStats(decoded->rgb);
  EXPECT_GT(stats.mean, 2);  // a bright object on a black background
  EXPECT_LT(stats.mean, 200);
  EXPECT_GT(stats.stddev, 10);
}

TEST(ImageIoDataTest, ReadsIphoneExif) {
  const std::string path = DataPath("apriltag_swatbotics_mapping/IMG_1368.JPG");
  auto decoded = ReadImage(path);
  ASSERT_TRUE(decoded.ok()) << decoded.status().ToString();
  const ExifInfo& exif = decoded->exif;
  EXPECT_TRUE(exif.present);
  EXPECT_EQ(exif.warning, "");
  EXPECT_EQ(exif.make, "Apple");
  EXPECT_EQ(exif.model, "iPhone 4S");
  EXPECT_NEAR(exif.focal_length_mm, 4.28, 0.01);
  EXPECT_EQ(exif.focal_length_35mm, 35);
  EXPECT_EQ(exif.orientation, 1);
  // The file was downscaled after capture: EXIF still describes the 8 MP original.
  EXPECT_EQ(exif.pixel_x_dimension, 3264);
  EXPECT_EQ(exif.pixel_y_dimension, 2448);
  EXPECT_EQ(decoded->rgb.width(), 816);
  EXPECT_EQ(decoded->rgb.height(), 612);
  EXPECT_EQ(ReadExifFromJpeg(ReadAll(path)).model, "iPhone 4S");
  // The exposure settings, as PIL reads them: 1/20 s, f/2.4, ISO 125.
  EXPECT_DOUBLE_EQ(exif.exposure_time_s, 0.05);
  EXPECT_NEAR(exif.f_number, 2.4, 1e-9);
  EXPECT_EQ(exif.iso, 125);

  const FocalPrior prior = EstimateFocalPrior(exif, 816, 612);
  EXPECT_EQ(prior.source, FocalPrior::Source::kExif35mm);
  // Upstream checkerboard calibration says fx = 765.0: the prior is within 5 %.
  EXPECT_NEAR(prior.focal_px, 765.0, 0.05 * 765.0);
}

TEST(ImageIoDataTest, ReadsLittleEndianCanonExif) {
  auto decoded = ReadImage(DataPath("bundler_kermit/kermit000.jpg"));
  ASSERT_TRUE(decoded.ok()) << decoded.status().ToString();
  const ExifInfo& exif = decoded->exif;
  EXPECT_TRUE(exif.present);
  EXPECT_EQ(exif.make, "Canon");
  EXPECT_EQ(exif.model, "Canon PowerShot A10");
  EXPECT_NEAR(exif.focal_length_mm, 5.4, 0.01);
  EXPECT_EQ(exif.focal_length_35mm, 0);
  EXPECT_NEAR(exif.focal_plane_x_resolution, 3106.8, 0.1);
  EXPECT_EQ(exif.focal_plane_resolution_unit, 2);
  EXPECT_DOUBLE_EQ(exif.exposure_time_s, 0.05);  // 1/20 s at f/2.8, no ISO recorded (as PIL reads it)
  EXPECT_NEAR(exif.f_number, 2.8, 1e-9);
  EXPECT_EQ(exif.iso, 0);
  const FocalPrior prior = EstimateFocalPrior(exif, decoded->rgb.width(), decoded->rgb.height());
  EXPECT_EQ(prior.source, FocalPrior::Source::kExifSensorTable);
  EXPECT_NEAR(prior.focal_px, exif.focal_length_mm / 5.27 * 640, 1e-6);
}

TEST(ImageIoDataTest, ReadsKodakExifFromSceaux) {
  auto decoded = ReadImage(DataPath("sceaux_castle/100_7100.JPG"));
  ASSERT_TRUE(decoded.ok()) << decoded.status().ToString();
  EXPECT_EQ(decoded->rgb.width(), 2832);
  EXPECT_EQ(decoded->rgb.height(), 2128);
  EXPECT_EQ(decoded->exif.make, "EASTMAN KODAK COMPANY");
  EXPECT_EQ(decoded->exif.focal_length_35mm, 35);
  // openMVG's K.txt for this set uses f = 2905.88 px (5.8 mm on its own sensor database); the
  // integer 35 mm equivalent gives 35/36 * 2832 = 2753.3 px, 5 % lower. A prior, not a calibration.
  const FocalPrior prior = EstimateFocalPrior(decoded->exif, 2832, 2128);
  EXPECT_EQ(prior.source, FocalPrior::Source::kExif35mm);
  EXPECT_NEAR(prior.focal_px, 2905.88, 0.1 * 2905.88);
}

TEST(ImageIoDataTest, RealJpegTruncatedAtHalfIsAnError) {
  const std::string path = DataPath("strecha_fountain-P11/images/0000.jpg");
  const std::string bytes = ReadAll(path);
  ASSERT_GT(bytes.size(), 1000u);
  auto decoded = ReadImageFromMemory(bytes.substr(0, bytes.size() / 2), "0000.jpg");
  ASSERT_FALSE(decoded.ok());
  EXPECT_EQ(decoded.status().code(), StatusCode::kCorruptData);
  EXPECT_TRUE(testing::HasSubstring(decoded.status().message(), "0000.jpg: truncated JPEG data (got "));
  EXPECT_TRUE(testing::HasSubstring(decoded.status().message(), " of 2048 rows)"));
  std::printf("%s\n", decoded.status().ToString().c_str());
}

// Documented behaviour: a flipped byte inside the entropy-coded scan either goes unnoticed by
// libjpeg (wrong pixels in one or more 16x16 blocks, Status ok) or makes the Huffman decoder
// lose sync, which we report as kCorruptData. Either way: no crash, and errors name the file.
TEST(ImageIoDataTest, RealJpegWithFlippedScanByte) {
  const std::string bytes = ReadAll(DataPath("strecha_fountain-P11/images/0000.jpg"));
  const size_t scan_start = bytes.find("\xFF\xDA");
  ASSERT_NE(scan_start, std::string::npos);
  int ok = 0;
  int corrupt = 0;
  for (int i = 0; i < 4; ++i) {
    std::string damaged = bytes;
    const size_t at = scan_start + (bytes.size() - scan_start) * (2 * i + 1) / 8;
    damaged[at] = static_cast<char>(damaged[at] ^ 0x5A);
    auto decoded = ReadImageFromMemory(damaged, "flipped.jpg");
    if (decoded.ok()) {
      ++ok;
      EXPECT_EQ(decoded->rgb.width(), 3072);
    } else {
      ++corrupt;
      EXPECT_EQ(decoded.status().code(), StatusCode::kCorruptData);
      EXPECT_TRUE(testing::HasSubstring(decoded.status().message(), "flipped.jpg: "));
      std::printf("byte %zu flipped: %s\n", at, decoded.status().ToString().c_str());
    }
  }
  std::printf("flipped scan bytes: %d decoded with wrong pixels, %d reported as corrupt\n", ok, corrupt);
}

// Every image of the smaller datasets decodes without error.
TEST(ImageIoDataTest, WholeDatasetsDecode) {
  const char* dirs[] = {"apriltag_swatbotics_mapping", "bundler_kermit", "bundler_ET", "middlebury_templeSparseRing",
                        "strecha_fountain-P11/images"};
  int count = 0;
  for (const char* dir : dirs) {
    const std::string root = DataPath(dir);
    for (const auto& entry : std::filesystem::directory_iterator(root)) {
      const std::string ext = entry.path().extension().string();
      if (ext != ".jpg" && ext != ".JPG" && ext != ".png") continue;
      auto decoded = ReadImage(entry.path().string());
      EXPECT_TRUE(decoded.ok()) << decoded.status().ToString();
      if (decoded.ok()) {
        EXPECT_FALSE(decoded->rgb.empty());
        for (const std::string& warning : decoded->warnings) std::printf("%s: %s\n", entry.path().c_str(), warning.c_str());
      }
      ++count;
    }
  }
  EXPECT_GT(count, 100);
}

}  // namespace
}  // namespace reconar
