#pragma once
// The photos' exposure gains (photo_gains.h: per photo and channel, what brings its colours to
// the photos' common exposure) against their cameras' exposure settings, so that a photo texturing
// did not use can be shown at its own exposure: per channel, log gain = intercept + slope * log H,
// H = ExposureTime * ISO / FNumber^2 (the light the sensor integrates for one scene radiance),
// fitted by least squares over the photos that have the three in EXIF. A straight line in the
// logs because a camera's tone curve is near a power law over the range one capture spans; its
// slope is found from the data rather than assumed, since phones' tone mapping bends it (the
// room's iPhone 4S photos: slope -0.26, where a plain gamma of 2.2 would give -0.45).
#include <cstddef>
#include <optional>
#include <vector>

#include <Eigen/Core>

#include "core/io/exif.h"

namespace reconar {

struct ExposureFit {
  Eigen::Vector3d intercept = Eigen::Vector3d::Zero(), slope = Eigen::Vector3d::Zero();
  size_t photos = 0;          // fitted over
  double correlation = 0.0;   // of log H with the mean of the log gains, over those photos

  // The gain of a photo taken at log H.
  Eigen::Vector3f Predict(double log_exposure) const;
};

// log H of a photo, when its EXIF has ExposureTime and ISO (FNumber taken as fixed when absent,
// as on phones whose aperture does not change).
std::optional<double> LogExposure(const ExifInfo& exif);

// Nothing unless at least kMinExposureFitPhotos photos have a log H and those spread over at
// least kMinExposureSpread (a capture at one fixed exposure predicts nothing: every photo's gain is
// then the texture's common exposure anyway).
inline constexpr size_t kMinExposureFitPhotos = 5;
inline constexpr double kMinExposureSpread = 0.1;  // standard deviation of log H
std::optional<ExposureFit> FitExposureGains(const std::vector<std::optional<double>>& log_exposures,
                                            const std::vector<Eigen::Vector3f>& gains);

}  // namespace reconar
