#pragma once
// An initial focal length in pixels for self-calibration, from EXIF when possible.
#include <string>

#include "core/io/exif.h"

namespace reconar {

struct FocalPrior {
  enum class Source {
    kExif35mm,         // FocalLengthIn35mmFilm: f_px = f35 / 36 * max(w, h)
    kExifSensorTable,  // FocalLength + sensor width from the built-in camera table
    kDefault,          // no usable EXIF: 1.2 * max(w, h)
  };
  double focal_px = 0;
  Source source = Source::kDefault;
  std::string explanation;  // one line for logs and reports, with the numbers used
};

// `width`/`height` are the image size after orientation (max(w, h) is what matters).
FocalPrior EstimateFocalPrior(const ExifInfo& exif, int width, int height);

// One token (no white space): it is a field of PROJECT/features/images.txt, and the mapper trusts
// priors whose name starts with "exif". "exif-35mm", "exif-sensor-table" or "default".
const char* FocalPriorSourceName(FocalPrior::Source source);

// The EXIF of an image from a camera whose focal length in pixels is known (a capture's keyframes):
// a virtual sensor 36 mm wide along the image's longer side, so FocalLength is the 35 mm
// equivalent to four decimals and FocalPlaneX/YResolution (pixels per centimetre) give the focal in
// pixels back exactly; FocalLengthIn35mmFilm (a whole millimetre) is what EstimateFocalPrior reads.
// Make "reconar", `model` as given, orientation 1, the pixel dimensions.
ExifInfo ExifForFocal(int width, int height, double focal_px, const std::string& model);

}  // namespace reconar
