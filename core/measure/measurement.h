#pragma once
// Measurements in a reconstructed project with a ± from the reconstruction (`reconar measure`,
// the view's tap-to-measure): distances, paths, areas and heights between points named by a tag,
// by world coordinates or by pixels in the registered photos.
//
// Where the ± comes from (docs/measure.md says it for users):
//  - The adjustment: every point a measurement uses is a function of points of the sparse model
//    and of points added to it with their observations (a pixel pair triangulated; a pixel met
//    with the mesh, observed where it projects in the photos that see it), and its variance comes
//    from the adjustment's covariance (project_covariance.h) by the gradient. On a metric project
//    the function is made independent of the model's similarity by dividing each length by the
//    scale tags' mean edge in the model over the tag size (the known length that fixes metres), so
//    that the scale's uncertainty enters through those corners.
//  - The surface: a point met with the mesh is off by the mesh's own error, taken as the RMS
//    distance of the dense points near it from its plane, along the ray (1 / cos of the incidence).
//  - The scale's spread: the scale tags' edges scatter more than their corners' noise explains
//    (printing, a tag not flat); (their standard deviation / mean / root of their number) times the
//    value, once per power of length, is added.
//  - Calibration by the known lengths: the scale tags' own edges and diagonals, measured as above,
//    against the tag size and its root two, give normalised errors; σ is multiplied by the larger
//    of their RMS and their 95th percentile / 1.96 (never by less than 1), as a survey calibrates
//    its error model against check distances. What it covers is what disturbs short lengths like
//    the tags' (errors correlated within a photo that the adjustment's independent-noise model
//    leaves out); what it cannot see: a bias of the mesh that its dense points share (a surface
//    the photos could not match, smoothed over), and a drift of the scale across the scene away
//    from the scale tags.
// On a project without a metric scale (no tags) the values and σ are in model units, σ relative to
// the model's own size (each length divided by the RMS distance of the model's points from their
// centroid), with no known length to calibrate it.
#include <memory>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "core/base/status.h"
#include "core/math/radial_camera.h"
#include "core/math/rigid3.h"
#include "core/pipeline/project.h"

