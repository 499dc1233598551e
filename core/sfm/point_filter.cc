#include "core/sfm/point_filter.h"

#include <cmath>

namespace reconar {

void FilterPoints(MapperModel* model, const std::vector<int>& point_ids, const MapperOptions& options) {
  constexpr double kDegree = M_PI / 180.0;
  for (int id : point_ids) {
    SfmPoint& point = model->rec.points[static_cast<size_t>(id)];
    if (point.deleted) continue;
    size_t kept = 0;
    for (const TrackElement& e : point.track) {
      if (model->SquaredError(point.position, e.image_id, e.keypoint_id) <=
          model->MaxSquaredError(e.image_id, e.keypoint_id, options)) {
        point.track[kept++] = e;
      } else {
        model->rec.images[static_cast<size_t>(e.image_id)].point3d_ids[static_cast<size_t>(e.keypoint_id)] = -1;
      }
    }
    point.track.resize(kept);
    if (kept < 2 || model->MaxTriangulationAngle(point) < options.min_triangulation_angle_deg * kDegree) {
      model->DeletePoint(id);
    }
  }
}

}  // namespace reconar
