#pragma once
// Step 1 of texturing (texture_mesh.h): which photos see which faces, and how well.
//
// In each photo, every vertex is projected through the camera model; the mesh is drawn into a
// depth buffer at a reduced resolution (1/z interpolated, so depths are exact along the
// triangle); a face is seen when it faces the camera, and its centroid and the points halfway to
// its corners project inside the frame no farther than the buffer's depth there (within a relative
// tolerance). A seen face keeps its projected area in full-resolution pixels and the photo's
// sharpness there (the mean gradient magnitude at those points, on the reduced photo smoothed over
// 5 x 5); view_labelling.h weighs them.
// Its colour is the mean of the reduced photo, smoothed over 3 x 3, at the same points.
// The reduced photo is kept for the seam levelling.
#include <array>
#include <cstdint>
#include <vector>

#include <Eigen/Core>

#include "core/base/image.h"
#include "core/mesh/mesh.h"
#include "core/texture/texture_mesh.h"

namespace reconar {

// Centroids and unit normals of a mesh's faces (zero normal for a degenerate face).
struct FaceGeometry {
  explicit FaceGeometry(const Mesh& mesh);
  std::vector<Eigen::Vector3d> centroids, normals;
};

// Projection of world points into one photo at full resolution, refusing points beyond the lens
// distortion's fold (where the radial model turns back and would put far-off points into the frame).
class PhotoProjector {
 public:
  explicit PhotoProjector(const TexturePhoto& photo);
  // False behind the camera, beyond the fold or for a non-finite result; the pixel may lie
  // outside the frame.
  bool Project(const Eigen::Vector3d& world_point, Eigen::Vector2d* pixel, double* depth) const;
  const TexturePhoto& photo() const { return photo_; }
  Eigen::Vector3d center() const { return center_; }

 private:
  TexturePhoto photo_;
  Eigen::Vector3d center_;
  double max_radius2_;  // of the normalised point
};

// A photo reduced by 2^level (area average), as the seam levelling samples it.
struct ReducedPhoto {
  int level = 0;
  Image<uint8_t> rgb;

  // Full-resolution pixel to this image's coordinates.
  Eigen::Vector2d FromFull(const Eigen::Vector2d& pixel) const {
    const double scale = 1.0 / static_cast<double>(1 << level);
    return (pixel.array() + 0.5) * scale - 0.5;
  }
};

struct FaceCandidate {
  int face = -1;
  int photo = -1;
  float area = 0.0f;       // of the face's projection, full-resolution pixels
  float sharpness = 0.0f;  // the photo's mean smoothed gradient magnitude at the face
  float quality = 0.0f;    // the data term's (view_labelling.h); the area until weighed
  std::array<float, 3> colour = {0.0f, 0.0f, 0.0f};
  float colour_distance = 0.0f;  // from the median colour of the face's candidates (view_labelling.h)
};

// Buffers one thread reuses from photo to photo.
struct CandidateScratch {
  std::vector<float> depth;
  std::vector<Eigen::Vector2d> pixels;  // per vertex, full resolution
  std::vector<double> depths;
  std::vector<uint8_t> projected;
  std::vector<float> gradient;
};

// The level of a photo for raster_long_side.
int ReducedLevel(int width, int height, int raster_long_side);

// The candidates of photo `photo_index` (appended to *candidates in face order) and the reduced
// photo kept for the seams.
void FindFaceCandidates(const Mesh& mesh, const FaceGeometry& geometry, int photo_index,
                        const PhotoProjector& projector, const Image<uint8_t>& rgb, const TextureOptions& options,
                        CandidateScratch* scratch, std::vector<FaceCandidate>* candidates, ReducedPhoto* reduced);

}  // namespace reconar
