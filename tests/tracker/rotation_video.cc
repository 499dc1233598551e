#include "tests/tracker/rotation_video.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>

#include "core/base/prng.h"
#include "core/features/sift/sift.h"
#include "core/io/gray.h"
#include "core/io/image_io.h"
#include "core/sfm/reconstruction.h"

namespace reconar::testing {

Result<RotationScene> MakeRotationScene(const std::string& path, int downscale, int width, int height,
                                        double focal_factor) {
  if (downscale < 1) return InvalidArgument("MakeRotationScene: downscale must be >= 1");
  RECONAR_ASSIGN_OR_RETURN(const DecodedImage decoded, ReadImage(path));
  const Image<uint8_t> gray = ToGray8(decoded.rgb);
  RotationScene scene;
  const int pw = gray.width() / downscale, ph = gray.height() / downscale;
  if (pw < 16 || ph < 16) return InvalidArgument(path + ": too small for the downscale");
  scene.photo = Image<uint8_t>(pw, ph);
  const double area = static_cast<double>(downscale) * downscale;
  for (int y = 0; y < ph; ++y) {
    for (int x = 0; x < pw; ++x) {
      int sum = 0;
      for (int j = 0; j < downscale; ++j) {
        const uint8_t* row = gray.row(y * downscale + j) + x * downscale;
        for (int i = 0; i < downscale; ++i) sum += row[i];
      }
      scene.photo.row(y)[x] = static_cast<uint8_t>(std::lround(sum / area));
    }
  }
  const double focal = focal_factor * std::max(pw, ph);
  scene.photo_camera.width = pw;
  scene.photo_camera.height = ph;
  scene.photo_camera.fx = scene.photo_camera.fy = focal;
  scene.photo_camera.cx = 0.5 * (pw - 1);
  scene.photo_camera.cy = 0.5 * (ph - 1);
  scene.frame_camera = scene.photo_camera;
  scene.frame_camera.width = width;
  scene.frame_camera.height = height;
  scene.frame_camera.cx = 0.5 * (width - 1);
  scene.frame_camera.cy = 0.5 * (height - 1);
  scene.photo_cam_from_world.rotation =
      Eigen::AngleAxisd(0.7, Eigen::Vector3d(0.3, -1.0, 0.2).normalized()).toRotationMatrix();
  scene.photo_cam_from_world.translation = Eigen::Vector3d(0.4, -0.25, 1.5);
  return scene;
}

Image<uint8_t> RenderRotatedView(const RotationScene& scene, const Eigen::Matrix3d& rotation) {
  const CameraIntrinsics& f = scene.frame_camera;
  const RadialCamera photo_camera = scene.photo_camera.Camera();
  const bool distorted = scene.photo_camera.k1 != 0.0 || scene.photo_camera.k2 != 0.0;
  Eigen::Matrix3d k_frame_inverse;
  k_frame_inverse << 1.0 / f.fx, 0, -f.cx / f.fx, 0, 1.0 / f.fy, -f.cy / f.fy, 0, 0, 1;
  Eigen::Matrix3d k_photo;
  k_photo << photo_camera.focal, 0, photo_camera.cx, 0, photo_camera.fy(), photo_camera.cy, 0, 0, 1;
  // The ray of frame pixel x in the photo camera's frame: R^T K_frame^-1 x (the frame camera is
  // taken as a pinhole); a pinhole photo maps it by K_photo (a homography), a distorted one through
  // its radial model.
  const Eigen::Matrix3d photo_ray = rotation.transpose() * k_frame_inverse;
  const Eigen::Matrix3d h = k_photo * photo_ray;
  Image<uint8_t> frame(f.width, f.height);
  const int pw = scene.photo.width(), ph = scene.photo.height();
  for (int y = 0; y < f.height; ++y) {
    uint8_t* out = frame.row(y);
    for (int x = 0; x < f.width; ++x) {
      out[x] = 128;
      double sx = 0.0, sy = 0.0;
      if (distorted) {
        const Eigen::Vector3d ray = photo_ray * Eigen::Vector3d(x, y, 1.0);
        if (!(ray.z() > 0.0)) continue;
        const Eigen::Vector2d s = photo_camera.Project(ray);
        sx = s.x();
        sy = s.y();
      } else {
        const Eigen::Vector3d s = h * Eigen::Vector3d(x, y, 1.0);
        if (!(s.z() > 0.0)) continue;
        sx = s.x() / s.z();
        sy = s.y() / s.z();
      }
      if (!(sx >= 0.0 && sy >= 0.0 && sx <= pw - 1 && sy <= ph - 1)) continue;
      const int x0 = std::min(static_cast<int>(sx), pw - 2), y0 = std::min(static_cast<int>(sy), ph - 2);
      const double ax = sx - x0, ay = sy - y0;
      const uint8_t* r0 = scene.photo.row(y0) + x0;
      const uint8_t* r1 = scene.photo.row(y0 + 1) + x0;
      const double v = (1 - ay) * ((1 - ax) * r0[0] + ax * r0[1]) + ay * ((1 - ax) * r1[0] + ax * r1[1]);
      out[x] = static_cast<uint8_t>(std::clamp(std::lround(v), 0L, 255L));
    }
  }
  return frame;
}

Rigid3 RotatedViewPose(const RotationScene& scene, const Eigen::Matrix3d& rotation) {
  return Rigid3{rotation, Eigen::Vector3d::Zero()} * scene.photo_cam_from_world;
}

Eigen::Matrix3d YawPitchRoll(double yaw_deg, double pitch_deg, double roll_deg) {
  const double d = M_PI / 180.0;
  return (Eigen::AngleAxisd(yaw_deg * d, Eigen::Vector3d::UnitY()) *
          Eigen::AngleAxisd(pitch_deg * d, Eigen::Vector3d::UnitX()) *
          Eigen::AngleAxisd(roll_deg * d, Eigen::Vector3d::UnitZ()))
      .toRotationMatrix();
}

Result<LocalizationMap> BuildRotationSceneMap(const RotationScene& scene,
                                              const std::vector<Eigen::Matrix3d>& keyframe_rotations, double min_depth,
                                              double max_depth) {
  Reconstruction model;
  SfmCamera camera;
  static_cast<RadialCamera&>(camera) = scene.frame_camera.Camera();
  camera.width = scene.frame_camera.width;
  camera.height = scene.frame_camera.height;
  model.cameras.push_back(camera);
  std::vector<std::vector<uint8_t>> descriptors;
  SiftExtractor extractor(SiftOptions{});
  SplitMix64 random(0x524f5441ull);
  for (size_t k = 0; k < keyframe_rotations.size(); ++k) {
    const Image<uint8_t> frame = RenderRotatedView(scene, keyframe_rotations[k]);
    Image<float> gray(frame.width(), frame.height());
    for (int y = 0; y < frame.height(); ++y) {
      for (int x = 0; x < frame.width(); ++x) gray.row(y)[x] = frame.row(y)[x] / 255.0f;
    }
    RECONAR_ASSIGN_OR_RETURN(SiftFeatures features, extractor.Extract(gray.view()));
    SfmImage image;
    image.name = "keyframe" + std::to_string(k) + ".png";
    image.camera_id = 0;
    image.registered = true;
    image.cam_from_world = RotatedViewPose(scene, keyframe_rotations[k]);
    const Rigid3 world_from_cam = image.cam_from_world.Inverse();
    for (size_t i = 0; i < features.keypoints.size(); ++i) {
      const Eigen::Vector2d pixel(features.keypoints[i].x, features.keypoints[i].y);
      const Eigen::Vector2d normalised = scene.frame_camera.Unproject(pixel);
      const double depth = random.Uniform(min_depth, max_depth);
      SfmPoint point;
      point.position = world_from_cam * (depth * Eigen::Vector3d(normalised.x(), normalised.y(), 1.0));
      point.track.push_back({static_cast<int>(k), static_cast<int>(i)});
      image.keypoints.push_back(pixel);
      image.point3d_ids.push_back(static_cast<int>(model.points.size()));
      model.points.push_back(point);
    }
    model.images.push_back(std::move(image));
    descriptors.push_back(std::move(features.descriptors));
  }
  MapBuildOptions options;
  options.vocabulary.branching = 8;
  options.vocabulary.depth = 3;
  const auto loader = [&](const SfmImage& image) -> Result<std::vector<uint8_t>> {
    for (size_t k = 0; k < model.images.size(); ++k) {
      if (model.images[k].name == image.name) return descriptors[k];
    }
    return NotFound(image.name);
  };
  return BuildLocalizationMap(model, loader, "arbitrary", false, options);
}

}  // namespace reconar::testing
