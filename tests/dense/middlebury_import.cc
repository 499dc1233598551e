#include "tests/dense/middlebury_import.h"

#include <filesystem>

#include "core/base/atomic_file.h"
#include "core/io/image_io.h"
#include "core/pipeline/project.h"
#include "core/sfm/model_io.h"
#include "tests/support/sfm_evaluation.h"

namespace reconar {
namespace testing {
namespace fs = std::filesystem;

Result<MiddleburyImportReport> ImportMiddleburyProject(const std::string& par_path, const std::string& project_dir,
                                                      const MiddleburyImportOptions& options) {
  if (options.view_stride < 1) return InvalidArgument("MiddleburyImportOptions: view_stride must be at least 1");
  RECONAR_ASSIGN_OR_RETURN(const std::vector<NamedGroundTruthCamera> views, ReadMiddleburyParInOrder(par_path));
  const fs::path image_dir =
      fs::absolute(options.image_dir.empty() ? fs::path(par_path).parent_path() : fs::path(options.image_dir));

  Reconstruction model;
  std::vector<Eigen::Matrix3d> camera_ks;
  std::vector<ProjectImage> list;
  for (size_t i = 0; i < views.size(); i += options.view_stride) {
    const std::string& name = views[i].name;
    const GroundTruthCamera& truth = views[i].camera;
    const std::string path = (image_dir / name).string();
    RECONAR_ASSIGN_OR_RETURN(const DecodedImage decoded, ReadImage(path));
    const int width = decoded.rgb.width();
    const int height = decoded.rgb.height();

    int camera_id = -1;
    for (size_t c = 0; c < camera_ks.size(); ++c) {
      if (camera_ks[c] == truth.K && model.cameras[c].width == width && model.cameras[c].height == height) {
        camera_id = static_cast<int>(c);
      }
    }
    if (camera_id < 0) {
      SfmCamera camera;
      camera.width = width;
      camera.height = height;
      camera.focal = truth.K(0, 0);
      camera.aspect = truth.K(1, 1) / truth.K(0, 0);
      camera.cx = truth.K(0, 2);
      camera.cy = truth.K(1, 2);
      camera_id = static_cast<int>(model.cameras.size());
      model.cameras.push_back(camera);
      camera_ks.push_back(truth.K);
    }
    SfmImage image;
    image.name = name;
    image.camera_id = camera_id;
    image.registered = true;
    image.cam_from_world.rotation = truth.cam_from_world_rotation;
    image.cam_from_world.translation = truth.cam_from_world_translation;
    model.images.push_back(image);

    ProjectImage entry;
    entry.name = name;
    entry.path = path;
    entry.width = width;
    entry.height = height;
    entry.focal_px = truth.K(0, 0);
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
