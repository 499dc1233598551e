#include "core/mvs/pmvs/pmvs_view.h"

namespace reconar {

PmvsView::PmvsView(const DenseView& view)
    : source(&view),
      width(view.gray.width()),
      height(view.gray.height()),
      gray(view.gray.data(), view.gray.data() + static_cast<size_t>(view.gray.width()) * view.gray.height()),
      projection(view.ProjectionMatrix()),
      world_from_cam_rotation(view.cam_from_world.rotation.transpose()),
      center(view.Center()),
      optical_axis(view.OpticalAxis().normalized()),
      fx(view.fx),
      fy(view.fy),
      cx(view.cx),
      cy(view.cy) {}

std::vector<std::vector<int>> NeighbourViews(const std::vector<PmvsView>& views, double max_angle) {
  const double min_cos = std::cos(max_angle);
  std::vector<std::vector<int>> neighbours(views.size());
  for (size_t i = 0; i < views.size(); ++i) {
    for (size_t j = 0; j < views.size(); ++j) {
      if (i == j) continue;
      if (views[i].optical_axis.dot(views[j].optical_axis) >= min_cos &&
          (views[i].center - views[j].center).norm() > 0.0) {
        neighbours[i].push_back(static_cast<int>(j));
      }
    }
  }
  return neighbours;
}

}  // namespace reconar
