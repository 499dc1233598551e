#pragma once
// Incremental structure from motion (Snavely, Seitz & Szeliski, "Photo Tourism", 2006; the
// paper's sections 2.1.4-2.1.5; Schoenberger & Frahm, "Structure-from-Motion Revisited", CVPR
// 2016): an initial pair with enough parallax, then one image at a time registered from its
// 2D-3D correspondences (P3P in LO-RANSAC), new tracks triangulated, local bundle adjustment
// around the new image, global bundle adjustment at growth milestones, and outlier filtering.
// mapper.cc holds only that orchestration; each step is its own part, over the shared state of
// mapper_model.h: initial_pair.h, next_image.h, image_registration.h, track_triangulation.h,
// point_filter.h, mapper_adjustment.h (the bundle-adjustment adapter) and intrinsics_selection.h
// (the final intrinsics model by BIC).
#include <functional>
#include <string>
#include <vector>

#include "core/base/status.h"
#include "core/sfm/reconstruction.h"
#include "core/sfm/tracks.h"

namespace reconar {

// A tag seen in an image: its four corners are the keypoints first_keypoint + k, k in the order of
// kTagCornerUnits (tag_observations.h). AddTagCorrespondences (tag_registration.h) sets them.
struct MapperTag {
  int tag_id = -1;
  int first_keypoint = -1;
};

struct MapperImage {
  std::string name;
  int width = 0;
  int height = 0;
  double focal_prior = 0.0;     // pixels
  bool focal_from_exif = false; // the prior came from EXIF (trusted by the 0.7-1.4 rule)
  std::vector<Eigen::Vector2d> keypoints;  // pixels
  std::vector<float> keypoint_scales;      // optional: detection scale (sigma, pixels) per keypoint
  // Optional: a bundle-adjustment weight (1 / relative standard deviation) per keypoint; 0 or an
  // empty vector leaves the keypoint to the scale rule (MapperOptions::weight_by_scale).
  std::vector<float> keypoint_weights;
  // Optional: the tags among the keypoints. An image with tags may register by them
  // (tag_image_registration.h); without, the mapper never looks at tags.
  std::vector<MapperTag> tags;
};

struct MapperPair {
  PairMatches matches;  // verified (F-inlier) matches
  bool planar = false;  // the two-view check found little parallax (H explains most inliers)
};

struct MapperOptions {
  // Initial pair: at least this many tracks triangulated, with median triangulation angle at
  // least init_min_median_angle_deg. The pairs get a quick two-view score (initial_pair.h) as far
  // down the list as needed (up to init_max_pairs_scored; 0: all of them: in a dense capture of
  // hundreds of photos the best-matched thousands may be neighbours without baseline), and up to
  // init_max_pairs_tried of those that pass get a full try, per round.
  int init_min_points = 100;
  double init_min_median_angle_deg = 4.0;
  int init_max_pairs_tried = 20;
  int init_max_pairs_scored = 0;
  // When no pair meets those bounds, both are halved and the pairs tried again, down to these
  // floors (COLMAP's mapper relaxes the same way): texture-poor rooms have few matches per pair.
  int init_min_points_floor = 25;
  double init_min_angle_floor_deg = 1.0;
  // Registration: P3P LO-RANSAC with this pixel threshold; a pose with this many inliers registers.
  double registration_max_error_px = 4.0;
  int registration_min_inliers = 30;
  // A pose with fewer inliers, down to registration_min_verified_inliers, registers provisionally
  // (provisional_registration.h) when they are at least half of the image's 2D-3D
  // correspondences, span registration_min_inlier_spread of the image, and the pose puts at least
  // registration_min_two_view_fraction of the image's matches to registered images on tracks
  // without a point on their epipolar lines (when there are registration_min_verified_inliers
  // such matches); it is tried after every candidate has had its try under the plain rule, and
  // checked again after every global adjustment. Texture-poor objects, sparse rings and dense
  // video rarely give 30 points in three views. registration_min_verified_inliers =
  // registration_min_inliers turns it off.
  int registration_min_verified_inliers = 12;
  double registration_min_two_view_fraction = 0.5;
  double registration_min_inlier_spread = 0.1;
  // Registration from a registered neighbour's two-view geometry (neighbour_registration.h) when
  // the absolute pose fails, provisional as above: this many model points must agree on the
  // baseline's length; 0 turns it off.
  int registration_min_baseline_points = 5;
  // Registration by tags (images with MapperImage::tags only, tag_image_registration.h): a pose
  // that puts every corner of every tag the model holds within registration_max_error_px
  // registers with fewer inliers when that is at least two such tags, or one and this many other
  // inliers.
  int registration_min_tag_point_inliers = 8;
  // ... and whose root mean square error over those corners is at most this: a tag's corners are
  // found to a few tenths of a pixel, and two small tags facing the camera admit a wrong pose that
  // fits them each within a few pixels.
  double registration_max_tag_rms_px = 2.0;
  // ... and, when the image has at least registration_min_tag_point_inliers matches to registered
  // images on tracks without a point, at least this fraction of them within
  // registration_max_error_px of their epipolar lines under the pose.
  double registration_min_tag_two_view_fraction = 0.3;
  // Triangulation and filtering.
  double max_reprojection_error_px = 4.0;
  double min_triangulation_angle_deg = 1.5;
  // Local bundle adjustment: the new image and up to this many images sharing the most points.
  int local_ba_images = 6;
  int local_ba_iterations = 25;
  // Global bundle adjustment whenever the registered count reached growth x the last one.
  double global_ba_growth = 1.25;
  int global_ba_iterations = 50;
  // The final global adjustment runs to a tighter relative cost change.
  int final_ba_iterations = 200;
  double final_ba_function_tolerance = 1e-10;
  // Scale (pixels) of the Cauchy loss in every bundle adjustment. Observations beyond
  // max_reprojection_error_px are dropped by filtering; the loss only tempers those near the bound.
  double ba_loss_scale_px = 3.0;
  // With keypoint scales given, an observation's standard deviation grows with its detection
  // scale beyond this one (pixels): weight = min(1, base_scale / scale).
  bool weight_by_scale = true;
  double base_scale_px = 1.6;
  // Intrinsics: the focal is refined once three images are registered; k1, k2 from then on when
  // each global adjustment's information criterion chooses them (GrowthRefinement in mapper.cc).
  bool refine_focal = true;
  bool refine_distortion = true;
  // Principal point: fixed at the image centre, refined in the final bundle adjustment, or
  // (kAuto) refined there when the Bayesian information criterion prefers it. With
  // refine_distortion the final adjustment likewise chooses between k1 = k2 = 0 and free k1, k2.
  enum class PrincipalPoint { kFixed, kAuto, kRefine };
  PrincipalPoint principal_point = PrincipalPoint::kAuto;
  // The final adjustment may also refine the pixel aspect ratio fy / fx (chosen the same way).
  bool refine_aspect = false;
  // EXIF focal priors outside [focal_prior_min_ratio, focal_prior_max_ratio] x the data's
  // estimate are distrusted (paper eq. 5).
  double focal_prior_min_ratio = 0.7;
  double focal_prior_max_ratio = 1.4;
  // Which images share one camera (one set of intrinsics):
  //  kAuto: images of the same size whose focal priors agree and come from EXIF, or that all
  //         lack EXIF (one unknown camera, the usual case of a single device without metadata);
  //  kPerImage: every image has its own intrinsics;
  //  kSingle: all images of the same size share one camera.
  enum class CameraSharing { kAuto, kPerImage, kSingle };
  CameraSharing camera_sharing = CameraSharing::kAuto;
  int num_threads = 0;  // <= 0: one per core
  // When registration stops with images left that have verified matches among themselves, a new
  // model is started from them, up to this many models in all; the largest is returned.
  int max_models = 8;
  // A model that stops at fewer than min(min_model_images, half the images its initial pair is
  // joined to by chains of verified pairs) is a failed start (like COLMAP's min_model_size): it is built again from the
  // next initial pair, up to init_max_starts starts in all, and the largest start is kept.
  int min_model_images = 10;
  int init_max_starts = 4;
  // With merge_models, another model is merged into the largest (model_merge.h) when a similarity
  // puts at least merge_min_shared_points of the 3D points they share through verified matches,
  // and half of them, within max_reprojection_error_px in both models' views (else, when a verified
  // pair between them gives the similarity: AlignModelsByTwoViewGeometry); the union is then
  // grown and adjusted as one, and kept only when it verifies: at least merge_min_shared_points of
  // its points are seen by images of both models (a wrong alignment leaves their tracks
  // untriangulable). Models of unrelated scenes share no point and stay apart.
  bool merge_models = true;
  int merge_min_shared_points = 12;
  // Tags as rigid squares (tag_squares.h): every global adjustment holds the corners of square_tags
  // (empty: every tag in MapperImage::tags) to the square of their mean edge that fits them best,
  // each coordinate with this standard deviation relative to the edge; 0 turns it off. 0.003 is
  // 0.4 mm on a 12.7 cm tag: a laser print's scale error and a sheet not quite flat.
  double tag_square_sigma = 0.003;
  std::vector<int> square_tags;

