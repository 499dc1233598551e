#pragma once
// Preview pictures of a mesh or point cloud without a display: views from around the model
// rendered offscreen (surfaceless EGL, GLES 3), tiled into one image. Used for the picture that
// `reconar reconstruct` leaves in the project, and for looking at reconstructions in bench/.
//
// WritePreview is the picture of a project: five views on a ring and one from above, 480 x 360
// each, tiled three to a row into a PNG. A textured model is drawn unlit (the photos' light is in
// its texture), any other with a headlight.
//
// Framing: the 1st..99th percentile box of the vertices per axis (a few stray points do not shrink
// the object to a dot); its bounding sphere fills 90 % of the shorter side of each view.
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Core>

#include "core/base/image.h"
#include "core/base/status.h"
#include "core/mesh/mesh.h"

namespace reconar {

struct PreviewOptions {
  int width = 640;  // per view
  int height = 480;
  Eigen::Vector3d up = -Eigen::Vector3d::UnitY();  // model up (SfM frames: the first camera's -y)
  // (azimuth, elevation) of each view in radians, azimuth about `up`; elevation from the horizon.
  std::vector<std::pair<double, double>> directions;
  float point_size_px = 2.0f;  // for point clouds
  int samples = 4;             // MSAA

  // `views` directions on a ring at `elevation_deg`, plus one from 70 degrees above.
  static std::vector<std::pair<double, double>> Ring(int views, double elevation_deg);
  Status Check() const;
};

// One RGB image per direction. `texture`: the texture pages of a mesh with texcoords, or null.
// Errors: bad options, an empty mesh, no EGL display or GLES context.
Result<std::vector<Image<uint8_t>>> RenderPreviewViews(const Mesh& mesh, const PreviewOptions& options,
                                                       const std::vector<TexturePage>* texture = nullptr);

// The views side by side, `columns` per row (all the same size), black where a row is short.
Image<uint8_t> TileImages(const std::vector<Image<uint8_t>>& views, int columns);

// The mesh or points (with their texture, or null) seen around `up`, written to `png_path`.
Status WritePreview(const Mesh& mesh, const std::vector<TexturePage>* texture, const Eigen::Vector3d& up,
                    const std::string& png_path);

}  // namespace reconar
