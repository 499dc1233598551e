#include "core/io/exif.h"

#include <gtest/gtest.h>

#include <random>

#include "core/io/image_io.h"
#include "tests/core/io/test_images.h"
#include "tests/core/io/test_matchers.h"

namespace reconar {
namespace {

using testing::TiffBuilder;

constexpr uint16_t kMake = 0x010F;
constexpr uint16_t kModel = 0x0110;
constexpr uint16_t kOrientation = 0x0112;
constexpr uint16_t kFocalLength = 0x920A;
constexpr uint16_t kFocal35 = 0xA405;
constexpr uint16_t kPixelX = 0xA002;
constexpr uint16_t kPixelY = 0xA003;
constexpr uint16_t kPlaneX = 0xA20E;
constexpr uint16_t kPlaneY = 0xA20F;
constexpr uint16_t kPlaneUnit = 0xA210;

TiffBuilder FullBlock(bool big_endian) {
  TiffBuilder tiff(big_endian);
  tiff.Ifd0Ascii(kMake, "Canon");
  tiff.Ifd0Ascii(kModel, "Canon EOS 80D");
  tiff.Ifd0Short(kOrientation, 8);
  tiff.ExifRational(kFocalLength, 37, 2);
  tiff.ExifShort(kFocal35, 29);
  tiff.ExifShort(kPixelX, 6000);
  tiff.ExifLong(kPixelY, 4000);
  tiff.ExifRational(kPlaneX, 6000000, 2234);
  tiff.ExifRational(kPlaneY, 4000000, 1489);
  tiff.ExifShort(kPlaneUnit, 3);
  return tiff;
}

void ExpectFullBlock(const ExifInfo& info) {
  EXPECT_TRUE(info.present);
  EXPECT_EQ(info.warning, "");
  EXPECT_EQ(info.make, "Canon");
  EXPECT_EQ(info.model, "Canon EOS 80D");
  EXPECT_EQ(info.orientation, 8);
  EXPECT_DOUBLE_EQ(info.focal_length_mm, 18.5);
  EXPECT_DOUBLE_EQ(info.focal_length_35mm, 29);
  EXPECT_EQ(info.pixel_x_dimension, 6000);
  EXPECT_EQ(info.pixel_y_dimension, 4000);
  EXPECT_DOUBLE_EQ(info.focal_plane_x_resolution, 6000000.0 / 2234);
  EXPECT_DOUBLE_EQ(info.focal_plane_y_resolution, 4000000.0 / 1489);
  EXPECT_EQ(info.focal_plane_resolution_unit, 3);
}

TEST(ExifTest, ParsesLittleEndianBlock) {
  ExpectFullBlock(ParseExifTiff(FullBlock(false).Build()));
  EXPECT_EQ(FullBlock(false).Build().substr(0, 4), std::string("II*\0", 4));
}

TEST(ExifTest, ParsesBigEndianBlock) {
  ExpectFullBlock(ParseExifTiff(FullBlock(true).Build()));
  EXPECT_EQ(FullBlock(true).Build().substr(0, 4), std::string("MM\0*", 4));
}

TEST(ExifTest, ParsesApp1PayloadAndJpegMarkers) {
  for (bool big_endian : {false, true}) {
    SCOPED_TRACE(big_endian ? "MM" : "II");
    const std::string app1 = FullBlock(big_endian).BuildApp1();
    ExpectFullBlock(ParseExifApp1(app1));

    testing::JpegSpec spec;
    spec.width = 24;
    spec.height = 16;
    spec.pixels = testing::TestPattern(24, 16, 3);
    spec.app1 = app1;
    const std::string jpeg = testing::EncodeJpeg(spec);
    ExpectFullBlock(ReadExifFromJpeg(jpeg));

    auto decoded = ReadImageFromMemory(jpeg, "exif.jpg");
    ASSERT_TRUE(decoded.ok()) << decoded.status().ToString();
    ExpectFullBlock(decoded->exif);
    EXPECT_EQ(decoded->rgb.width(), 16);  // orientation 8 swaps the axes
    EXPECT_EQ(decoded->rgb.height(), 24);
  }
}

TEST(ExifTest, JpegWithoutExifHasNoExifAndNoWarning) {
  testing::JpegSpec spec;
  spec.width = 8;
  spec.height = 8;
  spec.pixels = testing::TestPattern(8, 8, 3);
  const ExifInfo info = ReadExifFromJpeg(testing::EncodeJpeg(spec));
  EXPECT_FALSE(info.present);
  EXPECT_EQ(info.warning, "");
  EXPECT_EQ(info.orientation, 1);
}

TEST(ExifTest, RejectsNonExifApp1AndBadHeaders) {
  EXPECT_FALSE(ParseExifApp1("http://ns.adobe.com/xap/1.0/").present);
  EXPECT_FALSE(ParseExifTiff("").present);
  EXPECT_FALSE(ParseExifTiff(std::string("XX*\0\x08\0\0\0", 8)).present);
  const ExifInfo bad_magic = ParseExifTiff(std::string("II+\0\x08\0\0\0", 8));
  EXPECT_FALSE(bad_magic.present);
  EXPECT_TRUE(testing::HasSubstring(bad_magic.warning, "bad TIFF header"));
}

// Offsets of fields in a block built by TiffBuilder with IFD0 entries [Make, Orientation].
std::string SmallLittleEndianBlock() {
  TiffBuilder tiff(false);
  tiff.Ifd0Ascii(kMake, "SomeMaker");
  tiff.Ifd0Short(kOrientation, 3);
  tiff.ExifRational(kFocalLength, 50, 1);
  return tiff.Build();
}

void PutU32(std::string* block, size_t at, uint32_t v) {
  for (int i = 0; i < 4; ++i) (*block)[at + i] = static_cast<char>(v >> (8 * i));
}

TEST(ExifTest, Ifd0OffsetOutOfBoundsMeansNoExif) {
  std::string block = SmallLittleEndianBlock();
  PutU32(&block, 4, 0xFFFFFFF0u);
  const ExifInfo info = ParseExifTiff(block);
  EXPECT_FALSE(info.present);
  EXPECT_TRUE(testing::HasSubstring(info.warning, "IFD0 offset 4294967280 is outside the"));
}

TEST(ExifTest, ExifIfdPointerOutOfBoundsKeepsIfd0Fields) {
  std::string block = SmallLittleEndianBlock();
  // IFD0 at 8: count(2) + entries Make, Orientation, ExifIFD pointer; the pointer's value is the
  // last 4 bytes of the third entry.
  PutU32(&block, 8 + 2 + 12 * 2 + 8, static_cast<uint32_t>(block.size() + 100));
  const ExifInfo info = ParseExifTiff(block);
  EXPECT_TRUE(info.present);
  EXPECT_EQ(info.make, "SomeMaker");
  EXPECT_EQ(info.orientation, 3);
  EXPECT_EQ(info.focal_length_mm, 0);
  EXPECT_TRUE(testing::HasSubstring(info.warning, "ExifIFD offset"));
}

TEST(ExifTest, StringValueOutOfBoundsIsSkipped) {
  std::string block = SmallLittleEndianBlock();
  PutU32(&block, 8 + 2 + 8, 0x7FFFFFFF);  // Make's value offset
  const ExifInfo info = ParseExifTiff(block);
  EXPECT_TRUE(info.present);
  EXPECT_EQ(info.make, "");
  EXPECT_EQ(info.orientation, 3);
  EXPECT_DOUBLE_EQ(info.focal_length_mm, 50);
  EXPECT_TRUE(testing::HasSubstring(info.warning, "IFD0 tag 0x010F points outside the EXIF block"));
}

TEST(ExifTest, HugeEntryCountAndHugeValueCountAreBounded) {
  std::string block = SmallLittleEndianBlock();
  block[8] = '\xFF';
  block[9] = '\xFF';  // 65535 entries claimed
  ExifInfo info = ParseExifTiff(block);
  EXPECT_TRUE(info.present);
  EXPECT_TRUE(testing::HasSubstring(info.warning, "IFD0 claims 65535 entries"));

  block = SmallLittleEndianBlock();
  PutU32(&block, 8 + 2 + 4, 0xFFFFFFFFu);  // Make's count: 4 GB of ASCII
  info = ParseExifTiff(block);
  EXPECT_TRUE(info.present);
  EXPECT_EQ(info.make, "");
  EXPECT_EQ(info.orientation, 3);
}

TEST(ExifTest, ZeroDenominatorAndBadOrientationAreIgnored) {
  TiffBuilder tiff(true);
  tiff.Ifd0Short(kOrientation, 9);
  tiff.ExifRational(kFocalLength, 50, 0);
  const ExifInfo info = ParseExifTiff(tiff.Build());
  EXPECT_TRUE(info.present);
  EXPECT_EQ(info.orientation, 1);
  EXPECT_EQ(info.focal_length_mm, 0);
  EXPECT_TRUE(testing::HasSubstring(info.warning, "invalid Orientation 9"));
  EXPECT_TRUE(testing::HasSubstring(info.warning, "unreadable FocalLength"));
}

TEST(ExifTest, ExifIfdPointingAtItselfTerminates) {
  std::string block = SmallLittleEndianBlock();
  PutU32(&block, 8 + 2 + 12 * 2 + 8, 8);  // ExifIFD = IFD0
  const ExifInfo info = ParseExifTiff(block);
  EXPECT_TRUE(info.present);
  EXPECT_EQ(info.make, "SomeMaker");
}

TEST(ExifTest, JpegSegmentLengthPastEndIsAWarning) {
  const std::string jpeg("\xFF\xD8\xFF\xE1\x40\x00" "Exif\0\0II", 14);
  const ExifInfo info = ReadExifFromJpeg(jpeg);
  EXPECT_FALSE(info.present);
  EXPECT_TRUE(testing::HasSubstring(info.warning, "runs past the end"));
}

// Every truncation and thousands of random corruptions of valid blocks, in both byte orders:
// no crash, no out-of-bounds read (ASan), and orientation always stays in 1..8.
TEST(ExifTest, FuzzedBlocksNeverCrash) {
  std::mt19937 rng(1234);
  for (bool big_endian : {false, true}) {
    const std::string block = FullBlock(big_endian).Build();
    for (size_t length = 0; length <= block.size(); ++length) {
      const ExifInfo info = ParseExifTiff(block.substr(0, length));
      EXPECT_GE(info.orientation, 1);
      EXPECT_LE(info.orientation, 8);
    }
    for (int trial = 0; trial < 5000; ++trial) {
      std::string damaged = block;
      const int flips = 1 + static_cast<int>(rng() % 4);
      for (int f = 0; f < flips; ++f) damaged[rng() % damaged.size()] = static_cast<char>(rng());
      const ExifInfo info = ParseExifTiff(damaged);
      EXPECT_GE(info.orientation, 1);
      EXPECT_LE(info.orientation, 8);
      if (!info.present) {
        EXPECT_EQ(info.make, "");
      }
      const std::string app1 = std::string("Exif\0\0", 6) + damaged;
      (void)ReadExifFromJpeg(std::string("\xFF\xD8\xFF\xE1", 4) + static_cast<char>((app1.size() + 2) >> 8) +
                             static_cast<char>((app1.size() + 2) & 0xFF) + app1);
    }
  }
}

}  // namespace
}  // namespace reconar