namespace reconar {

enum class MeasurePointKind { kTagCentre, kTagCorner, kWorld, kPixels, kPlaced };

struct PhotoPixel {
  std::string image;  // a registered photo's name
  Eigen::Vector2d pixel = Eigen::Vector2d::Zero();  // centre of the top-left pixel at (0, 0)
};

// "tag:3" (centre), "tag:3:c2" (corner 0..3, libapriltag's order), "xyz:0.1,0.2,1.5" (world
// frame), "IMG.JPG@512.5,300" (the pixel's ray met with the model's surface) or
// "IMG.JPG@512.5,300+IMG2.JPG@498,305" (the same point in two or more photos, triangulated).
struct MeasurePoint {
  std::string text;  // as given, for messages
  MeasurePointKind kind = MeasurePointKind::kWorld;
  int tag_id = -1;
  int corner = -1;
  Eigen::Vector3d world = Eigen::Vector3d::Zero();
  std::vector<PhotoPixel> pixels;
  int placed = -1;  // kPlaced: a point ProjectMeasurer::PointOnSurface placed (`world` is where)
};

// InvalidArgument naming the text and what is wrong with it.
Result<MeasurePoint> ParseMeasurePoint(const std::string& text);

enum class MeasureKind { kDistance, kPath, kArea, kHeight };
const char* MeasureKindName(MeasureKind kind);  // "distance", "path", "area", "height"

// distance: 2 points; path: 2 or more; area: a polygon of 3 or more; height: the point, then three
// points of the plane it is measured from (signed, positive on the side the plane's normal
// (B - A) x (C - A) points to).
struct MeasureItem {
  MeasureKind kind = MeasureKind::kDistance;
  std::vector<MeasurePoint> points;
};

struct MeasuredItem {
  MeasureKind kind = MeasureKind::kDistance;
  std::vector<std::string> point_texts;
  std::vector<Eigen::Vector3d> points;  // world frame
  double value = 0.0;
  double sigma = 0.0;  // 1σ; infinity when a point is undetermined
  std::string unit;    // "m", "m2", or "model units" / "model units^2"
};

struct MeasureOptions {
  double pick_sigma_px = 1.0;                // how precisely a pixel was picked in its photo (1σ)
  int max_surface_views = 5;                 // photos that observe a point met with the surface
  double surface_occlusion_fraction = 0.99;  // a photo sees it when the surface first meets its ray past this share of the way
  double support_radius_spacings = 3.0;      // a surface point's dense points: within this many of their median spacings
  int min_support_points = 6;                // fewer within max_support_radii radii: Poisson's fill far from any point
  int max_support_radii = 16;
  double min_triangulation_angle_deg = 1.0;  // for pixels picked in several photos
  double max_pick_reprojection_px = 8.0;     // their rays must meet within this
  // A pixel met with the mesh is refused when the hit lies more than max_hit_behind (relative) deeper
  // than every model point its photo sees within hit_check_radius (of the image diagonal) of it,
  // given at least hit_check_min_points of them: the mesh misses the surface the pixel shows.
  double hit_check_radius = 0.02;
  int hit_check_min_points = 3;
  double max_hit_behind = 0.1;
};

struct MeasureSetup {  // what the ± rests on, for reports
  bool metric = false;
  double tag_size_m = 0.0;
  std::vector<int> scale_tags;
  int scale_segments = 0;             // the scale tags' edges and diagonals that calibrated σ
  double sigma_calibration = 1.0;     // the factor they gave
  double scale_relative_sigma = 0.0;   // the scale's own uncertainty, relative
  double length_relative_sigma = 0.0;  // a length's error beyond the covariance, relative
  double sigma0_px = 0.0;             // the adjustment's a-posteriori σ of unit weight
  int cameras = 0, points = 0, observations = 0;
  double seconds_setup = 0.0;
};

class ProjectMeasurer {
 public:
  // Reads the project's sparse model, tags and (when a point needs it) its mesh, and computes the
  // covariance once. NotFound naming what is missing for a project without a sparse model.
  static Result<ProjectMeasurer> Open(const Project& project, const MeasureOptions& options = {});
  ProjectMeasurer(ProjectMeasurer&&) noexcept;
  ProjectMeasurer& operator=(ProjectMeasurer&&) noexcept;
  ~ProjectMeasurer();

  // InvalidArgument for a wrong number of points; NotFound / FailedPrecondition naming a point the
  // model cannot place (an unknown tag or photo, a photo not registered, a pixel outside its photo,
  // a ray that meets no surface, a project without a mesh for a single pixel) and why.
  Result<MeasuredItem> Measure(const MeasureItem& item);

  // The point where the ray from `origin` along `direction` (world frame) first meets the model's
  // surface (the view's tap on the screen), as a MeasurePoint of kind kPlaced, observed where it
  // projects in the photos that see it, so that Measure gives it a σ. NotFound when it meets
  // nothing, FailedPrecondition when the project has no mesh.
  Result<MeasurePoint> PointOnSurface(const Eigen::Vector3d& origin, const Eigen::Vector3d& direction);

  // Reads the mesh and the dense points now rather than at the first pixel met with the surface
  // (the view calls it before its first frame). Errors as a pixel point would have them.
  Status LoadSurface();

  // The view's measure: the distance between the surface points under two pixels of a frame
  // taken by `camera` at `cam_from_world` (world frame), with its σ. The points are placed for
  // this call only, so that a measure every frame does not grow the measurer.
  Result<MeasuredItem> MeasureBetweenPixels(const Rigid3& cam_from_world, const RadialCamera& camera,
                                            const Eigen::Vector2d& a, const Eigen::Vector2d& b);

  const MeasureSetup& setup() const { return setup_; }

 private:
  struct State;
  explicit ProjectMeasurer(std::unique_ptr<State> state);
  std::unique_ptr<State> state_;
  MeasureSetup setup_;
};

// One item on one line: {"kind", "point_names": [...], "points": [[x,y,z]...], "value", "sigma"
// (null when infinite), "unit"}.
std::string MeasuredItemJson(const MeasuredItem& item);

// {"metric": bool, "setup": {...}, "items": [MeasuredItemJson...]}.
std::string MeasurementsJson(const MeasureSetup& setup, const std::vector<MeasuredItem>& items);

}  // namespace reconar
