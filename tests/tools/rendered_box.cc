#include "tests/tools/rendered_box.h"

#include <cstdio>
#include <filesystem>
#include <sstream>

#include "core/geometry/triangulation.h"
#include "core/io/image_write.h"

namespace reconar::testing {

std::string RenderedViewName(size_t index) {
  char name[32];
  std::snprintf(name, sizeof(name), "view_%02zu.png", index);
  return name;
}

Status WriteRenderedViews(const TexturedBoxScene& scene, const std::string& images_dir) {
  std::error_code error;
  std::filesystem::create_directories(images_dir, error);
  if (error) return IoError(images_dir + ": " + error.message());
  for (size_t i = 0; i < scene.views().size(); ++i) {
    RECONAR_RETURN_IF_ERROR(WritePng(images_dir + "/" + RenderedViewName(i), scene.views()[i].rgb.view(), 3));
  }
  return Status::Ok();
}

std::vector<int> ViewOfImage(const TexturedBoxScene& scene, const Reconstruction& model) {
  std::vector<int> view_of_image(model.images.size(), -1);
  for (size_t m = 0; m < model.images.size(); ++m) {
    for (size_t i = 0; i < scene.views().size(); ++i) {
      if (model.images[m].registered && model.images[m].name == RenderedViewName(i)) view_of_image[m] = static_cast<int>(i);
    }
  }
  return view_of_image;
}

void TrueSparsePoints(const TexturedBoxScene& scene, const Reconstruction& model, const std::vector<int>& view_of_image,
                      std::vector<Eigen::Vector3d>* model_points, std::vector<Eigen::Vector3d>* true_points) {
  for (const SfmPoint& point : model.points) {
    if (point.deleted || point.track.size() < 2) continue;
    std::vector<TriangulationView> views;
    for (const TrackElement& e : point.track) {
      const int v = view_of_image[static_cast<size_t>(e.image_id)];
      if (v < 0) continue;
      const DenseView& view = scene.views()[static_cast<size_t>(v)];
      const Eigen::Vector2d& pixel =
          model.images[static_cast<size_t>(e.image_id)].keypoints[static_cast<size_t>(e.keypoint_id)];
      views.push_back(
          {view.cam_from_world, Eigen::Vector2d((pixel.x() - view.cx) / view.fx, (pixel.y() - view.cy) / view.fy), view.fx});
    }
    Eigen::Vector3d truth;
    if (views.size() < 2 || !TriangulateMultiView(views, &truth)) continue;
    model_points->push_back(point.position);
    true_points->push_back(truth);
  }
}

std::string WidestPick(const TexturedBoxScene& scene, const Reconstruction& model, const std::vector<int>& view_of_image,
                       const Eigen::Vector3d& x, double margin_px) {
  std::vector<size_t> seeing;
  for (size_t m = 0; m < model.images.size(); ++m) {
    if (view_of_image[m] < 0) continue;
    const DenseView& view = scene.views()[static_cast<size_t>(view_of_image[m])];
    const Eigen::Vector2d pixel = view.Project(x);
    if (scene.Sees(view, x) && pixel.x() > margin_px && pixel.y() > margin_px &&
        pixel.x() < view.width() - margin_px && pixel.y() < view.height() - margin_px) {
      seeing.push_back(m);
    }
  }
  double widest = 0.0;
  std::string pick;
  for (size_t a = 0; a < seeing.size(); ++a) {
    for (size_t b = a + 1; b < seeing.size(); ++b) {
      const DenseView& va = scene.views()[static_cast<size_t>(view_of_image[seeing[a]])];
      const DenseView& vb = scene.views()[static_cast<size_t>(view_of_image[seeing[b]])];
      const double angle = TriangulationAngle(va.Center(), vb.Center(), x);
      if (angle <= widest) continue;
      widest = angle;
      std::ostringstream text;
      text.precision(10);
      text << model.images[seeing[a]].name << "@" << va.Project(x).x() << "," << va.Project(x).y() << "+"
           << model.images[seeing[b]].name << "@" << vb.Project(x).x() << "," << vb.Project(x).y();
      pick = text.str();
    }
  }
  return pick;
}

}  // namespace reconar::testing
