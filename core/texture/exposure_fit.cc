#include "core/texture/exposure_fit.h"

#include <cmath>

namespace reconar {

Eigen::Vector3f ExposureFit::Predict(double log_exposure) const {
  return (intercept + slope * log_exposure).array().exp().cast<float>().matrix();
}

std::optional<double> LogExposure(const ExifInfo& exif) {
  if (!(exif.exposure_time_s > 0.0) || exif.iso <= 0) return std::nullopt;
  const double aperture = exif.f_number > 0.0 ? exif.f_number : 1.0;
  return std::log(exif.exposure_time_s * exif.iso / (aperture * aperture));
}

std::optional<ExposureFit> FitExposureGains(const std::vector<std::optional<double>>& log_exposures,
                                            const std::vector<Eigen::Vector3f>& gains) {
  std::vector<double> x;
  std::vector<Eigen::Vector3d> y;
  for (size_t i = 0; i < log_exposures.size() && i < gains.size(); ++i) {
    if (!log_exposures[i] || !(gains[i].array() > 0.0f).all()) continue;
    x.push_back(*log_exposures[i]);
    y.push_back(gains[i].cast<double>().array().log().matrix());
  }
  if (x.size() < kMinExposureFitPhotos) return std::nullopt;
  const double n = static_cast<double>(x.size());
  double mean_x = 0.0;
  Eigen::Vector3d mean_y = Eigen::Vector3d::Zero();
  for (size_t i = 0; i < x.size(); ++i) {
    mean_x += x[i] / n;
    mean_y += y[i] / n;
  }
  double sxx = 0.0, syy = 0.0, sxy_mean = 0.0;
  Eigen::Vector3d sxy = Eigen::Vector3d::Zero();
  for (size_t i = 0; i < x.size(); ++i) {
    const double dx = x[i] - mean_x;
    const Eigen::Vector3d dy = y[i] - mean_y;
    sxx += dx * dx;
    sxy += dx * dy;
    sxy_mean += dx * dy.mean();
    syy += dy.mean() * dy.mean();
  }
  if (std::sqrt(sxx / n) < kMinExposureSpread) return std::nullopt;
  ExposureFit fit;
  fit.photos = x.size();
  fit.slope = sxy / sxx;
  fit.intercept = mean_y - fit.slope * mean_x;
  fit.correlation = syy > 0.0 ? sxy_mean / std::sqrt(sxx * syy) : 0.0;
  return fit;
}

}  // namespace reconar
