#pragma once
// A hand-held burst round a small, dull, texture-poor object standing on a dark floor: rendered
// views with exact cameras, for structure from motion on the captures a field user makes of a
// small plaster or clay object (the Stanford bunny, bun_zipper.ply, by default: bench/sfm
// render_capture). Test support only.
//
// The capture: the camera walks `revolutions` times round the object on a spiral rising evenly from
// min_elevation_deg to max_elevation_deg above the horizontal plane through the centre of the
// object's bounding box, `views` photos evenly spaced along it, each looking at that centre from
// distance_m, with a hand's jitter (position, distance, aim, roll; uniform, seeded).
// The world frame is the mesh's, its +y up; image y points down.
//
// The look: a solid texture of a few grey levels fixed to the surface (value noise of the 3D
// surface point, three octaves from texture_cell_m, so that every view agrees; its standard
// deviation texture_contrast grey levels at full light), shaded Lambertian under a directional
// light fixed in the world plus ambient light; both sides of a triangle are lit alike (the scan's
// holes show its inside). The floor (the plane through the object's lowest point) and everything
// beyond it are background_level, the floor with a faint texture of background_contrast grey
// levels (standard deviation; value noise of the floor point, cells from 1 cm). Each pixel
// averages supersampling^2 samples (supersampling.h), then gets Gaussian sensor noise and is
// rounded to 8 bits.
#include <Eigen/Core>
#include <cstdint>
#include <string>
#include <vector>

#include "core/base/image.h"
#include "core/base/status.h"
#include "core/mesh/mesh.h"
#include "tests/support/sfm_evaluation.h"

namespace reconar::testing {

struct ObjectCaptureOptions {
  int views = 320;
  double revolutions = 4.0;  // 4.5 degrees of azimuth between neighbouring views at the defaults
  double min_elevation_deg = 15.0;
  double max_elevation_deg = 60.0;
  double distance_m = 0.35;
  int width = 640;
  int height = 480;
  double focal_px = 520.0;  // square pixels, principal point at the image centre
  // The hand: each uniform in +- the value, drawn from `seed`.
  double position_jitter_deg = 1.0;  // azimuth and elevation
  double distance_jitter = 0.03;     // relative
  double aim_jitter_deg = 1.5;       // pan and tilt
  double roll_jitter_deg = 2.0;
  // The look, in grey levels.
  double surface_level = 110.0;   // the object's surface facing the light, before its clay tint
  double texture_contrast = 4.0;  // standard deviation of the surface's texture (at full light)
  double texture_cell_m = 0.002;  // finest cell of the texture (3 pixels at 0.35 m, f = 520)
  double ambient = 0.35;          // share of a surface's full light that reaches it when facing away
  double background_level = 28.0;
  double background_contrast = 1.0;  // standard deviation of the floor's texture
  double noise_sigma = 1.0;          // sensor noise per sample
  int supersampling = 2;             // samples per pixel along each axis
  uint32_t seed = 1;                 // the hand's jitter, the textures, the sensor noise
  int threads = 1;                   // views rendered in parallel; 0: one per core

  // InvalidArgument naming the first unusable field.
  Status Check() const;
};

// The centre of the mesh's axis-aligned bounding box.
Eigen::Vector3d BoundingBoxCenter(const Mesh& mesh);

// The views' true cameras in capture order, named view_NNN.png (zero-padded to the count's digits),
// looking at `centre`. The options must pass Check().
std::vector<NamedGroundTruthCamera> ObjectCaptureCameras(const ObjectCaptureOptions& options,
                                                         const Eigen::Vector3d& centre);

class ObjectCaptureScene {
 public:
  // InvalidArgument for options that fail Check(), a mesh that fails ValidateMesh or has no
  // triangles, or a view whose camera is not above the floor.
  static Result<ObjectCaptureScene> Create(Mesh object, const ObjectCaptureOptions& options);

  const ObjectCaptureOptions& options() const { return options_; }
  const std::vector<NamedGroundTruthCamera>& views() const { return views_; }
  const Eigen::Vector3d& centre() const { return centre_; }
  double floor_y() const { return floor_y_; }

  // View `index`'s picture, RGB. Safe to call from several threads.
  Image<uint8_t> Render(size_t index) const;

 private:
  ObjectCaptureScene() = default;
  Eigen::Vector3f Colour(const GroundTruthCamera& camera, const Eigen::Vector3d& direction, int32_t triangle) const;

  Mesh object_;  // with vertex normals
  ObjectCaptureOptions options_;
  Eigen::Vector3d centre_ = Eigen::Vector3d::Zero();
  double floor_y_ = 0.0;
  std::vector<NamedGroundTruthCamera> views_;
};

// Writes every view into `out_dir` (which must exist) as PNG, on options().threads threads; the
// true cameras by file name. The PNG writer's error for a file it cannot write.
Result<GroundTruthByName> WriteObjectCapture(const ObjectCaptureScene& scene, const std::string& out_dir);

}  // namespace reconar::testing
