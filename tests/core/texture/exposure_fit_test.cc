// Fitting the photos' exposure gains to their EXIF exposure (core/texture/exposure_fit.h).
#include "core/texture/exposure_fit.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

namespace reconar {
namespace {

TEST(ExposureFitTest, LogExposureNeedsTimeAndIso) {
  ExifInfo exif;
  EXPECT_FALSE(LogExposure(exif).has_value());
  exif.exposure_time_s = 0.05;
  EXPECT_FALSE(LogExposure(exif).has_value());
  exif.iso = 125;
  ASSERT_TRUE(LogExposure(exif).has_value());
  EXPECT_DOUBLE_EQ(*LogExposure(exif), std::log(0.05 * 125));  // aperture taken as fixed
  exif.f_number = 2.4;
  EXPECT_DOUBLE_EQ(*LogExposure(exif), std::log(0.05 * 125 / (2.4 * 2.4)));
}

TEST(ExposureFitTest, RecoversTheLineThroughNoisyGains) {
  const Eigen::Vector3d intercept(0.4, 0.3, 0.2), slope(-0.3, -0.25, -0.2);
  std::mt19937 random(5);
  std::uniform_real_distribution<double> exposure(std::log(0.01 * 50), std::log(0.07 * 400));
  std::normal_distribution<double> noise(0.0, 0.03);
  std::vector<std::optional<double>> log_exposures;
  std::vector<Eigen::Vector3f> gains;
  for (int i = 0; i < 60; ++i) {
    const double h = exposure(random);
    log_exposures.push_back(i % 7 == 3 ? std::nullopt : std::optional<double>(h));  // some without EXIF
    Eigen::Vector3d log_gain = intercept + slope * h;
    for (int c = 0; c < 3; ++c) log_gain[c] += noise(random);
    gains.push_back(log_gain.array().exp().cast<float>().matrix());
  }
  const std::optional<ExposureFit> fit = FitExposureGains(log_exposures, gains);
  ASSERT_TRUE(fit.has_value());
  EXPECT_EQ(fit->photos, 51u);
  for (int c = 0; c < 3; ++c) {
    EXPECT_NEAR(fit->slope[c], slope[c], 0.03) << c;
    EXPECT_NEAR(fit->intercept[c], intercept[c], 0.1) << c;
  }
  EXPECT_LT(fit->correlation, -0.9);
  const Eigen::Vector3f predicted = fit->Predict(1.0);
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(predicted[c], std::exp(intercept[c] + slope[c]), 0.05) << c;
}

TEST(ExposureFitTest, NothingFromTooFewPhotosOrOneExposure) {
  std::vector<std::optional<double>> log_exposures(4, 1.0);
  log_exposures[1] = 2.0;
  std::vector<Eigen::Vector3f> gains(4, Eigen::Vector3f::Ones());
  EXPECT_FALSE(FitExposureGains(log_exposures, gains).has_value());  // 4 photos
  log_exposures.assign(20, 1.0);  // every photo at one exposure
  gains.assign(20, Eigen::Vector3f::Ones());
  EXPECT_FALSE(FitExposureGains(log_exposures, gains).has_value());
  log_exposures.assign(20, std::nullopt);  // none with EXIF
  EXPECT_FALSE(FitExposureGains(log_exposures, gains).has_value());
}

}  // namespace
}  // namespace reconar
