#pragma once
// The sparse model that structure from motion builds and every later stage reads: cameras
// (intrinsics), images (poses and 2D keypoints) and 3D points with their tracks.
//
// Conventions (DESIGN.md):
//  - Pixel coordinates have the centre of the top-left pixel at (0, 0), x right, y down (the
//    SIFT convention). COLMAP's files put that centre at (0.5, 0.5); model_io converts.
//  - A pose is cam_from_world: X_cam = R X_world + t, camera looking down +z, y down.
//  - The camera model is RadialCamera (core/math/radial_camera.h): Bundler's radial model with a
//    principal point and a pixel aspect ratio (COLMAP's RADIAL model when aspect = 1, OPENCV's otherwise).
#include <Eigen/Core>
#include <Eigen/Geometry>
#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "core/math/camera_intrinsics.h"
#include "core/math/radial_camera.h"
#include "core/math/rigid3.h"

namespace reconar {

// A camera of the model: the one camera model (focal, cx, cy, k1, k2, aspect; Project, Undistort)
// and the size of its images.
struct SfmCamera : RadialCamera {
  int width = 0;
  int height = 0;

  // The same camera as the tracker and renderer take it (the models agree: fy = aspect * focal).
  CameraIntrinsics Intrinsics() const {
    CameraIntrinsics intrinsics;
    intrinsics.width = width;
    intrinsics.height = height;
    intrinsics.fx = focal;
    intrinsics.fy = aspect * focal;
    intrinsics.cx = cx;
    intrinsics.cy = cy;
    intrinsics.k1 = k1;
    intrinsics.k2 = k2;
    return intrinsics;
  }
};

struct SfmImage {
  std::string name;    // file name, unique within the project (images.txt of the feature stage)
  int camera_id = -1;  // index into Reconstruction::cameras
  bool registered = false;
  Rigid3 cam_from_world;  // meaningful when registered

  // The projection centre in world coordinates.
  Eigen::Vector3d Center() const { return CameraCenterInWorld(cam_from_world); }
  std::vector<Eigen::Vector2d> keypoints;  // pixels
  std::vector<int> point3d_ids;            // per keypoint: index into Reconstruction::points, or -1
};

struct TrackElement {
  int image_id = -1;     // index into Reconstruction::images
  int keypoint_id = -1;  // index into SfmImage::keypoints
};

struct SfmPoint {
  Eigen::Vector3d position = Eigen::Vector3d::Zero();
  std::array<uint8_t, 3> color = {0, 0, 0};  // RGB
  double error = 0.0;                        // mean reprojection error over the track, pixels
  std::vector<TrackElement> track;
  bool deleted = false;  // removed points keep their slot so that ids stay stable; writers skip them
};

struct Reconstruction {
  std::vector<SfmCamera> cameras;
  std::vector<SfmImage> images;
  std::vector<SfmPoint> points;

  int NumRegisteredImages() const {
    int n = 0;
    for (const SfmImage& image : images) n += image.registered ? 1 : 0;
    return n;
  }
  int NumPoints() const {
    int n = 0;
    for (const SfmPoint& point : points) n += point.deleted ? 0 : 1;
    return n;
  }
};

}  // namespace reconar
