#include "tests/support/sfm_evaluation.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <numeric>
#include <sstream>

#include "core/base/atomic_file.h"
#include "core/sfm/model_io.h"

namespace reconar::testing {

double Median(std::vector<double> values) {
  if (values.empty()) return 0.0;
  const size_t mid = values.size() / 2;
  std::nth_element(values.begin(), values.begin() + mid, values.end());
  if (values.size() % 2 == 1) return values[mid];
  return 0.5 * (values[mid] + *std::max_element(values.begin(), values.begin() + mid));
}

double Quantile(std::vector<double> values, double q) {
  if (values.empty()) return std::nan("");
  std::sort(values.begin(), values.end());
  return values[std::min(values.size() - 1, static_cast<size_t>(q * static_cast<double>(values.size())))];
}

// atan2(|sin|, cos) from the skew and symmetric parts: accurate for small angles, where
// acos((trace - 1) / 2) loses half the digits.
double RotationAngleDeg(const Eigen::Matrix3d& a, const Eigen::Matrix3d& b) {
  const Eigen::Matrix3d rotation = a * b.transpose();
  const Eigen::Vector3d axis_sin(rotation(2, 1) - rotation(1, 2), rotation(0, 2) - rotation(2, 0),
                                 rotation(1, 0) - rotation(0, 1));
  return std::atan2(0.5 * axis_sin.norm(), 0.5 * (rotation.trace() - 1.0)) * 180.0 / M_PI;
}

namespace {

double Mean(const std::vector<double>& values) {
  return values.empty() ? 0.0 : std::accumulate(values.begin(), values.end(), 0.0) / values.size();
}

double Max(const std::vector<double>& values) {
  return values.empty() ? 0.0 : *std::max_element(values.begin(), values.end());
}

}  // namespace

CameraPose PoseOf(const GroundTruthCamera& camera) { return {camera.cam_from_world_rotation, camera.Centre()}; }

Result<ModelScore> ScoreModelAgainstTruth(const std::string& model_dir, const GroundTruthByName& truth,
                                          const std::function<std::string(const std::string&)>& truth_name) {
  RECONAR_ASSIGN_OR_RETURN(const Reconstruction model, ReadColmapTextModel(model_dir));
  ModelScore score;
  std::vector<CameraPose> estimated, reference;
  for (const SfmImage& image : model.images) {
    if (!image.registered) continue;
    ++score.registered;
    const auto gt = truth.find(truth_name(image.name));
    if (gt == truth.end()) return NotFound(model_dir + ": " + image.name + " has no ground truth");
    estimated.push_back({image.cam_from_world.rotation, image.Center()});
    reference.push_back(PoseOf(gt->second));
  }
  RECONAR_ASSIGN_OR_RETURN(score.errors, CameraCenterErrors(estimated, reference));
  return score;
}

Result<CameraPoseErrors> CameraCenterErrors(const std::vector<CameraPose>& estimated,
                                            const std::vector<CameraPose>& ground_truth) {
  if (estimated.size() != ground_truth.size()) return InvalidArgument("CameraCenterErrors: camera lists differ in size");
  std::vector<Eigen::Vector3d> from;
  std::vector<Eigen::Vector3d> to;
  for (size_t i = 0; i < estimated.size(); ++i) {
    from.push_back(estimated[i].centre);
    to.push_back(ground_truth[i].centre);
  }
  CameraPoseErrors errors;
  RECONAR_ASSIGN_OR_RETURN(errors.gt_from_estimate, AlignSimilarity(from, to));
  const Similarity3& similarity = errors.gt_from_estimate;
  for (size_t i = 0; i < estimated.size(); ++i) {
    errors.centre_errors.push_back((similarity.Apply(from[i]) - to[i]).norm());
    // The estimate's camera in the ground-truth world: cam_from_gt = cam_from_estimate * estimate_from_gt.
    const Eigen::Matrix3d cam_from_gt = estimated[i].cam_from_world_rotation * similarity.rotation.transpose();
    errors.rotation_errors_deg.push_back(
        RotationAngleDeg(cam_from_gt, ground_truth[i].cam_from_world_rotation));
  }
  errors.centre_mean = Mean(errors.centre_errors);
  errors.centre_median = Median(errors.centre_errors);
  errors.centre_max = Max(errors.centre_errors);
  errors.rotation_mean_deg = Mean(errors.rotation_errors_deg);
  errors.rotation_median_deg = Median(errors.rotation_errors_deg);
  errors.rotation_max_deg = Max(errors.rotation_errors_deg);
  std::vector<double> relative_errors;
  for (size_t i = 0; i < estimated.size(); ++i) {
    for (size_t j = i + 1; j < estimated.size(); ++j) {
      const Eigen::Matrix3d estimated_i_from_j =
          estimated[i].cam_from_world_rotation * estimated[j].cam_from_world_rotation.transpose();
      const Eigen::Matrix3d true_i_from_j =
          ground_truth[i].cam_from_world_rotation * ground_truth[j].cam_from_world_rotation.transpose();
      relative_errors.push_back(RotationAngleDeg(estimated_i_from_j, true_i_from_j));
    }
  }
  errors.relative_rotation_mean_deg = Mean(relative_errors);
  return errors;
}

Status WriteGroundTruthModel(const GroundTruthByName& truth, const std::string& dir) {
  Reconstruction model;
  for (const auto& [name, camera] : truth) {
    const Eigen::Matrix3d& k = camera.K;
    if (k(0, 1) != 0.0) return InvalidArgument(dir + ": " + name + " has a skewed K");
    SfmCamera model_camera;
    model_camera.width = camera.width;
    model_camera.height = camera.height;
    model_camera.focal = k(0, 0);
    model_camera.aspect = k(1, 1) / k(0, 0);
    model_camera.cx = k(0, 2);
    model_camera.cy = k(1, 2);
    const auto same = [&model_camera](const SfmCamera& other) {
      return other.width == model_camera.width && other.height == model_camera.height &&
             other.focal == model_camera.focal && other.aspect == model_camera.aspect && other.cx == model_camera.cx &&
             other.cy == model_camera.cy;
    };
    const auto found = std::find_if(model.cameras.begin(), model.cameras.end(), same);
    SfmImage image;
    image.name = name;
    image.camera_id = static_cast<int>(found - model.cameras.begin());
    if (found == model.cameras.end()) model.cameras.push_back(model_camera);
    image.registered = true;
    image.cam_from_world.rotation = camera.cam_from_world_rotation;
    image.cam_from_world.translation = camera.cam_from_world_translation;
    model.images.push_back(std::move(image));
  }
  return WriteColmapTextModel(model, dir);
}

Result<GroundTruthByName> ReadGroundTruthModel(const std::string& dir) {
  RECONAR_ASSIGN_OR_RETURN(const Reconstruction model, ReadColmapTextModel(dir));
  GroundTruthByName truth;
  for (const SfmImage& image : model.images) {
    const SfmCamera& camera = model.cameras[static_cast<size_t>(image.camera_id)];
    if (camera.k1 != 0.0 || camera.k2 != 0.0) {
      return Unsupported(dir + "/cameras.txt: camera " + std::to_string(image.camera_id + 1) +
                         " has distortion; ground truth is a pinhole");
    }
    GroundTruthCamera& truth_camera = truth[std::filesystem::path(image.name).filename().string()];
    truth_camera.K << camera.focal, 0.0, camera.cx, 0.0, camera.fy(), camera.cy, 0.0, 0.0, 1.0;
    truth_camera.cam_from_world_rotation = image.cam_from_world.rotation;
    truth_camera.cam_from_world_translation = image.cam_from_world.translation;
    truth_camera.width = camera.width;
    truth_camera.height = camera.height;
  }
  return truth;
}

Result<GroundTruthByName> ReadStrechaGroundTruth(const std::string& dir) {
  namespace fs = std::filesystem;
  std::error_code ec;
  fs::directory_iterator entries(dir, ec);
  if (ec) return FileError(StatusCode::kNotFound, dir, "cannot list directory: " + ec.message());
  GroundTruthByName cameras;
  for (const fs::directory_entry& entry : entries) {
    if (entry.path().extension() != ".camera") continue;
    RECONAR_ASSIGN_OR_RETURN(GroundTruthCamera camera, ReadStrechaCamera(entry.path().string()));
    cameras.emplace(entry.path().stem().string(), camera);
  }
  if (cameras.empty()) return FileError(StatusCode::kNotFound, dir, "no *.camera files");
  return cameras;
}

Result<std::vector<NamedGroundTruthCamera>> ReadMiddleburyParInOrder(const std::string& path) {
  RECONAR_ASSIGN_OR_RETURN(const std::string text, ReadFileToString(path));
  const auto line_error = [&path](int line, const std::string& reason) {
    return CorruptData(path + ":" + std::to_string(line) + ": " + reason);
  };
  std::istringstream in(text);
  std::string line;
  int line_number = 0;
  int expected = -1;
  std::vector<NamedGroundTruthCamera> cameras;
  while (std::getline(in, line)) {
    ++line_number;
    if (line.find_first_not_of(" \t\r") == std::string::npos) continue;
    std::istringstream fields(line);
    if (expected < 0) {
      if (!(fields >> expected) || expected <= 0) return line_error(line_number, "expected the image count");
      continue;
    }
    NamedGroundTruthCamera named;
    double v[21];
    if (!(fields >> named.name)) return line_error(line_number, "expected an image name");
    for (double& value : v) {
      if (!(fields >> value) || !std::isfinite(value)) {
        return line_error(line_number, "expected 21 numbers after the name (K, R, t)");
      }
    }
    std::string extra;
    if (fields >> extra) return line_error(line_number, "unexpected text after t: \"" + extra + "\"");
    GroundTruthCamera& camera = named.camera;
    camera.K << v[0], v[1], v[2], v[3], v[4], v[5], v[6], v[7], v[8];
    camera.cam_from_world_rotation << v[9], v[10], v[11], v[12], v[13], v[14], v[15], v[16], v[17];
    camera.cam_from_world_translation << v[18], v[19], v[20];
    const Eigen::Matrix3d& k = camera.K;
    if (k(1, 0) != 0.0 || k(2, 0) != 0.0 || k(2, 1) != 0.0 || k(2, 2) != 1.0 || !(k(0, 0) > 0.0) || !(k(1, 1) > 0.0)) {
      return line_error(line_number, "K must be upper triangular with positive focal lengths and k33 = 1");
    }
    if (k(0, 1) != 0.0) return Unsupported(path + ":" + std::to_string(line_number) + ": skewed K");
    Eigen::Matrix3d& r = camera.cam_from_world_rotation;
    if ((r.transpose() * r - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff() > 1e-5 || r.determinant() < 0.0) {
      return line_error(line_number, "R is not a rotation");
    }
    // Printed to a few digits (dinoSparseRing's are 1.4e-6 off): the nearest rotation.
    const Eigen::JacobiSVD<Eigen::Matrix3d> svd(r, Eigen::ComputeFullU | Eigen::ComputeFullV);
    r = svd.matrixU() * svd.matrixV().transpose();
    cameras.push_back(std::move(named));
  }
  if (expected < 0) return CorruptData(path + ": empty file");
  if (static_cast<int>(cameras.size()) != expected) {
    return CorruptData(path + ": the header announces " + std::to_string(expected) + " images, the file has " +
                       std::to_string(cameras.size()));
  }
  return cameras;
}

Result<GroundTruthByName> ReadMiddleburyPar(const std::string& path) {
  RECONAR_ASSIGN_OR_RETURN(std::vector<NamedGroundTruthCamera> in_order, ReadMiddleburyParInOrder(path));
  GroundTruthByName cameras;
  for (NamedGroundTruthCamera& named : in_order) cameras.emplace(std::move(named.name), named.camera);
  return cameras;
}

}  // namespace reconar::testing
