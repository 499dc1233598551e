#include "tests/dense/middlebury_import.h"

#include <Eigen/LU>
#include <cmath>
#include <filesystem>
#include <sstream>

#include "core/base/atomic_file.h"
#include "core/io/image_io.h"
#include "core/pipeline/project.h"
#include "core/sfm/model_io.h"

namespace reconar {
namespace testing {
namespace {

namespace fs = std::filesystem;

Status LineError(const std::string& path, int line, const std::string& reason) {
  return CorruptData(path + ":" + std::to_string(line) + ": " + reason);
}

}  // namespace

Result<std::vector<MiddleburyView>> ReadMiddleburyParameters(const std::string& par_path) {
  RECONAR_ASSIGN_OR_RETURN(const std::string text, ReadFileToString(par_path));
  std::istringstream in(text);
  std::string line;
  int line_number = 0;
  int expected = -1;
  std::vector<MiddleburyView> views;
  while (std::getline(in, line)) {
    ++line_number;
    if (line.find_first_not_of(" \t\r") == std::string::npos) continue;
    std::istringstream fields(line);
    if (expected < 0) {
      if (!(fields >> expected) || expected <= 0) return LineError(par_path, line_number, "expected the image count");
      continue;
    }
    MiddleburyView view;
    double v[21];
    if (!(fields >> view.name)) return LineError(par_path, line_number, "expected an image name");
    for (double& value : v) {
      if (!(fields >> value) || !std::isfinite(value)) {
        return LineError(par_path, line_number, "expected 21 numbers after the name (K, R, t)");
      }
    }
    std::string extra;
    if (fields >> extra) return LineError(par_path, line_number, "unexpected text after t: \"" + extra + "\"");
    for (int r = 0; r < 3; ++r) {
      for (int c = 0; c < 3; ++c) {
        view.k(r, c) = v[3 * r + c];
        view.pose.cam_from_world_rotation(r, c) = v[9 + 3 * r + c];
      }
      view.pose.cam_from_world_translation[r] = v[18 + r];
    }
    if (view.k(1, 0) != 0.0 || view.k(2, 0) != 0.0 || view.k(2, 1) != 0.0 || view.k(2, 2) != 1.0 ||
        !(view.k(0, 0) > 0.0) || !(view.k(1, 1) > 0.0)) {
      return LineError(par_path, line_number, "K must be upper triangular with positive focal lengths and k33 = 1");
    }
    if (view.k(0, 1) != 0.0) return Unsupported(par_path + ":" + std::to_string(line_number) + ": skewed K");
    const Eigen::Matrix3d& r = view.pose.cam_from_world_rotation;
    if ((r.transpose() * r - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff() > 1e-6 || r.determinant() < 0.0) {
      return LineError(par_path, line_number, "R is not a rotation");
    }
    views.push_back(std::move(view));
  }
  if (expected < 0) return CorruptData(par_path + ": empty file");
  if (static_cast<int>(views.size()) != expected) {
    return CorruptData(par_path + ": the header announces " + std::to_string(expected) + " images, the file has " +
                       std::to_string(views.size()));
  }
  return views;
}

Result<MiddleburyImportReport> ImportMiddleburyProject(const std::string& par_path, const std::string& project_dir,
                                                      const MiddleburyImportOptions& options) {
  if (options.view_stride < 1) return InvalidArgument("MiddleburyImportOptions: view_stride must be at least 1");
  RECONAR_ASSIGN_OR_RETURN(const std::vector<MiddleburyView> views, ReadMiddleburyParameters(par_path));
  const fs::path image_dir =
      fs::absolute(options.image_dir.empty() ? fs::path(par_path).parent_path() : fs::path(options.image_dir));

  Reconstruction model;
  std::vector<Eigen::Matrix3d> camera_ks;
  std::vector<ProjectImage> list;
  for (size_t i = 0; i < views.size(); i += options.view_stride) {
    const MiddleburyView& view = views[i];
    const std::string path = (image_dir / view.name).string();
    RECONAR_ASSIGN_OR_RETURN(const DecodedImage decoded, ReadImage(path));
    const int width = decoded.rgb.width();
    const int height = decoded.rgb.height();

    int camera_id = -1;
    for (size_t c = 0; c < camera_ks.size(); ++c) {
      if (camera_ks[c] == view.k && model.cameras[c].width == width && model.cameras[c].height == height) {
        camera_id = static_cast<int>(c);
      }
    }
    if (camera_id < 0) {
      SfmCamera camera;
      camera.width = width;
      camera.height = height;
      camera.focal = view.k(0, 0);
      camera.aspect = view.k(1, 1) / view.k(0, 0);
      camera.cx = view.k(0, 2);
      camera.cy = view.k(1, 2);
      camera_id = static_cast<int>(model.cameras.size());
      model.cameras.push_back(camera);
      camera_ks.push_back(view.k);
    }
    SfmImage image;
    image.name = view.name;
    image.camera_id = camera_id;
    image.registered = true;
    image.pose = view.pose;
    model.images.push_back(image);

    ProjectImage entry;
    entry.name = view.name;
    entry.path = path;
    entry.width = width;
    entry.height = height;
    entry.focal_px = view.k(0, 0);
    entry.focal_source = "ground-truth";
    list.push_back(entry);
  }

  const Project project(project_dir);
  RECONAR_RETURN_IF_ERROR(project.WriteImageList(list));
  RECONAR_RETURN_IF_ERROR(WriteColmapTextModel(model, project.SparseDir()));
  MiddleburyImportReport report;
  report.views = static_cast<int>(model.images.size());
  report.cameras = static_cast<int>(model.cameras.size());
  return report;
}

}  // namespace testing
}  // namespace reconar
