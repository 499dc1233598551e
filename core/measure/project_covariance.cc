#include "core/measure/project_covariance.h"

#include <filesystem>

#include "core/base/json_reader.h"
#include "core/features/sift/sift_io.h"
#include "core/sfm/mapper_adjustment.h"
#include "core/sfm/model_io.h"
#include "core/sfm/tag_observations.h"
#include "core/sfm/tag_registration.h"

namespace reconar {

Result<ProjectCovariance> ComputeProjectCovariance(const Project& project) {
  ProjectCovariance result;
  RECONAR_ASSIGN_OR_RETURN(result.model, ReadColmapTextModel(project.SparseDir()));
  RECONAR_ASSIGN_OR_RETURN(const JsonValue report, ReadJsonFile(project.SparseDir() + "/report.json"));
  const auto flag = [&](const char* key) {
    const JsonValue* value = report.Find(key);
    return value != nullptr && value->is_bool() && value->bool_value();
  };
  result.distortion_free = flag("distortion_refined");
  result.principal_point_free = flag("principal_point_refined");
  const Reconstruction& model = result.model;

  std::map<std::string, const std::vector<TagObservation>*> tags_of_image;
  TagDetectionsFile detections;
  std::error_code error;
  if (std::filesystem::exists(project.TagDetectionsPath(), error)) {
    RECONAR_ASSIGN_OR_RETURN(detections, ReadTagDetections(project.TagDetectionsPath()));
    for (const ImageTagObservations& image : detections.images) tags_of_image[image.image_name] = &image.tags;
  }

  RadialProblem problem;
  result.problem_camera.assign(model.images.size(), -1);
  result.problem_point.assign(model.points.size(), -1);
  for (size_t p = 0, next = 0; p < model.points.size(); ++p) {
    if (!model.points[p].deleted) result.problem_point[p] = static_cast<int>(next++);
  }
  std::vector<std::vector<float>> scales(model.images.size());
  BundleAdjustmentConstancy constancy;
  for (size_t i = 0; i < model.images.size(); ++i) {
    const SfmImage& image = model.images[i];
    if (!image.registered) continue;
    const int camera_index = problem.num_cameras();
    result.problem_camera[i] = camera_index;
    AppendCameraBlock(image, model.cameras[static_cast<size_t>(image.camera_id)], &problem);
    constancy.intrinsics_group.push_back(image.camera_id);
    RECONAR_ASSIGN_OR_RETURN(const FeatureFile features, ReadFeatureFile(project.MatchedFeaturePath(image.name)));
    for (const SiftKeypoint& keypoint : features.features.keypoints) scales[i].push_back(keypoint.scale);

    const auto tags = tags_of_image.find(image.name);
    if (tags == tags_of_image.end()) continue;
    for (const TagCornerKeypoint& corner :
         TagCornerKeypointsOfImage(static_cast<int>(i), *tags->second, static_cast<int>(scales[i].size()))) {
      const Eigen::Vector2d& pixel = corner.pixel;
      TagCornerInModel& in_model = result.tag_corners[{corner.tag_id, corner.corner}];
      in_model.observations.push_back({camera_index, -1, pixel.x(), pixel.y(), kTagCornerWeight});
      const auto keypoint = static_cast<size_t>(corner.keypoint_id);
      if (in_model.point < 0 && keypoint < image.point3d_ids.size() && image.point3d_ids[keypoint] >= 0) {
        in_model.point = result.problem_point[static_cast<size_t>(image.point3d_ids[keypoint])];
      }
    }
  }
  const MapperOptions mapper;
  for (size_t p = 0; p < model.points.size(); ++p) {
    const SfmPoint& point = model.points[p];
    if (point.deleted) continue;
    problem.points.insert(problem.points.end(), point.position.data(), point.position.data() + 3);
    for (const TrackElement& e : point.track) {
      const int camera_index = result.problem_camera[static_cast<size_t>(e.image_id)];
      if (camera_index < 0) continue;
      const Eigen::Vector2d& x =
          model.images[static_cast<size_t>(e.image_id)].keypoints[static_cast<size_t>(e.keypoint_id)];
      const std::vector<float>& image_scales = scales[static_cast<size_t>(e.image_id)];
      double weight = kTagCornerWeight;
      if (static_cast<size_t>(e.keypoint_id) < image_scales.size()) {
        weight = ScaleWeight(image_scales[static_cast<size_t>(e.keypoint_id)], mapper);
      } else {
        ++result.tag_corner_observations;
      }
      problem.observations.push_back({camera_index, result.problem_point[p], x.x(), x.y(), weight});
    }
  }
  result.observations = static_cast<int>(problem.observations.size());
  if (!result.distortion_free) constancy.constant_camera_parameters = {7, 8};
  if (!result.principal_point_free) {
    constancy.constant_camera_parameters.push_back(9);
    constancy.constant_camera_parameters.push_back(10);
  }
  if (!flag("aspect_refined")) constancy.constant_camera_parameters.push_back(11);
  RECONAR_ASSIGN_OR_RETURN(result.covariance, AdjustmentCovariance::Compute(problem, constancy));
  return result;
}

}  // namespace reconar
