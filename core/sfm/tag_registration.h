#pragma once
// Metric registration of a reconstruction by AprilTags of known size (the paper's sections 2.4.3
// and 3.4: the markers give the model absolute scale and the frame it is shown in).
//
// AddTagCorrespondences gives the mapper each tag corner as a keypoint and every pair of images
// that see the same tag its four corner matches, so that the corners become tracks: they help
// register images of texture-poor surfaces (the paper's Fig. 12) and bundle adjustment refines
// them with every other point.
//
// RegisterToTags then finds each tag's four corners in the model (the adjusted track, or a
// triangulation from the registered views when the mapper kept none), takes the scale from the
// mean edge of the scale tags (every complete tag unless scale_tags names some: the others then
// check it), and moves the model into the frame of the world tag (tag frame: origin at its
// centre, x right, y up, z out of the printed tag; metres): world_from_model is the similarity
// with that scale whose rotation and translation fit the world tag's corners to their ideal places
// (Umeyama with fixed scale). Those corners are the world tag as a rigid square of that edge whose
// pose best reprojects into every registered view of it (its four corner points only start the
// fit and stay when the square does not fit within max_reprojection_error_px rms): four corners
// triangulated each on its own tilt the frame by their depth errors, which the cameras metres away
// turn into centimetres.
#include <array>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "core/base/status.h"
#include "core/math/rigid3.h"
#include "core/math/sim3.h"
#include "core/sfm/mapper.h"
#include "core/sfm/reconstruction.h"
#include "core/sfm/tag_layout.h"
#include "core/sfm/tag_observations.h"

namespace reconar {

// Where AddTagCorrespondences put a corner.
struct TagCornerKeypoint {
  int image_id = -1;
  int keypoint_id = -1;
  int tag_id = -1;
  int corner = -1;  // 0..3, kTagCornerUnits order
  Eigen::Vector2d pixel = Eigen::Vector2d::Zero();  // where the image shows it
};

// Bundle-adjustment weight of a tag corner against a keypoint detected at the base scale: the
// inverse ratio of their localisation errors, about 0.1 px for libapriltag's edge-fitted corners
// (Wang & Olson 2016) against 0.2-0.3 px for SIFT (Lowe 2004's sub-pixel fit).
inline constexpr double kTagCornerWeight = 2.0;

// Where AddTagCorrespondences puts the corners of one image's tags, `tags`, whose keypoints before
// them number `first_keypoint`: four consecutive keypoints per tag, in the order of `tags`, for
// each tag whose id the image shows once (a printed id twice in one photo: which is which is unknown).
std::vector<TagCornerKeypoint> TagCornerKeypointsOfImage(int image_id, const std::vector<TagObservation>& tags,
                                                         int first_keypoint);

// observations[i] are the tags seen in images[i]. Corners get `keypoint_scale` as detection scale
// (when the images carry scales) and `corner_weight` as weight, and each image lists its tags in
// MapperImage::tags (so that the mapper may register it by them). A pair of images that share tags
// but have no verified pair gets a new one, marked planar so that it never starts the reconstruction.
std::vector<TagCornerKeypoint> AddTagCorrespondences(const std::vector<std::vector<TagObservation>>& observations,
                                                     double keypoint_scale, double corner_weight,
                                                     std::vector<MapperImage>* images, std::vector<MapperPair>* pairs);

struct TagRegistrationOptions {
  double tag_size_m = 0.0;                 // edge of the black square (libapriltag's width_at_border), > 0
  // The tag at the world frame's origin; -1: the lowest complete id. Without a layout the frame's
  // axes are the tag board's (tag_board.h): the plane of the tags on its wall, the up they share.
  int world_tag = -1;
  std::vector<int> scale_tags;             // the tags whose size sets the scale; empty: every complete tag
  // A layout the user declares (tag_layout.h, e.g. an earlier project's tags.layout or a survey):
  // when it holds any complete tag, the world frame is the layout's, fitted to every complete tag
  // it holds (their corners, rigidly, at the scale the scale tags set), instead of the world tag's.
  TagLayout layout;
  int min_views = 2;                       // registered views a corner needs to be triangulated
  double max_reprojection_error_px = 4.0;  // a triangulated corner's observations beyond this are dropped

