// evaluate_sfm: accuracy of a sparse model (COLMAP text: ours or COLMAP's own) against ground
// truth, as JSON on stdout.
//
//   evaluate_sfm MODEL_DIR [--strecha GT_DIR | --middlebury-par FILE | --colmap-truth DIR]
//
// Images are matched to the ground truth by file name (the last path component of NAME in
// images.txt). Centre errors are in millimetres for Strecha (metres in its files) and in
// ground-truth units otherwise, after a 7-DoF similarity alignment of the camera centres.
// --colmap-truth reads the true cameras from a COLMAP text model (render_capture's OUT_DIR/truth).
// registered_fraction: the images matched to the truth over the truth's images.
// Exit codes: 0 ok, 1 fewer than 3 images matched (no alignment), 2 bad usage or input.
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <string>
#include <vector>

#include "core/sfm/model_io.h"
#include "tests/support/sfm_evaluation.h"

namespace reconar {
namespace {

using testing::CameraPose;
using testing::GroundTruthByName;
using testing::GroundTruthCamera;

int Usage(const char* message) {
  if (message != nullptr) std::fprintf(stderr, "evaluate_sfm: %s\n", message);
  std::fprintf(stderr,
               "usage: evaluate_sfm MODEL_DIR [--strecha GT_DIR | --middlebury-par FILE | --colmap-truth DIR]\n"
               "  MODEL_DIR  cameras.txt, images.txt, points3D.txt (COLMAP text)\n"
               "  --strecha GT_DIR          Strecha gt_cameras/ (or the dataset folder holding it)\n"
               "  --middlebury-par FILE     Middlebury *_par.txt\n"
               "  --colmap-truth DIR        the true cameras as a COLMAP text model (render_capture OUT_DIR/truth)\n");
  return 2;
}

// A JSON number, or null when it is not finite.
std::string Number(double value) {
  if (!std::isfinite(value)) return "null";
  char buffer[32];
  std::snprintf(buffer, sizeof(buffer), "%.6g", value);
  return buffer;
}

std::string Quoted(const std::string& text) {
  std::string out = "\"";
  for (const char c : text) {
    if (c == '"' || c == '\\') out += '\\';
    out += c;
  }
  return out + "\"";
}

struct ImageResult {
  std::string name;
  double focal = NAN;
  double gt_focal = NAN;
  double centre_error = NAN;
  double rotation_error_deg = NAN;
};

int Run(int argc, char** argv) {
  std::string model_dir, strecha_dir, par_file, colmap_truth_dir;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    if (arg == "--help" || arg == "-h") {
      Usage(nullptr);
      return 0;
    } else if (arg == "--strecha" && i + 1 < argc) {
      strecha_dir = argv[++i];
    } else if (arg == "--middlebury-par" && i + 1 < argc) {
      par_file = argv[++i];
    } else if (arg == "--colmap-truth" && i + 1 < argc) {
      colmap_truth_dir = argv[++i];
    } else if (!arg.empty() && arg[0] != '-' && model_dir.empty()) {
      model_dir = arg;
    } else {
      return Usage(("unexpected argument " + arg).c_str());
    }
  }
  if (model_dir.empty()) return Usage("missing MODEL_DIR");
  const int truths = static_cast<int>(!strecha_dir.empty()) + static_cast<int>(!par_file.empty()) +
                     static_cast<int>(!colmap_truth_dir.empty());
  if (truths > 1) return Usage("give one ground truth");

  Result<Reconstruction> model = ReadColmapTextModel(model_dir);
  if (!model.ok()) {
    std::fprintf(stderr, "evaluate_sfm: %s\n", model.status().ToString().c_str());
    return 2;
  }
  GroundTruthByName ground_truth;
  double unit_scale = 1.0;
  std::string unit = "gt_units";
  std::string gt_source;
  Result<GroundTruthByName> read = GroundTruthByName();
  if (!strecha_dir.empty()) {
    if (std::filesystem::is_directory(strecha_dir + "/gt_cameras")) strecha_dir += "/gt_cameras";
    read = testing::ReadStrechaGroundTruth(strecha_dir);
    unit_scale = 1000.0;
    unit = "mm";
    gt_source = strecha_dir;
  } else if (!par_file.empty()) {
    read = testing::ReadMiddleburyPar(par_file);
    gt_source = par_file;
  } else if (!colmap_truth_dir.empty()) {
    read = testing::ReadGroundTruthModel(colmap_truth_dir);
    gt_source = colmap_truth_dir;
  }
  if (!read.ok()) {
    std::fprintf(stderr, "evaluate_sfm: %s\n", read.status().ToString().c_str());
    return 2;
  }
  ground_truth = std::move(*read);

  // Points: file ERROR column and our own reprojection of every observation.
  double error_sum = 0.0;
  double reprojection_sum = 0.0;
  long num_observations = 0;
  for (const SfmPoint& point : model->points) {
    error_sum += point.error;
    for (const TrackElement& element : point.track) {
      const SfmImage& image = model->images[element.image_id];
      const SfmCamera& camera = model->cameras[image.camera_id];
      const Eigen::Vector2d projected = camera.Project(image.cam_from_world * point.position);
      reprojection_sum += (projected - image.keypoints[element.keypoint_id]).norm();
      ++num_observations;
    }
  }
  const double num_points = static_cast<double>(model->points.size());

