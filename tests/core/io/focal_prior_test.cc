#include "core/io/focal_prior.h"

#include <gtest/gtest.h>

#include <string>

#include "tests/core/io/test_matchers.h"

namespace reconar {
namespace {


ExifInfo Camera(const std::string& make, const std::string& model, double focal_mm, double focal_35mm = 0) {
  ExifInfo exif;
  exif.present = true;
  exif.make = make;
  exif.model = model;
  exif.focal_length_mm = focal_mm;
  exif.focal_length_35mm = focal_35mm;
  return exif;
}

TEST(FocalPriorTest, ThirtyFiveMmEquivalentWins) {
  // The iPhone 4S photos of apriltag_swatbotics_mapping: 4.28 mm, 35 mm equivalent, 816x612.
  const FocalPrior prior = EstimateFocalPrior(Camera("Apple", "iPhone 4S", 4.28, 35), 816, 612);
  EXPECT_EQ(prior.source, FocalPrior::Source::kExif35mm);
  EXPECT_DOUBLE_EQ(prior.focal_px, 35.0 / 36.0 * 816);
  EXPECT_TRUE(testing::HasSubstring(prior.explanation, "35 mm-equivalent"));
  EXPECT_TRUE(testing::HasSubstring(prior.explanation, "793.3 px"));
  // Portrait: max(width, height) is still the long side.
  EXPECT_DOUBLE_EQ(EstimateFocalPrior(Camera("Apple", "iPhone 4S", 4.28, 35), 612, 816).focal_px, prior.focal_px);
}

TEST(FocalPriorTest, SensorTableWhenOnlyFocalMm) {
  const FocalPrior prior = EstimateFocalPrior(Camera("Apple", "iPhone 4S", 4.28), 3264, 2448);
  EXPECT_EQ(prior.source, FocalPrior::Source::kExifSensorTable);
  EXPECT_DOUBLE_EQ(prior.focal_px, 4.28 / 4.57 * 3264);
  EXPECT_TRUE(testing::HasSubstring(prior.explanation, "Apple iPhone 4S (sensor width 4.57 mm)"));
}

TEST(FocalPriorTest, SensorTableMatchingIsCaseInsensitiveAndToleratesMakeInModel) {
  struct Case {
    const char* make;
    const char* model;
    double sensor_mm;
  };
  const Case cases[] = {
      {"APPLE", "IPHONE 12 PRO MAX", 6.85},
      {"Canon", "Canon EOS 5D Mark III", 36.0},
      {"NIKON CORPORATION", "NIKON D750", 35.9},
      {"samsung", "SM-G991B", 7.20},
      {"SONY", "DSC-RX100M3", 13.2},
      {"GoPro", "HERO7 Black", 6.17},
      {"DJI", "FC6310", 13.2},
      {"Google", "Pixel 6a", 5.64},
      {"Google", "Pixel 6", 9.79},
      {"Canon", "Canon PowerShot A10", 5.27},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(std::string(c.make) + " / " + c.model);
    const FocalPrior prior = EstimateFocalPrior(Camera(c.make, c.model, 10.0), 1000, 800);
    EXPECT_EQ(prior.source, FocalPrior::Source::kExifSensorTable);
    EXPECT_NEAR(prior.focal_px, 10.0 / c.sensor_mm * 1000, 1e-9);
  }
}

TEST(FocalPriorTest, UnknownCameraFallsBackToDefault) {
  const FocalPrior prior = EstimateFocalPrior(Camera("Acme", "Obscura 1", 7.0), 640, 480);
  EXPECT_EQ(prior.source, FocalPrior::Source::kDefault);
  EXPECT_DOUBLE_EQ(prior.focal_px, 1.2 * 640);
  EXPECT_TRUE(testing::HasSubstring(prior.explanation, "camera \"Acme Obscura 1\" is not in the sensor table"));
  // A model that only shares a prefix with a table entry must not match it.
  EXPECT_EQ(EstimateFocalPrior(Camera("Apple", "iPhone 4 Mini", 4.0), 640, 480).source, FocalPrior::Source::kDefault);
  EXPECT_EQ(EstimateFocalPrior(Camera("Nikon", "iPhone 4S", 4.0), 640, 480).source, FocalPrior::Source::kDefault);
}

TEST(FocalPriorTest, NoExifUsesDefault) {
  const FocalPrior prior = EstimateFocalPrior(ExifInfo{}, 3072, 2048);
  EXPECT_EQ(prior.source, FocalPrior::Source::kDefault);
  EXPECT_DOUBLE_EQ(prior.focal_px, 1.2 * 3072);
  EXPECT_TRUE(testing::HasSubstring(prior.explanation, "no EXIF focal length; using 1.2·max(width,height)"));
  EXPECT_STREQ(FocalPriorSourceName(prior.source), "default");
}

// The names are fields of features/images.txt (one token each) and the mapper trusts "exif*".
TEST(FocalPriorTest, SourceNamesAreSingleTokensAndExifOnesSayExif) {
  EXPECT_STREQ(FocalPriorSourceName(FocalPrior::Source::kExif35mm), "exif-35mm");
  EXPECT_STREQ(FocalPriorSourceName(FocalPrior::Source::kExifSensorTable), "exif-sensor-table");
  for (auto source : {FocalPrior::Source::kExif35mm, FocalPrior::Source::kExifSensorTable, FocalPrior::Source::kDefault}) {
    EXPECT_EQ(std::string(FocalPriorSourceName(source)).find_first_of(" \t"), std::string::npos);
  }
}

}  // namespace
}  // namespace reconar
