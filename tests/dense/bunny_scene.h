#pragma once
// A synthetic multi-view stereo scene with exact cameras: the Stanford bunny (bun_zipper.ply,
// metres, y up) seen from two rings of cameras looking at the centre of its bounding box, rendered
// with our GLES stack (surfaceless EGL, render/) and a procedural texture so that small NCC
// patches are discriminative.
//
// Conventions: pixel (0, 0) is the centre of the top-left pixel, x right, y down; poses are
// cam_from_world with the camera looking down +z (core/sfm/reconstruction.h). The renderer's clip
// transform (render/camera_projection.h) follows the same pixel convention, so a bunny vertex X
// lands where SfmCamera::Project(pose * X) says.
//
// Appearance (view independent, so the scene is Lambertian, as PMVS assumes): the albedo is
// multi-octave 3D value noise of the model-space position, squashed to high contrast, finest cell
// BunnySceneOptions::texture_cell_m (about 2 pixels at the chosen distance), with a slow colour
// tint; shading is ambient plus Lambert under a directional light fixed in the world. The
// background is black. Each pixel averages supersampling^2 samples (box filter), as a sensor
// integrates over its pixel.
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "core/base/image.h"
#include "core/base/status.h"
#include "core/mesh/mesh.h"
#include "core/sfm/reconstruction.h"
#include "tests/support/object_capture.h"  // BoundingBoxCenter: the point every camera looks at

namespace reconar {
namespace testing {

struct BunnySceneOptions {
  int width = 640;
  int height = 480;
  double focal_px = 800.0;  // square pixels, principal point at the image centre
  // Camera centres at this distance from the bunny's bounding-box centre: 0.45 m with f = 800 makes
  // the bunny (0.15 m tall) about 270 px high, ~57 % of the frame; pixel footprint there 0.56 mm.
  double distance_m = 0.45;
  int cameras_per_ring = 20;
  double low_ring_elevation_deg = 15.0;   // above the bunny's horizontal plane (world +y is up)
  double high_ring_elevation_deg = 45.0;  // the high ring is turned by half a step in azimuth
  int supersampling = 2;                  // samples per pixel along each axis; 1 = one sample at the centre
  double texture_cell_m = 0.0012;         // finest noise cell, ~2 px at distance_m

  // InvalidArgument naming the first offending field.
  Status Check() const;
};

// One camera (index 0) and cameras_per_ring * 2 registered images "bunny_NNN.png" with their
// exact poses, no keypoints and no points: the low ring first, then the high ring.
Reconstruction MakeBunnyCameras(const Mesh& bunny, const BunnySceneOptions& options);

// Renders the bunny (needs the GLES 3 context current at Create and at every call).
class BunnyRenderer {
 public:
  // Uploads the mesh (computing vertex normals when it has none) and builds the shaders.
  static Result<std::unique_ptr<BunnyRenderer>> Create(const Mesh& bunny, const BunnySceneOptions& options);
  ~BunnyRenderer();

  // The textured, shaded image, RGB, width x height of the options.
  Status RenderColor(const SfmCamera& camera, const Rigid3& pose, Image<uint8_t>* rgb);
  // Camera-frame depth z of the surface seen through each pixel centre (one sample per pixel), in
  // metres, 0 where the pixel sees the background. Exact to 0.1 um (24-bit fixed point to 2 m).
  Status RenderDepth(const SfmCamera& camera, const Rigid3& pose, Image<float>* depth);
  // Share of each pixel's supersampling^2 samples (those RenderColor averages) that see the bunny.
  Status RenderCoverage(const SfmCamera& camera, const Rigid3& pose, Image<float>* coverage);

 private:
  struct Gl;
  explicit BunnyRenderer(std::unique_ptr<Gl> gl);
  std::unique_ptr<Gl> gl_;
};

// How much of the bunny the cameras see, from the depth renders: a vertex counts as seen by a view
// when it projects inside the image, its depth matches the rendered depth at its pixel within
// depth_tolerance_m, and its normal is within max_angle_deg of the direction to the camera.
struct BunnyVisibility {
  double seen_by_2_fraction = 0.0;  // vertices seen by >= 2 views
  double seen_by_3_fraction = 0.0;
  std::vector<int> views_per_vertex;
};

struct BunnySceneReport {
  int views = 0;
  double mean_foreground_fraction = 0.0;   // bunny pixels / image pixels, averaged over views
  double pixel_footprint_at_center_m = 0.0;  // distance_m / focal_px
  BunnyVisibility visibility;
};

struct BunnyProjectOptions {
  BunnySceneOptions scene;
  double visibility_depth_tolerance_m = 0.0015;
  double visibility_max_angle_deg = 60.0;  // PMVS's angle limit iota = pi/3
};

// Renders every view into <project_dir>/images/<name>, writes features/images.txt
// (Project::WriteImageList, focal source "ground-truth") and sparse/ (WriteColmapTextModel: the
// exact cameras, k1 = k2 = 0, no points). Needs a current GLES 3 context.
Result<BunnySceneReport> WriteBunnyProject(const Mesh& bunny, const BunnyProjectOptions& options,
                                           const std::string& project_dir);

}  // namespace testing
}  // namespace reconar
