#pragma once
// `reconar render PROJECT IMAGE_NAME... --out DIR [--model PATH]`: a model drawn alone from the
// viewpoint of registered photos, for reports and for measuring a texture against the photos.
//
// For each named photo, with its camera undistorted (the same focal, principal point and size,
// no radial distortion): DIR/NAME.png, the model drawn unlit on black: its vertex colours as they
// are, or the project's texture at the photo's exposure (the texture holds the photos' common
// exposure: a photo texturing used is shown at its own gain, one it did not at the gain its EXIF
// exposure settings predict, core/texture/exposure_fit.h, and at the texture's own exposure when
// neither is known); DIR/NAME.mask.png, white where the model covers the pixel (the pixels whose
// colour does not change with the background's: no anti-aliasing, so the mask is exact);
// DIR/NAME.photo.png, the photo itself undistorted to that camera (core/mvs/undistort.h), to
// compare with. Every file is written atomically.
#include <string>
#include <vector>

#include <Eigen/Core>

#include "core/base/image.h"
#include "core/base/status.h"

namespace reconar {

struct PhotoRenderOptions {
  std::vector<std::string> image_names;
  std::string out_dir;
  std::string model_path;  // empty: the project's (mesh/textured.glb, else mesh/mesh.ply)
  bool write_photos = true;
  bool match_photo_exposure = true;  // false: the texture as it is
};

// How a photo's render was exposed.
enum class RenderExposure { kTexture, kPhotoGain, kExif };
const char* RenderExposureName(RenderExposure exposure);  // "texture", "photo's gain", "EXIF"

struct PhotoRenderReport {
  std::string model_path;
  bool textured = false;
  size_t faces = 0;
  std::vector<std::string> written;  // NAME.png of each photo
  std::vector<double> coverage;      // per photo: the fraction of its pixels the model covers
  std::vector<RenderExposure> exposure;  // per photo
  std::vector<Eigen::Vector3f> gain;     // per photo: the texture's colours were divided by it
  std::string warning;                   // why the photos' exposures could not be used, if so
};

// InvalidArgument naming a photo that is not a registered photo of the project; file errors of
// the project, the model and the photos; FailedPrecondition without a display driver (EGL).
Result<PhotoRenderReport> RenderFromPhotos(const std::string& project_dir, const PhotoRenderOptions& options);

// The model of `model_path` (any LoadArModel reads: a textured .glb with its texture) seen from
// around `up` (render/preview.h's WritePreview), written to `png_path`: the PreviewFunction of
// core/pipeline/reconstruct.h. Errors name the file.
Status WriteModelPreview(const std::string& model_path, const Eigen::Vector3d& up, const std::string& png_path);

}  // namespace reconar
