// WriteJpeg / EncodeJpeg with the EXIF a capture writes (BuildExifApp1, ExifForFocal): the pixels
// read back within JPEG's loss, every EXIF field reads back through the project's own reader (and
// the focal prior from it), and failed writes name the path and leave no file.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <string>

#include "core/base/atomic_file.h"
#include "core/io/exif.h"
#include "core/io/focal_prior.h"
#include "core/io/image_io.h"
#include "core/io/image_write.h"
#include "tests/core/io/test_images.h"

namespace reconar {
namespace {

namespace fs = std::filesystem;

Image<uint8_t> TemplePhoto() {
  auto photo = ReadImage(std::string(RECONAR_SOURCE_DIR) + "/data/templeSparseRing/templeSR0001.png");
  EXPECT_TRUE(photo.ok()) << photo.status().ToString();
  return std::move(photo->rgb);
}

double MeanAbsoluteDifference(const Image<uint8_t>& a, const Image<uint8_t>& b) {
  double sum = 0.0;
  for (int y = 0; y < a.height(); ++y)
    for (int x = 0; x < a.width() * a.channels(); ++x) sum += std::abs(a.row(y)[x] - b.row(y)[x]);
  return sum / (static_cast<double>(a.width()) * a.channels() * a.height());
}

TEST(JpegWriteTest, APhotoReadsBackWithinTheLossOfQuality95) {
  const Image<uint8_t> photo = TemplePhoto();
  const std::string dir = testing::MakeTempDir("jpeg_write_photo");
  const std::string path = dir + "/photo.jpg";
  ASSERT_TRUE(WriteJpeg(path, photo.view(), 3, 95).ok());
  auto back = ReadImage(path);
  ASSERT_TRUE(back.ok()) << back.status().ToString();
  ASSERT_EQ(back->rgb.width(), photo.width());
  ASSERT_EQ(back->rgb.height(), photo.height());
  const double error = MeanAbsoluteDifference(back->rgb, photo);
  std::printf("mean absolute difference %.3f grey levels\n", error);
  EXPECT_LT(error, 2.0);
  EXPECT_FALSE(back->exif.present);
  fs::remove_all(dir);
}

TEST(JpegWriteTest, TheCaptureExifReadsBackWithItsFocal) {
  const double focal_px = 1520.4;
  const ExifInfo written = ExifForFocal(640, 480, focal_px, "test camera");
  const Image<uint8_t> photo = TemplePhoto();
  auto bytes = EncodeJpeg(photo.view(), 3, 90, BuildExifApp1(written));
  ASSERT_TRUE(bytes.ok()) << bytes.status().ToString();
  const ExifInfo read = ReadExifFromJpeg(*bytes);
  ASSERT_TRUE(read.present) << read.warning;
  EXPECT_TRUE(read.warning.empty()) << read.warning;
  EXPECT_EQ(read.make, "reconar");
  EXPECT_EQ(read.model, "test camera");
  EXPECT_EQ(read.orientation, 1);
  EXPECT_NEAR(read.focal_length_mm, focal_px * 36.0 / 640.0, 1e-4);
  EXPECT_EQ(read.focal_length_35mm, std::round(focal_px * 36.0 / 640.0));
  EXPECT_EQ(read.focal_plane_resolution_unit, 3);
  EXPECT_EQ(read.pixel_x_dimension, 640);
  EXPECT_EQ(read.pixel_y_dimension, 480);
  // The focal in pixels from FocalLength and the focal-plane resolution (pixels per cm).
  EXPECT_NEAR(read.focal_length_mm * read.focal_plane_x_resolution / 10.0, focal_px, 0.01);
  // The prior the mapper takes: from the 35 mm equivalent, within its whole-millimetre rounding.
  const FocalPrior prior = EstimateFocalPrior(read, 640, 480);
  EXPECT_EQ(prior.source, FocalPrior::Source::kExif35mm);
  EXPECT_NEAR(prior.focal_px, focal_px, 0.5 / 36.0 * 640.0);
}

TEST(JpegWriteTest, OrientationIsWrittenAndApplied) {
  ExifInfo exif = ExifForFocal(640, 480, 600.0, "");
  exif.orientation = 6;
  const Image<uint8_t> photo = TemplePhoto();
  const std::string dir = testing::MakeTempDir("jpeg_write_orientation");
  ASSERT_TRUE(WriteJpeg(dir + "/turned.jpg", photo.view(), 3, 90, BuildExifApp1(exif)).ok());
  auto back = ReadImage(dir + "/turned.jpg");
  ASSERT_TRUE(back.ok()) << back.status().ToString();
  EXPECT_EQ(back->exif.orientation, 6);
  EXPECT_EQ(back->exif.model, "");
  EXPECT_EQ(back->rgb.width(), 480);  // read upright: turned a quarter
  EXPECT_EQ(back->rgb.height(), 640);
  fs::remove_all(dir);
}

TEST(JpegWriteTest, GrayFramesAndBadArguments) {
  Image<uint8_t> gray(64, 48);
  for (int y = 0; y < 48; ++y)
    for (int x = 0; x < 64; ++x) gray.row(y)[x] = static_cast<uint8_t>(4 * x);
  auto bytes = EncodeJpeg(gray.view(), 1, 90);
  ASSERT_TRUE(bytes.ok()) << bytes.status().ToString();
  EXPECT_EQ(static_cast<unsigned char>((*bytes)[0]), 0xFF);
  EXPECT_EQ(static_cast<unsigned char>((*bytes)[1]), 0xD8);
  EXPECT_FALSE(EncodeJpeg(gray.view(), 2, 90).ok());
  EXPECT_FALSE(EncodeJpeg(gray.view(), 1, 0).ok());
  EXPECT_FALSE(EncodeJpeg(ImageView<const uint8_t>(), 1, 90).ok());
  EXPECT_FALSE(EncodeJpeg(gray.view(), 1, 90, std::string(70000, 'x')).ok());
}

TEST(JpegWriteTest, AFailedWriteNamesThePathAndLeavesNoFile) {
  Image<uint8_t> gray(16, 16);
  const std::string path = "/nonexistent_reconar_dir/frame.jpg";
  const Status status = WriteJpeg(path, gray.view(), 1, 90);
  ASSERT_FALSE(status.ok());
  EXPECT_NE(status.message().find(path), std::string::npos) << status.message();
  EXPECT_FALSE(fs::exists(path));
}

}  // namespace
}  // namespace reconar
