#pragma once
// The state the incremental mapper's parts share: the model being built, the tracks it is built
// from, the links between tracks and points, and why each image is not registered (yet). The
// parts (initial_pair.h, next_image.h, image_registration.h, track_triangulation.h,
// point_filter.h, mapper_adjustment.h, intrinsics_selection.h) each take it explicitly.
#include <Eigen/Core>
#include <string>
#include <vector>

#include "core/sfm/reconstruction.h"
#include "core/sfm/tracks.h"


namespace reconar {

struct MapperOptions;

struct MapperModel {
  Reconstruction rec;
  TrackSet tracks;
  std::vector<int> point_of_track;     // track -> point id or -1
  std::vector<int> track_of_point;     // point id -> track
  std::vector<double> camera_prior;    // per camera: focal prior
  std::vector<bool> camera_from_exif;  // per camera: the prior came from EXIF
  std::vector<std::string> failure;    // per image: why it is not registered (yet)
  std::vector<int> tried_with;         // per image: visible points at the last failed attempt
  std::vector<int> neighbour_tried_with;  // the same for registration from a neighbour
  // Per image: its tag corners' keypoints (sorted) and each one's error bound in pixels, the
  // tag's mean edge there (MaxSquaredError).
  struct TagCornerBound {
    int keypoint = -1;
    double bound_px = 0.0;
    bool operator<(const TagCornerBound& other) const { return keypoint < other.keypoint; }
  };
  std::vector<std::vector<TagCornerBound>> tag_corner_bounds;

  // A model over `tracks` with no point yet: every track untriangulated.
  void SetTracks(TrackSet track_set);

  // Squared reprojection error (pixels^2) of `position` in keypoint kp of `image`; infinity
  // behind the camera.
  double SquaredError(const Eigen::Vector3d& position, int image, int kp) const;
  // The largest squared reprojection error (pixels^2) an observation of keypoint kp of `image`
  // keeps: max_reprojection_error_px, or for a tag corner the tag's edge in that image when longer.
  // A tag corner is identified by the decoded tag, not matched: far off, it says that the model
  // drifted (the room's odd photos: the one view across the room saw three tags 7-16 px off their
  // points and lost them, and with them the loop), while a corner still within the tag's own size
  // is the same corner.
  double MaxSquaredError(int image, int kp, const MapperOptions& options) const;
  // The largest angle (radians) between rays from the point to the centres of its first 30 views.
  double MaxTriangulationAngle(const SfmPoint& point) const;
  void AddObservation(int point_id, int image, int kp);
  // Removes the point's observations and marks it deleted; its track becomes untriangulated.
  void DeletePoint(int point_id);
  // Keypoints of `image` whose track has a point.
  int CountVisiblePoints(int image) const;
  // Registered images using `camera`.
  int CameraUsers(int camera) const;
  // Some camera serves more than one image.
  bool CameraShared() const;
  std::vector<int> AllPoints() const;  // not deleted
  std::vector<int> PointsSeenBy(const std::vector<int>& images) const;
  std::vector<int> RegisteredImages() const;
  // Back to no image registered and no point, each camera at its focal prior without distortion.
  void Reset();
};

}  // namespace reconar