  Status Check() const;
};

struct MapperReport {
  struct Unregistered {
    std::string name;
    std::string reason;
  };
  int num_images = 0;
  int num_registered = 0;
  int num_points = 0;
  int num_tracks = 0;
  int num_conflicting_matches = 0;
  std::string initial_pair;  // "a.jpg + b.jpg"
  int initial_image_a = -1, initial_image_b = -1;
  int init_starts = 1;       // how often the model was started (a failed start is built again)
  std::string failed_start;  // why no start could be made, when none could
  int init_relaxations = 0;  // how often the initial-pair bounds were halved before one was found
  int init_pairs_scored = 0;              // pairs given a quick two-view score before the initial pair was found
  int num_registered_from_neighbour = 0;  // images registered from a neighbour's two-view geometry
  // Provisional registrations (provisional_registration.h): every image registered so, still in
  // the model or taken out again (then with the reason among `unregistered`).
  struct Provisional {
    std::string name;
    std::string evidence;  // "few inliers" or "neighbour"
    int inliers = 0;
    bool kept = false;
  };
  std::vector<Provisional> provisional;
  std::vector<Unregistered> unregistered;
  // Every model built, the returned (largest) one first: its images and point count. An image in
  // another model is listed as unregistered with the reason "in model K".
  struct Model {
    std::vector<std::string> images;
    int num_points = 0;
    std::string initial_pair;
    std::string not_merged;  // why it was not merged into the main model
  };
  std::vector<Model> models;
  // The models merged into this one: their initial pair, size, and the shared points that aligned them.
  struct Merge {
    std::string initial_pair;
    int num_images = 0;
    int num_shared_points = 0;
    int num_inliers = 0;
    std::string aligned_by;  // "shared points", or the pair whose two-view geometry aligned them
  };
  std::vector<Merge> merges;
  std::string not_merged;  // of a model not merged into the main one: why
  int num_local_ba = 0;
  int num_global_ba = 0;
  // Adjustments that failed numerically (the model was left as it was before each) and the
  // first one's message; the mapper carries on after them.
  int num_failed_ba = 0;
  std::string first_ba_failure;
  double seconds_ba = 0.0;
  double seconds_total = 0.0;
  double mean_reprojection_error_px = 0.0;
  double mean_track_length = 0.0;
  bool principal_point_refined = false;  // the final model's choices (see MapperOptions)
  bool distortion_refined = false;
  bool aspect_refined = false;
};

// Called after each registration with (registered, total).
using MapperProgress = std::function<void(int, int)>;

// Builds a model from the images and their verified pairwise matches, then further models from
// the images left (MapperOptions::max_models), and returns the largest; the others, with every
// image (unregistered where not theirs), go to *other_models when given. InvalidArgument for bad
// options or inconsistent input (a match indexing a missing keypoint), or a bundle adjustment
// refusing its problem (a programming error); FailedPrecondition, with the reason, when no
// initial pair can be found (e.g. unrelated photos or too few matches).
Result<Reconstruction> RunIncrementalMapper(const std::vector<MapperImage>& images,
                                            const std::vector<MapperPair>& pairs, const MapperOptions& options,
                                            MapperReport* report, const MapperProgress& progress = nullptr,
                                            std::vector<Reconstruction>* other_models = nullptr);

// How ContinueIncrementalMapper adjusts the model it grows.
struct MapperContinuation {
  // true: the whole model is adjusted as at the end of a run (the intrinsics model chosen, then the
  // final adjustment). false: each new image gets the local adjustment, and the model a global one
  // when the registered count reaches MapperOptions::global_ba_growth x registered_at_last_global,
  // which is updated: a model that grows a photo at a time, adjusted as a whole once at its end.
  bool final_adjustment = true;
  int registered_at_last_global = 0;
};

// Grows `previous`, a model of some of `images` (found by name; built by either function, or read
// back from its files), over all of them: its registered images start with their poses and
// cameras, every track is triangulated again, the rest register as they can, and the model is
// adjusted as `continuation` says (null: as at the end of a run). For a model that grows while
// photos arrive (a capture), and for mapping that continues from it. InvalidArgument when
// `previous` holds fewer than two registered images, or an image not among `images` or of another size.
Result<Reconstruction> ContinueIncrementalMapper(const std::vector<MapperImage>& images,
                                                 const std::vector<MapperPair>& pairs, const MapperOptions& options,
                                                 const Reconstruction& previous,
                                                 MapperContinuation* continuation = nullptr,
                                                 MapperReport* report = nullptr,
                                                 const MapperProgress& progress = nullptr);

}  // namespace reconar
