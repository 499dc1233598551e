#include "core/io/focal_prior.h"

#include <algorithm>
#include <cstdio>

#include "core/io/sensor_table.h"

namespace reconar {

namespace {

constexpr double kFullFrameWidthMm = 36.0;
constexpr double kDefaultFocalFactor = 1.2;

std::string Num(double value, int decimals) {
  char text[64];
  std::snprintf(text, sizeof(text), "%.*f", decimals, value);
  return text;
}

// "Apple iPhone 4S", but "Canon EOS 80D" rather than "Canon Canon EOS 80D".
std::string CameraName(const ExifInfo& exif) {
  if (exif.make.empty()) return exif.model;
  if (exif.model.empty()) return exif.make;
  const std::string first_word = exif.make.substr(0, exif.make.find(' '));
  if (exif.model.compare(0, first_word.size(), first_word) == 0) return exif.model;
  return exif.make + " " + exif.model;
}

}  // namespace

FocalPrior EstimateFocalPrior(const ExifInfo& exif, int width, int height) {
  const double size = std::max({width, height, 0});
  FocalPrior prior;
  if (exif.focal_length_35mm > 0) {
    prior.source = FocalPrior::Source::kExif35mm;
    prior.focal_px = exif.focal_length_35mm / kFullFrameWidthMm * size;
    prior.explanation = "EXIF 35 mm-equivalent focal length " + Num(exif.focal_length_35mm, 0) + " mm: " +
                        Num(exif.focal_length_35mm, 0) + "/36·" + Num(size, 0) + " px = " + Num(prior.focal_px, 1) +
                        " px";
    return prior;
  }
  std::string reason = "no EXIF focal length";
  if (exif.focal_length_mm > 0) {
    if (const auto sensor_mm = io_internal::LookupSensorWidthMm(exif.make, exif.model)) {
      prior.source = FocalPrior::Source::kExifSensorTable;
      prior.focal_px = exif.focal_length_mm / *sensor_mm * size;
      prior.explanation = "EXIF focal length " + Num(exif.focal_length_mm, 2) + " mm on " + CameraName(exif) +
                          " (sensor width " + Num(*sensor_mm, 2) + " mm): " + Num(exif.focal_length_mm, 2) + "/" +
                          Num(*sensor_mm, 2) + "·" + Num(size, 0) + " px = " + Num(prior.focal_px, 1) + " px";
      return prior;
    }
    reason = "EXIF focal length " + Num(exif.focal_length_mm, 2) + " mm but camera \"" + CameraName(exif) +
             "\" is not in the sensor table";
  }
  prior.source = FocalPrior::Source::kDefault;
  prior.focal_px = kDefaultFocalFactor * size;
  prior.explanation = reason + "; using 1.2·max(width,height) = " + Num(prior.focal_px, 1) + " px";
  return prior;
}

const char* FocalPriorSourceName(FocalPrior::Source source) {
  switch (source) {
    case FocalPrior::Source::kExif35mm: return "exif-35mm";
    case FocalPrior::Source::kExifSensorTable: return "exif-sensor-table";
    case FocalPrior::Source::kDefault: return "default";
  }
  return "unknown";
}

ExifInfo ExifForFocal(int width, int height, double focal_px, const std::string& model) {
  ExifInfo exif;
  exif.present = true;
  exif.make = "reconar";
  exif.model = model;
  const double long_side = std::max(width, height);
  exif.focal_length_mm = focal_px * 36.0 / long_side;
  exif.focal_length_35mm = exif.focal_length_mm;
  exif.focal_plane_x_resolution = exif.focal_plane_y_resolution = long_side / 3.6;
  exif.focal_plane_resolution_unit = 3;
  exif.pixel_x_dimension = width;
  exif.pixel_y_dimension = height;
  return exif;
}

}  // namespace reconar
