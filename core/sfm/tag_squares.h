#pragma once
// Tags as rigid squares in the bundle adjustment. A printed tag is a square of one known edge;
// left to its four corners' tracks alone, a model's scale drifts from wall to wall (the room's odd
// photos: the tags on one wall came out 1.2 % large, on the opposite one 1.3 % small), and a
// measurement or a world frame taken from the tags inherits the drift.
//
// FindTagSquares gives each square tag whose four corners the model holds with the square of the
// square tags' mean edge that fits them best (Umeyama with fixed scale). The mapper's global adjustments
// add each as a frame block whose pose and edge (shared by every tag) are free, with the corners
// anchored to it (core/optim/bal_problem.h, PointAnchor): the corners stay a square of the common
// edge, to a standard deviation relative to it, while the square moves and turns with the cameras.
// Only the scale tags are squares: the others stay free to check the scale.
#include <array>
#include <vector>

#include <Eigen/Core>

#include "core/math/rigid3.h"
#include "core/sfm/mapper.h"
#include "core/sfm/reconstruction.h"
#include "core/sfm/tag_registration.h"

namespace reconar {

// A tag's corners in its own frame (tag_observations.h: kTagCornerUnits * edge / 2, z = 0).
std::array<Eigen::Vector3d, 4> TagSquareCorners(double edge);

// The model points that hold a tag's corners (-1 where none does).
struct TagCornerPoints {
  int tag_id = -1;
  std::array<int, 4> points = {-1, -1, -1, -1};
};

// Per tag seen in a registered image (by id), the point that most of each corner's keypoints in
// registered images belong to (deleted points do not count).
std::vector<TagCornerPoints> FindTagCornerPoints(const Reconstruction& rec,
                                                 const std::vector<TagCornerKeypoint>& corner_keypoints);

// The corner keypoints the images' MapperImage::tags describe.
std::vector<TagCornerKeypoint> CornerKeypointsOfImages(const std::vector<MapperImage>& images);

struct TagSquare {
  int tag_id = -1;
  std::array<int, 4> points = {-1, -1, -1, -1};  // model point ids, corner order of kTagCornerUnits
  Rigid3 world_from_tag;                         // the best-fitting square of the common edge
};

struct TagSquares {
  double edge = 0.0;  // the square tags' mean edge, model units
  std::vector<TagSquare> squares;
};

// The tags among `square_tags` (empty: every tag) whose corners are four distinct points.
TagSquares FindTagSquares(const Reconstruction& rec, const std::vector<TagCornerKeypoint>& corner_keypoints,
                          const std::vector<int>& square_tags);

}  // namespace reconar