  std::vector<ImageResult> images;
  std::vector<CameraPose> estimated, expected;
  std::vector<size_t> matched;  // index into images
  for (const SfmImage& image : model->images) {
    ImageResult result;
    result.name = std::filesystem::path(image.name).filename().string();
    result.focal = model->cameras[image.camera_id].focal;
    const auto gt = ground_truth.find(result.name);
    if (gt != ground_truth.end()) {
      const GroundTruthCamera& camera = gt->second;
      result.gt_focal = 0.5 * (camera.K(0, 0) + camera.K(1, 1));
      estimated.push_back({image.cam_from_world.rotation, image.Center()});
      expected.push_back(testing::PoseOf(camera));
      matched.push_back(images.size());
    }
    images.push_back(result);
  }
  double focal_ratio_sum = 0.0;
  for (const size_t i : matched) focal_ratio_sum += images[i].focal / images[i].gt_focal;

  testing::CameraPoseErrors errors;
  bool aligned = false;
  std::string alignment_error;
  if (!ground_truth.empty()) {
    Result<testing::CameraPoseErrors> found = testing::CameraCenterErrors(estimated, expected);
    if (found.ok()) {
      errors = std::move(*found);
      aligned = true;
      for (size_t k = 0; k < matched.size(); ++k) {
        images[matched[k]].centre_error = errors.centre_errors[k] * unit_scale;
        images[matched[k]].rotation_error_deg = errors.rotation_errors_deg[k];
      }
    } else {
      alignment_error = found.status().message();
    }
  }
  const double nan = NAN;
  const auto if_aligned = [&](double value) { return aligned ? value : nan; };

  std::printf("{\n");
  std::printf("  \"model\": %s,\n", Quoted(model_dir).c_str());
  std::printf("  \"ground_truth\": %s,\n", ground_truth.empty() ? "null" : Quoted(gt_source).c_str());
  std::printf("  \"registered\": %zu,\n", model->images.size());
  std::printf("  \"total\": %s,\n", ground_truth.empty() ? "null" : std::to_string(ground_truth.size()).c_str());
  std::printf("  \"matched\": %zu,\n", matched.size());
  const double registered_fraction = static_cast<double>(matched.size()) / ground_truth.size();
  std::printf("  \"registered_fraction\": %s,\n", ground_truth.empty() ? "null" : Number(registered_fraction).c_str());
  std::printf("  \"num_points\": %zu,\n", model->points.size());
  std::printf("  \"mean_track_length\": %s,\n", Number(num_observations / num_points).c_str());
  std::printf("  \"centre_error_unit\": %s,\n", Quoted(unit).c_str());
  std::printf("  \"centre_error_mean\": %s,\n", Number(if_aligned(errors.centre_mean * unit_scale)).c_str());
  std::printf("  \"centre_error_median\": %s,\n", Number(if_aligned(errors.centre_median * unit_scale)).c_str());
  std::printf("  \"centre_error_max\": %s,\n", Number(if_aligned(errors.centre_max * unit_scale)).c_str());
  std::printf("  \"rotation_error_mean_deg\": %s,\n", Number(if_aligned(errors.rotation_mean_deg)).c_str());
  std::printf("  \"rotation_error_max_deg\": %s,\n", Number(if_aligned(errors.rotation_max_deg)).c_str());
  std::printf("  \"relative_rotation_error_mean_deg\": %s,\n",
              Number(if_aligned(errors.relative_rotation_mean_deg)).c_str());
  std::printf("  \"alignment_scale\": %s,\n", Number(if_aligned(errors.gt_from_estimate.scale)).c_str());
  std::printf("  \"focal_ratio_mean\": %s,\n", Number(focal_ratio_sum / matched.size()).c_str());
  std::printf("  \"reprojection_error_mean\": %s,\n", Number(error_sum / num_points).c_str());
  std::printf("  \"reprojection_error_recomputed_mean\": %s,\n",
              Number(reprojection_sum / num_observations).c_str());
  if (!alignment_error.empty()) std::printf("  \"alignment_error\": %s,\n", Quoted(alignment_error).c_str());
  std::printf("  \"images\": [");
  for (size_t i = 0; i < images.size(); ++i) {
    const ImageResult& r = images[i];
    std::printf("%s\n    {\"name\": %s, \"focal\": %s, \"gt_focal\": %s, \"focal_ratio\": %s, \"centre_error\": %s, "
                "\"rotation_error_deg\": %s}",
                i == 0 ? "" : ",", Quoted(r.name).c_str(), Number(r.focal).c_str(), Number(r.gt_focal).c_str(),
                Number(r.focal / r.gt_focal).c_str(), Number(r.centre_error).c_str(),
                Number(r.rotation_error_deg).c_str());
  }
  std::printf("\n  ]\n}\n");
  return ground_truth.empty() || aligned ? 0 : 1;
}

}  // namespace
}  // namespace reconar

int main(int argc, char** argv) { return reconar::Run(argc, argv); }
