#pragma once
// Internal to core/io: sensor widths of common cameras, for focal priors from EXIF FocalLength.
#include <optional>
#include <string_view>

namespace reconar::io_internal {

// Width in mm of the long side of the sensor of `make` `model` as written in EXIF, matched
// case-insensitively (a model may repeat the make, as in "Canon EOS 80D"); nullopt if unknown.
std::optional<double> LookupSensorWidthMm(std::string_view make, std::string_view model);

}  // namespace reconar::io_internal
