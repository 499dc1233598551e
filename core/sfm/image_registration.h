#pragma once
// Registration of one image into the mapper's model: its 2D-3D correspondences (keypoints whose
// track has a point), the absolute pose (P3P in LO-RANSAC, the focal free and the DLT as a
// fallback while the camera's focal is unconfirmed), and the inlier observations added.
#include <utility>
#include <vector>

#include "core/sfm/mapper.h"
#include "core/sfm/mapper_model.h"

namespace reconar {

// Intrinsics guess for an image about to be registered: its camera when that camera is in use or
// has an EXIF focal, otherwise the mean of the registered cameras of the same size without EXIF
// (the same device, most likely), otherwise the prior.
SfmCamera GuessCamera(const MapperModel& model, int image);

// Marks `image` registered at cam_from_world with its observations (keypoint, point id) of
// existing points, and clears its failure.
void AcceptRegistration(MapperModel* model, int image, const Rigid3& cam_from_world,
                        const std::vector<std::pair<int, int>>& observations);

// Registers `image`; false, with the reason in model->failure[image], when no pose is found.
// *focal_changed tells whether the registration set its camera's focal (the camera was not yet
// confirmed by three images), after which the caller adjusts globally. *num_inliers, when given,
// is the absolute pose's inlier count (0 for a registration by tags): under
// MapperOptions::registration_min_inliers the registration is provisional
// (provisional_registration.h). An image with tags that fails may still register by them
// (tag_image_registration.h).
bool RegisterImage(MapperModel* model, const std::vector<MapperImage>& images, int image, const MapperOptions& options,
                   bool* focal_changed, int* num_inliers = nullptr);

}  // namespace reconar