  Status Check() const;
};

struct RegisteredTag {
  int id = -1;
  std::array<Eigen::Vector3d, 4> corners;  // world frame, metres
  int views = 0;                           // registered images that saw all four corners
  bool adjusted = false;                   // all corners were bundle-adjusted tracks
  std::array<double, 4> edges_m = {};      // |corner k+1 - corner k|
  double rms_reprojection_px = 0.0;        // of the corners in the views that saw them
  Rigid3 world_from_tag;                   // fitted to the corners (rotation, translation)
};

struct TagRegistrationReport {
  // The model is in metres in the world tag's frame. False: no tag was seen with all four
  // corners in `min_views` registered images (`reason` says what was seen); the model is unchanged.
  bool metric = false;
  std::string reason;
  int world_tag = -1;
  // Without a layout: the tags that fixed the frame with the world tag (tag_board.h; each list
  // the world tag alone when it fixed the frame by itself) and the frame's turn from its own.
  std::vector<int> board_plane_tags, board_up_tags;
  double board_turn_deg = 0.0;
  // With a layout: the complete tags it holds, that fixed the frame, and the distances of their
  // corners from their places in the layout after the fit (metres).
  std::vector<int> layout_tags;
  double layout_rms_m = 0.0, layout_max_m = 0.0;
  int tags_seen = 0;                 // distinct ids detected in registered images
  double metres_per_model_unit = 0;  // the scale applied
  std::vector<int> scale_tags;       // the complete tags that set it
  Sim3 world_from_model;
  std::vector<RegisteredTag> tags;                                         // complete tags, by id
  double edge_mean_m = 0.0, edge_std_m = 0.0, edge_max_abs_error_m = 0.0;  // over all edges of all tags
  // The same with each tag measured at a scale it did not help set: a scale tag at the scale of
  // the other scale tags, any other tag at the scale tags' (the mean above over the scale tags
  // equals the tag size by construction). Zero held_out_edges when no tag can be held out.
  // The scale tags held as squares in the adjustment (mapper_adjustment.h, CrossCheckTagSquares):
  // the relative errors of the tags a cross-check left out. Set by the caller; empty otherwise.
  std::vector<double> square_check;
  int held_out_edges = 0;
  double held_out_edge_mean_m = 0.0, held_out_edge_std_m = 0.0, held_out_edge_max_abs_error_m = 0.0;
};

// observations[i] are the tags seen in rec->images[i]; `corner_keypoints` (may be empty) says which
// of their keypoints carry corners. On success with report.metric, *rec is moved into the world
// frame (points, poses; intrinsics are unchanged). InvalidArgument for bad options, when the
// requested world tag is not among the complete tags, or when a layout holds none of them.
Result<TagRegistrationReport> RegisterToTags(const std::vector<std::vector<TagObservation>>& observations,
                                             const std::vector<TagCornerKeypoint>& corner_keypoints,
                                             const TagRegistrationOptions& options, Reconstruction* rec);

// PROJECT/tags.json: {"metric", "reason", "family", "tag_size_m", "world_tag", "frame" ("tag_board",
// "world_tag" when no other tag shares its wall or up, or "layout"), without a layout "plane_tags",
// "up_tags": [ids], "board_turn_deg", with one "layout_tags": [ids], "layout_rms_m", "layout_max_m"; "tags_seen",
// "metres_per_model_unit", "scale_tags": [ids], "edge_mean_m", "edge_std_m", "edge_max_abs_error_m", "held_out_edges", "held_out_edge_mean_m",
// "held_out_edge_std_m", "held_out_edge_max_abs_error_m" (when an edge is held out), "square_check":
// {"segments", "rms_relative_error", "max_abs_relative_error"} (when the scale tags were squares), "tags": [{"id",
// "views", "adjusted", "corners": [[x, y, z] x 4] (metres, world frame), "edges_m": [4],
// "rms_reprojection_px", "world_from_tag": {"R": [9, row-major], "t": [3]}}]}.
std::string TagRegistrationJson(const TagRegistrationReport& report, const std::string& family, double tag_size_m);

// The registered tags in the text format of core/sfm/tag_layout.h ("id size x y z qw qx qy qz", the
// layout frame being the world frame), so that the AR tracker can use all of them at once.
std::string TagLayoutText(const TagRegistrationReport& report, double tag_size_m);

}  // namespace reconar
