#pragma once
// Registration of an image from a registered neighbour's two-view geometry, for chains of views
// whose tracks rarely reach a third image (a sparse ring around a texture-poor object, a walk
// forward down a street): too few of the image's keypoints see model points for an absolute pose,
// but its verified matches to a registered neighbour are many. The pair's essential matrix
// (pair_pose.h) gives the image's rotation and the direction of the baseline; the few model
// points the image does see fix the baseline's length: each point proposes a length, and the one
// the most points agree with (within MapperOptions::registration_max_error_px) is refined on them.
// The pose needs MapperOptions::registration_min_baseline_points such points, and it must put the
// image's matches to the other registered images on their epipolar lines (two_view_check.h).
#include <vector>

#include "core/sfm/mapper.h"
#include "core/sfm/mapper_model.h"

namespace reconar {

// The unregistered images to try in that way, best first: those with a verified pair to a
// registered image, by the size of their best such pair; images whose visible points have not
// grown since their last failed attempt (`tried_with`, per image) are left out.
std::vector<int> NeighbourRegistrationCandidates(const MapperModel& model, const std::vector<MapperPair>& pairs,
                                                 const std::vector<int>& tried_with);

// Registers `image` from the best of its registered neighbours that gives a pose meeting the rule
// above (the neighbours by the size of their verified pair). Needs the image's camera focal
// confirmed (three registered images, or MapperOptions::refine_focal off). False, with the reason
// in model->failure[image], when none does.
bool RegisterImageFromNeighbour(MapperModel* model, const std::vector<MapperPair>& pairs, int image,
                                const MapperOptions& options);

}  // namespace reconar
