// WritePng: what it writes reads back identically through ReadImage (and, for the alpha channel
// ReadImage drops, through libpng's own reader); failed writes name the path and leave no file.
#include "core/io/image_write.h"

#include <gtest/gtest.h>
#include <png.h>
#include <signal.h>
#include <sys/resource.h>

#include <algorithm>
#include <filesystem>
#include <string>
#include <vector>

#include "core/io/image_io.h"
#include "tests/core/io/test_images.h"

namespace reconar {
namespace {

namespace fs = std::filesystem;

class ImageWriteTest : public ::testing::Test {
 protected:
  void SetUp() override {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    dir_ = testing::MakeTempDir(std::string("image_write_") + info->name());
  }
  void TearDown() override { fs::remove_all(dir_); }

  size_t FileCount() const { return static_cast<size_t>(std::distance(fs::directory_iterator(dir_), {})); }

  std::string dir_;
};

// Reads a PNG as raw RGBA with libpng's simplified API (independent of ReadImage).
std::vector<uint8_t> ReadRgbaWithLibpng(const std::string& path, int* width, int* height) {
  png_image image{};
  image.version = PNG_IMAGE_VERSION;
  if (png_image_begin_read_from_file(&image, path.c_str()) == 0) return {};
  image.format = PNG_FORMAT_RGBA;
  std::vector<uint8_t> pixels(PNG_IMAGE_SIZE(image));
  if (png_image_finish_read(&image, nullptr, pixels.data(), 0, nullptr) == 0) return {};
  *width = static_cast<int>(image.width);
  *height = static_cast<int>(image.height);
  return pixels;
}

TEST_F(ImageWriteTest, RgbRoundTripThroughReadImage) {
  const int width = 37, height = 23;
  Image<uint8_t> image(width, height, 3);
  const std::vector<uint8_t> pattern = testing::TestPattern(width, height, 3);
  std::copy(pattern.begin(), pattern.end(), image.data());
  const std::string path = dir_ + "/rgb.png";
  ASSERT_TRUE(WritePng(path, image.view(), 3).ok());

  const Result<DecodedImage> decoded = ReadImage(path);
  ASSERT_TRUE(decoded.ok()) << decoded.status().ToString();
  ASSERT_EQ(decoded->rgb.width(), width);
  ASSERT_EQ(decoded->rgb.height(), height);
  ASSERT_EQ(decoded->rgb.channels(), 3);
  EXPECT_TRUE(std::equal(pattern.begin(), pattern.end(), decoded->rgb.data()));
  EXPECT_EQ(FileCount(), 1u);  // no temporary left behind
}

TEST_F(ImageWriteTest, GrayAndStridedSubView) {
  // A 20x10 window inside a 50-sample-wide buffer: the stride must be honoured.
  const int buffer_width = 50, buffer_height = 16;
  std::vector<uint8_t> buffer(static_cast<size_t>(buffer_width) * buffer_height);
  for (size_t i = 0; i < buffer.size(); ++i) buffer[i] = static_cast<uint8_t>((i * 37) % 251);
  const ImageView<const uint8_t> full(buffer_width, buffer_height, buffer_width, buffer.data());
  const ImageView<const uint8_t> window = full.sub(7, 3, 20, 10);
  const std::string path = dir_ + "/gray.png";
  ASSERT_TRUE(WritePng(path, window, 1).ok());

  const Result<DecodedImage> decoded = ReadImage(path);
  ASSERT_TRUE(decoded.ok()) << decoded.status().ToString();
  ASSERT_EQ(decoded->rgb.width(), 20);
  ASSERT_EQ(decoded->rgb.height(), 10);
  for (int y = 0; y < 10; ++y) {
    for (int x = 0; x < 20; ++x) {
      for (int c = 0; c < 3; ++c) {
        ASSERT_EQ(decoded->rgb.row(y)[3 * x + c], window.at(x, y)) << x << "," << y;
      }
    }
  }
}

TEST_F(ImageWriteTest, RgbaKeepsAlpha) {
  const int width = 16, height = 9;
  Image<uint8_t> image(width, height, 4);
  const std::vector<uint8_t> pattern = testing::TestPattern(width, height, 4);
  std::copy(pattern.begin(), pattern.end(), image.data());
  const std::string path = dir_ + "/rgba.png";
  ASSERT_TRUE(WritePng(path, image.view(), 4).ok());

  int read_width = 0, read_height = 0;
  const std::vector<uint8_t> rgba = ReadRgbaWithLibpng(path, &read_width, &read_height);
  ASSERT_EQ(read_width, width);
  ASSERT_EQ(read_height, height);
  EXPECT_EQ(rgba, pattern);

  const Result<DecodedImage> decoded = ReadImage(path);  // RGB part through our own decoder
  ASSERT_TRUE(decoded.ok()) << decoded.status().ToString();
  for (int i = 0; i < width * height; ++i) {
    for (int c = 0; c < 3; ++c) ASSERT_EQ(decoded->rgb.data()[3 * i + c], pattern[4 * i + c]);
  }
}

TEST_F(ImageWriteTest, UnwritablePathIsIoErrorNamingThePath) {
  Image<uint8_t> image(4, 4, 3);
  const std::string path = dir_ + "/missing_directory/out.png";
  const Status status = WritePng(path, image.view(), 3);
  ASSERT_FALSE(status.ok());
  EXPECT_EQ(status.code(), StatusCode::kIoError);
  EXPECT_NE(status.message().find(path), std::string::npos) << status.message();
  EXPECT_FALSE(fs::exists(dir_ + "/missing_directory"));
  EXPECT_EQ(FileCount(), 0u);
}

TEST_F(ImageWriteTest, FullDiskLeavesPreviousFileAndNoTemporary) {
  // RLIMIT_FSIZE makes write() fail with EFBIG as a full disk would (SIGXFSZ ignored meanwhile).
  const std::string path = dir_ + "/big.png";
  Image<uint8_t> small(2, 2, 3);
  ASSERT_TRUE(WritePng(path, small.view(), 3).ok());
  const auto previous_size = fs::file_size(path);

  const int width = 512, height = 512;
  Image<uint8_t> noisy(width, height, 3);
  uint32_t state = 12345;
  for (size_t i = 0; i < noisy.size_bytes(); ++i) {
    state = state * 1664525u + 1013904223u;
    noisy.data()[i] = static_cast<uint8_t>(state >> 24);  // incompressible: ~768 KB of PNG
  }
  struct sigaction ignore {}, previous {};
  ignore.sa_handler = SIG_IGN;
  sigaction(SIGXFSZ, &ignore, &previous);
  rlimit old_limit{};
  getrlimit(RLIMIT_FSIZE, &old_limit);
  rlimit limited = old_limit;
  limited.rlim_cur = 64 * 1024;
  ASSERT_EQ(setrlimit(RLIMIT_FSIZE, &limited), 0);
  const Status status = WritePng(path, noisy.view(), 3);
  setrlimit(RLIMIT_FSIZE, &old_limit);
  sigaction(SIGXFSZ, &previous, nullptr);

  ASSERT_FALSE(status.ok());
  EXPECT_EQ(status.code(), StatusCode::kIoError);
  EXPECT_NE(status.message().find(path), std::string::npos) << status.message();
  EXPECT_EQ(fs::file_size(path), previous_size);
  EXPECT_EQ(FileCount(), 1u);
}

TEST(EncodePngTest, RejectsBadArguments) {
  std::vector<uint8_t> pixels(30);
  const ImageView<const uint8_t> view(10, 3, 10, pixels.data());
  EXPECT_EQ(EncodePng(view, 2).status().code(), StatusCode::kInvalidArgument);
  EXPECT_EQ(EncodePng(view, 3).status().code(), StatusCode::kInvalidArgument);  // 10 % 3 != 0
  EXPECT_EQ(EncodePng(ImageView<const uint8_t>(), 1).status().code(), StatusCode::kInvalidArgument);
  EXPECT_TRUE(EncodePng(view, 1).ok());
  EXPECT_EQ(EncodePng(view, 1, 10).status().code(), StatusCode::kInvalidArgument);
  EXPECT_EQ(EncodePng(view, 1, -1).status().code(), StatusCode::kInvalidArgument);
  EXPECT_EQ(WritePng("/tmp/never_written.png", view, 3).code(), StatusCode::kInvalidArgument);
}


// Every compression level is lossless; the fast one only costs bytes.
TEST(EncodePngTest, EveryLevelDecodesToTheSamePixels) {
  Image<uint8_t> image(64, 48, 3);
  for (int y = 0; y < image.height(); ++y) {
    for (int x = 0; x < 3 * image.width(); ++x) image.row(y)[x] = static_cast<uint8_t>((x * 37 + y * 11) ^ (x * y));
  }
  for (const int level : {0, kPngFastCompression, kPngDefaultCompression, 9}) {
    const Result<std::string> png = EncodePng(image.view(), 3, level);
    ASSERT_TRUE(png.ok()) << level;
    const Result<DecodedImage> decoded = ReadImageFromMemory(*png, "level " + std::to_string(level));
    ASSERT_TRUE(decoded.ok()) << decoded.status().ToString();
    for (int y = 0; y < image.height(); ++y) {
      ASSERT_TRUE(std::equal(image.row(y), image.row(y) + 3 * image.width(), decoded->rgb.row(y))) << level;
    }
  }
}

}  // namespace
}  // namespace reconar
