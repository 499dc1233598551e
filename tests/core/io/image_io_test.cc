// ReadImage / ReadImageFromMemory on images made in the test itself: every PNG colour type and
// bit depth, JPEG variants, and damaged or hostile inputs (which must yield a Status, not a crash).
#include "core/io/image_io.h"

#include <gtest/gtest.h>
#include <png.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <random>

#include <jpeglib.h>

#include "tests/core/io/test_images.h"
#include "tests/core/io/test_matchers.h"

namespace reconar {
namespace {

using testing::EncodeJpeg;
using testing::EncodePng;
using testing::JpegSpec;
using testing::PngSpec;

class ImageIoTest : public ::testing::Test {
 protected:
  void SetUp() override {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    dir_ = testing::MakeTempDir(info->name());
  }
  void TearDown() override { std::filesystem::remove_all(dir_); }

  std::string Write(const std::string& name, const std::string& bytes) {
    const std::string path = dir_ + "/" + name;
    testing::WriteBytes(path, bytes);
    return path;
  }

  std::string dir_;
};

int SampleCount(int color_type) {
  switch (color_type) {
    case PNG_COLOR_TYPE_GRAY: return 1;
    case PNG_COLOR_TYPE_GRAY_ALPHA: return 2;
    case PNG_COLOR_TYPE_RGB: return 3;
    case PNG_COLOR_TYPE_RGB_ALPHA: return 4;
    default: return 1;
  }
}

// Maps a sample of the given depth to the 8-bit value the decoder must produce.
uint8_t To8Bit(uint32_t v, int bit_depth) {
  if (bit_depth == 16) return static_cast<uint8_t>((v * 255 + 32767) / 65535);
  const uint32_t max = (1u << bit_depth) - 1;
  return static_cast<uint8_t>(v * 255 / max);  // exact for 1, 2, 4, 8 bits (255 is divisible by max)
}

struct PngCase {
  int color_type;
  int bit_depth;
  bool interlaced;
  bool with_trns;
};

std::string CaseName(const PngCase& c) {
  return "type" + std::to_string(c.color_type) + "_depth" + std::to_string(c.bit_depth) +
         (c.interlaced ? "_adam7" : "") + (c.with_trns ? "_trns" : "");
}

TEST_F(ImageIoTest, ReadsEveryPngColorTypeAndBitDepthExactly) {
  std::vector<PngCase> cases;
  for (int depth : {1, 2, 4, 8, 16}) cases.push_back({PNG_COLOR_TYPE_GRAY, depth, false, false});
  for (int depth : {1, 2, 4, 8}) cases.push_back({PNG_COLOR_TYPE_PALETTE, depth, false, false});
  for (int depth : {8, 16}) {
    cases.push_back({PNG_COLOR_TYPE_GRAY_ALPHA, depth, false, false});
    cases.push_back({PNG_COLOR_TYPE_RGB, depth, false, false});
    cases.push_back({PNG_COLOR_TYPE_RGB_ALPHA, depth, false, false});
  }
  cases.push_back({PNG_COLOR_TYPE_RGB, 8, true, false});
  cases.push_back({PNG_COLOR_TYPE_GRAY, 4, true, false});
  cases.push_back({PNG_COLOR_TYPE_PALETTE, 8, false, true});
  cases.push_back({PNG_COLOR_TYPE_RGB_ALPHA, 16, true, false});

  std::mt19937 rng(42);
  for (const PngCase& c : cases) {
    SCOPED_TRACE(CaseName(c));
    PngSpec spec;
    spec.width = 13;  // odd sizes exercise bit packing and Adam7 passes
    spec.height = 11;
    spec.color_type = c.color_type;
    spec.bit_depth = c.bit_depth;
    spec.interlaced = c.interlaced;
    const int n = SampleCount(c.color_type);
    const uint32_t max_value = (1u << c.bit_depth) - 1;  // also the largest palette index
    if (c.color_type == PNG_COLOR_TYPE_PALETTE) {
      for (uint32_t i = 0; i <= max_value; ++i) {
        spec.palette.push_back({static_cast<uint8_t>(i * 7), static_cast<uint8_t>(255 - i), static_cast<uint8_t>(i * 3 + 1)});
      }
      if (c.with_trns) spec.palette_alpha.assign(spec.palette.size() / 2, 0);
    }
    spec.samples.resize(static_cast<size_t>(spec.width) * spec.height * n);
    for (auto& s : spec.samples) s = static_cast<uint16_t>(rng() % (max_value + 1));
    // Make sure the extremes are present.
    spec.samples[0] = 0;
    spec.samples[1] = static_cast<uint16_t>(max_value);

    const std::string path = Write(CaseName(c) + ".png", EncodePng(spec));
    auto decoded = ReadImage(path);
    ASSERT_TRUE(decoded.ok()) << decoded.status().ToString();
    const Image<uint8_t>& rgb = decoded->rgb;
    ASSERT_EQ(rgb.width(), spec.width);
    ASSERT_EQ(rgb.height(), spec.height);
    ASSERT_EQ(rgb.channels(), 3);
    EXPECT_FALSE(decoded->exif.present);
    for (int y = 0; y < spec.height; ++y) {
      for (int x = 0; x < spec.width; ++x) {
        const uint16_t* s = spec.samples.data() + (static_cast<size_t>(y) * spec.width + x) * n;
        uint8_t expected[3];
        if (c.color_type == PNG_COLOR_TYPE_PALETTE) {
          for (int k = 0; k < 3; ++k) expected[k] = spec.palette[s[0]][k];
        } else if (c.color_type == PNG_COLOR_TYPE_GRAY || c.color_type == PNG_COLOR_TYPE_GRAY_ALPHA) {
          expected[0] = expected[1] = expected[2] = To8Bit(s[0], c.bit_depth);
        } else {
          for (int k = 0; k < 3; ++k) expected[k] = To8Bit(s[k], c.bit_depth);
        }
        const uint8_t* p = rgb.row(y) + 3 * x;
        ASSERT_EQ(p[0], expected[0]) << "x=" << x << " y=" << y;
        ASSERT_EQ(p[1], expected[1]) << "x=" << x << " y=" << y;
        ASSERT_EQ(p[2], expected[2]) << "x=" << x << " y=" << y;
      }
    }
  }
}

JpegSpec PatternJpeg(int width, int height, int components = 3) {
  JpegSpec spec;
  spec.width = width;
  spec.height = height;
  spec.components = components;
  spec.pixels = testing::TestPattern(width, height, components);
  return spec;
}

double MeanAbsDifference(const Image<uint8_t>& rgb, const std::vector<uint8_t>& expected) {
  double sum = 0;
  for (size_t i = 0; i < expected.size(); ++i) sum += std::abs(rgb.data()[i] - expected[i]);
  return sum / static_cast<double>(expected.size());
}

TEST_F(ImageIoTest, DecodesRgbJpegCloseToSource) {
  JpegSpec spec = PatternJpeg(97, 61);  // not multiples of the MCU size
  spec.quality = 100;
  auto decoded = ReadImage(Write("rgb.jpg", EncodeJpeg(spec)));
  ASSERT_TRUE(decoded.ok()) << decoded.status().ToString();
  ASSERT_EQ(decoded->rgb.width(), 97);
  ASSERT_EQ(decoded->rgb.height(), 61);
  EXPECT_EQ(decoded->original_width, 97);
  EXPECT_EQ(decoded->original_height, 61);
  EXPECT_LT(MeanAbsDifference(decoded->rgb, spec.pixels), 2.0);
  EXPECT_TRUE(decoded->warnings.empty());
}

TEST_F(ImageIoTest, TheHeaderGivesTheUprightSizeWithoutDecoding) {
  JpegSpec spec = PatternJpeg(480, 320);
  testing::TiffBuilder tiff(true);
  tiff.Ifd0Short(0x0112, 6);  // rotate 90 degrees clockwise for display
  spec.app1 = tiff.BuildApp1();
  const std::string jpeg = EncodeJpeg(spec);
  auto rotated = ReadImageHeader(Write("header.jpg", jpeg));
  ASSERT_TRUE(rotated.ok()) << rotated.status().ToString();
  EXPECT_EQ(rotated->width, 320);
  EXPECT_EQ(rotated->height, 480);
  EXPECT_EQ(rotated->exif.orientation, 6);
  // A photo cut short after its headers still has its size; one cut inside them does not.
  auto cut = ReadImageHeader(Write("cut.jpg", jpeg.substr(0, jpeg.size() / 2)));
  ASSERT_TRUE(cut.ok()) << cut.status().ToString();
  EXPECT_EQ(cut->width, 320);
  EXPECT_EQ(ReadImageHeader(Write("head.jpg", jpeg.substr(0, 40))).status().code(), StatusCode::kCorruptData);
  PngSpec png{7, 5, PNG_COLOR_TYPE_RGB, 8};
  png.samples.assign(7 * 5 * 3, 90);
  auto png_header = ReadImageHeader(Write("header.png", EncodePng(png)));
  ASSERT_TRUE(png_header.ok()) << png_header.status().ToString();
  EXPECT_EQ(png_header->width, 7);
  EXPECT_EQ(png_header->height, 5);
  EXPECT_EQ(ReadImageHeader(Write("short.png", EncodePng(png).substr(0, 20))).status().code(),
            StatusCode::kCorruptData);
  EXPECT_EQ(ReadImageHeader(Write("present.jpg", jpeg) + ".missing").status().code(), StatusCode::kNotFound);
}

TEST_F(ImageIoTest, DecodesProgressiveAndRestartIntervalJpegs) {
  JpegSpec progressive = PatternJpeg(64, 48);
  progressive.progressive = true;
  JpegSpec restarts = PatternJpeg(64, 48);
  restarts.restart_interval_rows = 1;
  for (const JpegSpec* spec : {&progressive, &restarts}) {
    auto decoded = ReadImageFromMemory(EncodeJpeg(*spec), "memory.jpg");
    ASSERT_TRUE(decoded.ok()) << decoded.status().ToString();
    EXPECT_LT(MeanAbsDifference(decoded->rgb, spec->pixels), 4.0);
  }
}

TEST_F(ImageIoTest, GrayscaleJpegBecomesRgbWithEqualChannels) {
  const JpegSpec spec = PatternJpeg(40, 30, 1);
  auto decoded = ReadImageFromMemory(EncodeJpeg(spec), "gray.jpg");
  ASSERT_TRUE(decoded.ok()) << decoded.status().ToString();
  ASSERT_EQ(decoded->rgb.channels(), 3);
  for (int i = 0; i < 40 * 30; ++i) {
    const uint8_t* p = decoded->rgb.data() + 3 * i;
    ASSERT_EQ(p[0], p[1]);
    ASSERT_EQ(p[1], p[2]);
  }
}

TEST_F(ImageIoTest, MissingFileIsNotFound) {
  const std::string path = dir_ + "/does_not_exist.jpg";
  auto decoded = ReadImage(path);
  ASSERT_FALSE(decoded.ok());
  EXPECT_EQ(decoded.status().code(), StatusCode::kNotFound);
  EXPECT_TRUE(testing::HasSubstring(decoded.status().message(), path));
}

TEST_F(ImageIoTest, EmptyFileIsCorruptData) {
  const std::string path = Write("empty.jpg", "");
  auto decoded = ReadImage(path);
  ASSERT_FALSE(decoded.ok());
  EXPECT_EQ(decoded.status().code(), StatusCode::kCorruptData);
  EXPECT_EQ(decoded.status().message(), path + ": empty file (0 bytes)");
}

TEST_F(ImageIoTest, RandomBytesAreNotAnImage) {
  std::mt19937 rng(7);
  std::string bytes(4096, '\0');
  for (char& b : bytes) b = static_cast<char>(rng());
  bytes[0] = 'x';  // make sure it cannot start with a real signature by chance
  const std::string path = Write("noise.jpg", bytes);
  auto decoded = ReadImage(path);
  ASSERT_FALSE(decoded.ok());
  EXPECT_EQ(decoded.status().code(), StatusCode::kCorruptData);
  EXPECT_TRUE(testing::HasSubstring(decoded.status().message(), path + ": not a JPEG or PNG image"));
}

TEST_F(ImageIoTest, DispatchesOnMagicBytesNotExtension) {
  PngSpec spec{4, 3, PNG_COLOR_TYPE_RGB, 8};
  spec.samples.assign(4 * 3 * 3, 200);
  auto decoded = ReadImage(Write("actually_a_png.jpg", EncodePng(spec)));
  ASSERT_TRUE(decoded.ok()) << decoded.status().ToString();
  EXPECT_EQ(decoded->rgb.width(), 4);
  EXPECT_EQ(DetectImageFormat(EncodeJpeg(PatternJpeg(8, 8))), ImageFormat::kJpeg);
  EXPECT_EQ(DetectImageFormat("GIF89a"), ImageFormat::kUnknown);
}

TEST_F(ImageIoTest, KnownButUnsupportedFormatsSaySo) {
  auto gif = ReadImageFromMemory(std::string("GIF89a\x01\x00\x01\x00", 10), "a.gif");
  ASSERT_FALSE(gif.ok());
  EXPECT_EQ(gif.status().code(), StatusCode::kUnsupported);
  EXPECT_TRUE(testing::HasSubstring(gif.status().message(), "GIF images are not supported"));
  auto heic = ReadImageFromMemory(std::string("\0\0\0\x18" "ftypheic\0\0\0\0", 16), "IMG_0001.HEIC");
  ASSERT_FALSE(heic.ok());
  EXPECT_EQ(heic.status().code(), StatusCode::kUnsupported);
  EXPECT_TRUE(testing::HasSubstring(heic.status().message(), "IMG_0001.HEIC: HEIC/HEIF images are not supported"));
}

TEST_F(ImageIoTest, TruncatedJpegIsReportedWithRowCount) {
  const std::string jpeg = EncodeJpeg(PatternJpeg(256, 256));
  auto decoded = ReadImageFromMemory(jpeg.substr(0, jpeg.size() / 2), "half.jpg");
  ASSERT_FALSE(decoded.ok());
  EXPECT_EQ(decoded.status().code(), StatusCode::kCorruptData);
  EXPECT_TRUE(testing::HasSubstring(decoded.status().message(), "half.jpg: truncated JPEG data (got "));
  EXPECT_TRUE(testing::HasSubstring(decoded.status().message(), " of 256 rows)"));
}

TEST_F(ImageIoTest, TruncatedProgressiveJpegIsReported) {
  JpegSpec spec = PatternJpeg(128, 96);
  spec.progressive = true;
  const std::string jpeg = EncodeJpeg(spec);
  auto decoded = ReadImageFromMemory(jpeg.substr(0, jpeg.size() * 6 / 10), "prog.jpg");
  ASSERT_FALSE(decoded.ok());
  EXPECT_EQ(decoded.status().code(), StatusCode::kCorruptData);
  EXPECT_TRUE(testing::HasSubstring(decoded.status().message(), "prog.jpg: truncated JPEG data (ends in scan "));
}

// Cut exactly between two scans, libjpeg sees a clean (fake) end and warns about nothing;
// the missing refinement bits still give the truncation away.
TEST_F(ImageIoTest, ProgressiveJpegTruncatedBetweenScansIsReported) {
  JpegSpec spec = PatternJpeg(128, 96);
  spec.progressive = true;
  const std::string jpeg = EncodeJpeg(spec);
  const size_t first_sos = jpeg.find("\xFF\xDA");
  const size_t third_sos = jpeg.find("\xFF\xDA", jpeg.find("\xFF\xDA", first_sos + 2) + 2);
  ASSERT_NE(third_sos, std::string::npos);
  auto decoded = ReadImageFromMemory(jpeg.substr(0, third_sos), "scans.jpg");
  ASSERT_FALSE(decoded.ok());
  EXPECT_EQ(decoded.status().code(), StatusCode::kCorruptData);
  EXPECT_TRUE(testing::HasSubstring(decoded.status().message(), "scans.jpg: truncated JPEG data (ends in scan "));
}

TEST_F(ImageIoTest, JpegTruncatedInHeaders) {
  const std::string jpeg = EncodeJpeg(PatternJpeg(32, 32));
  auto decoded = ReadImageFromMemory(jpeg.substr(0, 40), "head.jpg");
  ASSERT_FALSE(decoded.ok());
  EXPECT_EQ(decoded.status().code(), StatusCode::kCorruptData);
  EXPECT_EQ(decoded.status().message(), "head.jpg: truncated JPEG data (ends inside the headers)");
}

TEST_F(ImageIoTest, JpegMissingOnlyTheEoiMarkerStillDecodes) {
  const JpegSpec spec = PatternJpeg(64, 64);
  const std::string jpeg = EncodeJpeg(spec);
  auto decoded = ReadImageFromMemory(jpeg.substr(0, jpeg.size() - 2), "no_eoi.jpg");
  ASSERT_TRUE(decoded.ok()) << decoded.status().ToString();
  EXPECT_LT(MeanAbsDifference(decoded->rgb, spec.pixels), 4.0);
  EXPECT_FALSE(decoded->warnings.empty());
}

// Every prefix length and many single-byte corruptions: the decoder must return (ok or an
// error Status), never crash or read out of bounds (run under ASan/UBSan in CI).
TEST_F(ImageIoTest, DamagedJpegsNeverCrash) {
  JpegSpec spec = PatternJpeg(48, 40);
  spec.app1 = [] {
    testing::TiffBuilder tiff(false);
    tiff.Ifd0Ascii(0x010F, "Maker");
    tiff.Ifd0Short(0x0112, 6);
    tiff.ExifRational(0x920A, 50, 10);
    return tiff.BuildApp1();
  }();
  for (bool progressive : {false, true}) {
    spec.progressive = progressive;
    const std::string jpeg = EncodeJpeg(spec);
    for (size_t length = 1; length < jpeg.size(); length += 7) {
      auto decoded = ReadImageFromMemory(jpeg.substr(0, length), "cut.jpg");
      if (!decoded.ok()) {
        EXPECT_EQ(decoded.status().code(), StatusCode::kCorruptData) << decoded.status().ToString();
      }
    }
    std::mt19937 rng(progressive ? 3 : 4);
    int failures = 0;
    for (int trial = 0; trial < 400; ++trial) {
      std::string damaged = jpeg;
      damaged[rng() % damaged.size()] ^= static_cast<char>(1 + rng() % 255);
      auto decoded = ReadImageFromMemory(damaged, "flip.jpg");
      if (!decoded.ok()) {
        ++failures;
        EXPECT_TRUE(testing::HasSubstring(decoded.status().message(), "flip.jpg: "));
      }
    }
    EXPECT_GT(failures, 0);
  }
}

TEST_F(ImageIoTest, DamagedPngsNeverCrash) {
  PngSpec spec{31, 17, PNG_COLOR_TYPE_RGB_ALPHA, 16, true};
  spec.samples.assign(31 * 17 * 4, 0);
  for (size_t i = 0; i < spec.samples.size(); ++i) spec.samples[i] = static_cast<uint16_t>(i * 2654435761u);
  const std::string png = EncodePng(spec);
  constexpr size_t kIendChunkSize = 12;  // pixels are complete without it; we do not insist on it
  for (size_t length = 1; length < png.size(); length += 5) {
    auto decoded = ReadImageFromMemory(png.substr(0, length), "cut.png");
    if (length < png.size() - kIendChunkSize) {
      ASSERT_FALSE(decoded.ok()) << "length " << length;
    }
    if (!decoded.ok()) {
      EXPECT_EQ(decoded.status().code(), StatusCode::kCorruptData);
    }
  }
  std::mt19937 rng(11);
  for (int trial = 0; trial < 400; ++trial) {
    std::string damaged = png;
    damaged[8 + rng() % (damaged.size() - 8)] ^= static_cast<char>(1 + rng() % 255);
    auto decoded = ReadImageFromMemory(damaged, "flip.png");
    if (!decoded.ok()) {
      EXPECT_TRUE(testing::HasSubstring(decoded.status().message(), "flip.png: "));
    }
  }
}

TEST_F(ImageIoTest, TruncatedPngIsCorruptData) {
  PngSpec spec{64, 64, PNG_COLOR_TYPE_RGB, 8};
  spec.samples.resize(64 * 64 * 3);
  std::mt19937 rng(5);
  for (auto& s : spec.samples) s = static_cast<uint16_t>(rng() % 256);  // incompressible
  const std::string png = EncodePng(spec);
  const std::string path = Write("half.png", png.substr(0, png.size() / 2));
  auto decoded = ReadImage(path);
  ASSERT_FALSE(decoded.ok());
  EXPECT_EQ(decoded.status().code(), StatusCode::kCorruptData);
  EXPECT_EQ(decoded.status().message(), path + ": truncated PNG data");
}

TEST_F(ImageIoTest, CmykAndYcckJpegsAreUnsupported) {
  JpegSpec cmyk = PatternJpeg(16, 16, 4);
  JpegSpec ycck = cmyk;
  ycck.jpeg_color_space = JCS_YCCK;
  for (const JpegSpec* spec : {&cmyk, &ycck}) {
    const std::string path = Write("cmyk.jpg", EncodeJpeg(*spec));
    auto decoded = ReadImage(path);
    ASSERT_FALSE(decoded.ok());
    EXPECT_EQ(decoded.status().code(), StatusCode::kUnsupported);
    EXPECT_EQ(decoded.status().message(), path + ": CMYK JPEG is not supported; convert to RGB");
  }
}

TEST_F(ImageIoTest, PngHeaderClaimingHugeSizeIsRefusedBeforeAllocating) {
  PngSpec spec{100000, 100000, PNG_COLOR_TYPE_RGB, 8};
  const std::string path = Write("huge.png", EncodePng(spec, /*header_only=*/true));
  auto decoded = ReadImage(path);
  ASSERT_FALSE(decoded.ok());
  EXPECT_EQ(decoded.status().code(), StatusCode::kResourceExhausted);
  EXPECT_EQ(decoded.status().message(),
            path + ": image is 100000x100000 = 10000000000 pixels, above the limit of 100000000");
}

// Rewrites the frame size in the SOF0 segment of a baseline JPEG.
std::string PatchJpegSize(std::string jpeg, int width, int height) {
  const size_t sof = jpeg.find("\xFF\xC0");
  EXPECT_NE(sof, std::string::npos);
  jpeg[sof + 5] = static_cast<char>(height >> 8);
  jpeg[sof + 6] = static_cast<char>(height & 0xFF);
  jpeg[sof + 7] = static_cast<char>(width >> 8);
  jpeg[sof + 8] = static_cast<char>(width & 0xFF);
  return jpeg;
}

TEST_F(ImageIoTest, JpegHeaderClaimingHugeSizeIsRefused) {
  const std::string jpeg = PatchJpegSize(EncodeJpeg(PatternJpeg(16, 16)), 65000, 65000);
  auto decoded = ReadImageFromMemory(jpeg, "huge.jpg");
  ASSERT_FALSE(decoded.ok());
  EXPECT_EQ(decoded.status().code(), StatusCode::kResourceExhausted);
  EXPECT_TRUE(testing::HasSubstring(decoded.status().message(), "huge.jpg: image is 65000x65000"));
}

TEST_F(ImageIoTest, JpegWithZeroHeightIsCorrupt) {
  const std::string jpeg = PatchJpegSize(EncodeJpeg(PatternJpeg(16, 16)), 16, 0);
  auto decoded = ReadImageFromMemory(jpeg, "zero.jpg");
  ASSERT_FALSE(decoded.ok());
  EXPECT_EQ(decoded.status().code(), StatusCode::kCorruptData);
  EXPECT_TRUE(testing::HasSubstring(decoded.status().message(), "zero.jpg: "));
}

TEST_F(ImageIoTest, MaxPixelsOptionIsHonoured) {
  const std::string jpeg = EncodeJpeg(PatternJpeg(40, 30));
  ImageReadOptions options;
  options.max_pixels = 40 * 30 - 1;
  auto refused = ReadImageFromMemory(jpeg, "small.jpg", options);
  ASSERT_FALSE(refused.ok());
  EXPECT_EQ(refused.status().code(), StatusCode::kResourceExhausted);
  options.max_pixels = 40 * 30;
  EXPECT_TRUE(ReadImageFromMemory(jpeg, "small.jpg", options).ok());
  options.max_pixels = 0;
  auto invalid = ReadImageFromMemory(jpeg, "small.jpg", options);
  ASSERT_FALSE(invalid.ok());
  EXPECT_EQ(invalid.status().code(), StatusCode::kInvalidArgument);
}

TEST_F(ImageIoTest, ExifOrientationIsAppliedUnlessDisabled) {
  JpegSpec spec = PatternJpeg(48, 32);
  spec.quality = 100;
  testing::TiffBuilder tiff(true);
  tiff.Ifd0Ascii(0x010F, "Apple");
  tiff.Ifd0Ascii(0x0110, "iPhone 12");
  tiff.Ifd0Short(0x0112, 6);  // rotate 90° clockwise for display
  spec.app1 = tiff.BuildApp1();
  const std::string jpeg = EncodeJpeg(spec);

  auto upright = ReadImageFromMemory(jpeg, "rotated.jpg");
  ASSERT_TRUE(upright.ok()) << upright.status().ToString();
  EXPECT_TRUE(upright->exif.present);
  EXPECT_EQ(upright->exif.make, "Apple");
  EXPECT_EQ(upright->exif.orientation, 6);
  EXPECT_EQ(upright->rgb.width(), 32);
  EXPECT_EQ(upright->rgb.height(), 48);
  EXPECT_EQ(upright->original_width, 48);
  EXPECT_EQ(upright->original_height, 32);

  ImageReadOptions options;
  options.apply_exif_orientation = false;
  auto stored = ReadImageFromMemory(jpeg, "rotated.jpg", options);
  ASSERT_TRUE(stored.ok());
  EXPECT_EQ(stored->rgb.width(), 48);
  EXPECT_EQ(stored->rgb.height(), 32);
  // Upright top-right pixel is stored top-left (orientation 6: stored row 0 is the visual right).
  for (int k = 0; k < 3; ++k) EXPECT_EQ(upright->rgb.row(0)[3 * 31 + k], stored->rgb.row(0)[k]);
}

TEST_F(ImageIoTest, PngExifChunkIsReadAndApplied) {
  PngSpec spec{3, 2, PNG_COLOR_TYPE_GRAY, 8};
  spec.samples = {1, 2, 3, 4, 5, 6};
  testing::TiffBuilder tiff(false);
  tiff.Ifd0Ascii(0x010F, "PngMaker");
  tiff.Ifd0Short(0x0112, 3);  // rotated 180°
  spec.exif = tiff.Build();
  auto decoded = ReadImageFromMemory(EncodePng(spec), "exif.png");
  ASSERT_TRUE(decoded.ok()) << decoded.status().ToString();
  EXPECT_TRUE(decoded->exif.present);
  EXPECT_EQ(decoded->exif.make, "PngMaker");
  EXPECT_EQ(decoded->exif.orientation, 3);
  EXPECT_EQ(decoded->rgb.row(0)[0], 6);
  EXPECT_EQ(decoded->rgb.row(1)[3 * 2], 1);
}

}  // namespace
}  // namespace reconar
