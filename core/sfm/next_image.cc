#include "core/sfm/next_image.h"

#include <algorithm>
#include <string>

namespace reconar {

std::vector<NextImageCandidate> NextImageCandidates(MapperModel* model, const MapperOptions& options) {
  std::vector<NextImageCandidate> candidates;
  for (size_t i = 0; i < model->rec.images.size(); ++i) {
    if (model->rec.images[i].registered) continue;
    const int visible = model->CountVisiblePoints(static_cast<int>(i));
    if (visible == 0) continue;
    if (visible < options.registration_min_inliers) {
      model->failure[i] = "sees only " + std::to_string(visible) + " reconstructed points (need " +
                          std::to_string(options.registration_min_inliers) + ")";
      continue;
    }
    if (visible <= model->tried_with[i]) continue;  // failed before and nothing new is visible
    candidates.push_back({visible, static_cast<int>(i)});
  }
  std::stable_sort(candidates.begin(), candidates.end(),
                   [](const NextImageCandidate& x, const NextImageCandidate& y) { return x.visible > y.visible; });
  return candidates;
}

}  // namespace reconar
