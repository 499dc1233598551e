#pragma once
// The mapper's choice of the next image to register.
#include <vector>

#include "core/sfm/mapper.h"
#include "core/sfm/mapper_model.h"

namespace reconar {

struct NextImageCandidate {
  int visible = 0;  // keypoints whose track has a point
  int image = -1;
};

// The unregistered images to try next, the one seeing the most triangulated points first (ties
// by index). Images seeing none are skipped; those seeing fewer than
// MapperOptions::registration_min_inliers are skipped with the reason in model->failure; those
// that failed before (model->tried_with) and see no more points than then are skipped. An image
// with tags (MapperImage::tags) that sees too few points is a candidate when the tags the model
// holds can register it (tag_image_registration.h); its `visible` then also counts their corners
// that are no points yet.
std::vector<NextImageCandidate> NextImageCandidates(MapperModel* model, const std::vector<MapperImage>& images,
                                                    const MapperOptions& options);

}  // namespace reconar
