#pragma once
// A synthetic multi-view scene for dense MVS tests: a box standing on a ground square, every face
// covered with seeded value noise (bilinear interpolation of random lattice values, two octaves),
// seen by pinhole cameras on a ring. Images are rendered on the CPU by inverse mapping: the ray of
// each pixel centre is intersected with the faces and the nearest hit's texture is sampled
// bilinearly. The geometry is exact, so distances to the true surface are known.
#include <Eigen/Core>
#include <cstdint>
#include <vector>

#include "core/mvs/dense_view.h"

namespace reconar::testing {

struct TexturedBoxSceneOptions {
  int num_cameras = 6;
  int width = 320, height = 240;
  double focal = 300.0;            // pixels
  double ring_radius = 3.0;        // cameras on a circle around the z axis ...
  double ring_height = 2.0;        // ... at this height, looking at `target`
  Eigen::Vector3d target = Eigen::Vector3d(0.0, 0.0, 0.2);
  double box_half_size = 0.5;      // box [-h, h]^2 x [0, box_height]
  double box_height = 0.6;
  double ground_half_size = 2.5;   // ground square [-g, g]^2 at z = 0
  double texel = 0.02;             // lattice spacing of the fine noise octave (world units)
  // > 0: the box's four sides are plain grey (kBlankPanelValue) inside a textured frame this wide:
  // texture-poor panels, like white walls between door frames.
  double blank_panel_inset = 0.0;
  uint64_t seed = 1;
};

constexpr double kBlankPanelValue = 0.55;

struct SceneHit {
  bool hit = false;
  double distance = 0.0;  // along the (unit) ray
  int face = -1;
  Eigen::Vector3d point = Eigen::Vector3d::Zero();
};

class TexturedBoxScene {
 public:
  explicit TexturedBoxScene(const TexturedBoxSceneOptions& options);

  const std::vector<DenseView>& views() const { return views_; }
  std::vector<const DenseView*> view_pointers() const;

  // Nearest intersection of the ray origin + s * direction (s > 0, direction unit).
  SceneHit Intersect(const Eigen::Vector3d& origin, const Eigen::Vector3d& direction) const;
  // Distance from x to the nearest face, and that face's outward normal.
  double DistanceToSurface(const Eigen::Vector3d& x, Eigen::Vector3d* normal = nullptr) const;
  // True when surface point x of `face` lies in a blank panel (TexturedBoxSceneOptions::blank_panel_inset).
  bool InBlankPanel(int face, const Eigen::Vector3d& x) const;
  // True when `view` sees surface point x (x is the first hit along the ray to it).
  bool Sees(const DenseView& view, const Eigen::Vector3d& x) const;

 private:
  struct Face {
    Eigen::Vector3d origin, u, v, normal;  // point = origin + a u + b v, a in [0, extent_u], b in [0, extent_v]
    double extent_u, extent_v;
  };
  double Texture(int face, double a, double b) const;

  TexturedBoxSceneOptions options_;
  std::vector<Face> faces_;
  std::vector<DenseView> views_;
};

}  // namespace reconar::testing
