#include "core/sfm/next_image.h"

#include <algorithm>
#include <string>

#include "core/sfm/tag_image_registration.h"

namespace reconar {

namespace {

// For an image with tags that sees too few points for the ordinary registration: its visible
// points plus the corners of known tags that are no points yet, when its known tags can meet the
// tag rule (tag_image_registration.h); otherwise 0.
int TagVisible(const MapperModel& model, const std::vector<MapperImage>& images, int image, int visible,
               const MapperOptions& options) {
  if (static_cast<size_t>(image) >= images.size() || images[static_cast<size_t>(image)].tags.empty()) return 0;
  const std::vector<KnownTag> known = KnownTags(model, images, image, options);
  int tracked_corners = 0, derived_corners = 0;
  for (const KnownTag& tag : known) {
    for (int point : tag.points) (point >= 0 ? tracked_corners : derived_corners) += 1;
  }
  if (!TagsCanRegister(static_cast<int>(known.size()), visible - tracked_corners, options)) return 0;
  return visible + derived_corners;
}

}  // namespace

std::vector<NextImageCandidate> NextImageCandidates(MapperModel* model, const std::vector<MapperImage>& images,
                                                    const MapperOptions& options) {
  std::vector<NextImageCandidate> candidates;
  for (size_t i = 0; i < model->rec.images.size(); ++i) {
    if (model->rec.images[i].registered) continue;
    int visible = model->CountVisiblePoints(static_cast<int>(i));
    if (visible < options.registration_min_inliers) {
      const int by_tags = TagVisible(*model, images, static_cast<int>(i), visible, options);
      if (by_tags > 0) {
        if (by_tags > model->tried_with[i]) candidates.push_back({by_tags, static_cast<int>(i)});
        continue;
      }
    }
    if (visible == 0) continue;
    if (visible < options.registration_min_verified_inliers) {
      model->failure[i] = "sees only " + std::to_string(visible) + " reconstructed points (need " +
                          std::to_string(options.registration_min_verified_inliers) + ")";
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
