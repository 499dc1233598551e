#pragma once
// The rendered textured box (tests/core/mvs/pmvs/textured_box_scene.h) as photos of a project,
// for the command-line tests against exact truth (measure, compare): the views written as PNG,
// the registered images matched to their views, the sparse points paired with their true positions
// and a scene point picked by its exact pixels in two photos. Test support only.
#include <string>
#include <vector>

#include <Eigen/Core>

#include "core/base/status.h"
#include "core/sfm/reconstruction.h"
#include "tests/core/mvs/pmvs/textured_box_scene.h"

namespace reconar::testing {

// view_NN.png
std::string RenderedViewName(size_t index);

// Every view of the scene as IMAGES_DIR/view_NN.png (the directory is created).
Status WriteRenderedViews(const TexturedBoxScene& scene, const std::string& images_dir);

// Per image of the model, the index of its view in the scene; -1 when it is not registered.
std::vector<int> ViewOfImage(const TexturedBoxScene& scene, const Reconstruction& model);

// The model's sparse points (tracks of two or more registered views) with their true positions:
// the same observations triangulated with the views' true cameras.
void TrueSparsePoints(const TexturedBoxScene& scene, const Reconstruction& model, const std::vector<int>& view_of_image,
                      std::vector<Eigen::Vector3d>* model_points, std::vector<Eigen::Vector3d>* true_points);

// Scene point x as `reconar measure` takes a point seen in two photos ("A.png@x,y+B.png@x,y"): its
// exact pixels in the two registered views that see it at the widest angle, at least `margin_px`
// inside their frames; empty when fewer than two see it.
std::string WidestPick(const TexturedBoxScene& scene, const Reconstruction& model, const std::vector<int>& view_of_image,
                       const Eigen::Vector3d& x, double margin_px = 10.0);

}  // namespace reconar::testing
