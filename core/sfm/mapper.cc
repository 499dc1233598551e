#include "core/sfm/mapper.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <map>
#include <set>
#include <utility>

#include "core/base/elapsed.h"
#include "core/sfm/image_registration.h"
#include "core/sfm/initial_pair.h"
#include "core/sfm/intrinsics_selection.h"
#include "core/sfm/mapper_adjustment.h"
#include "core/sfm/mapper_model.h"
#include "core/sfm/model_merge.h"
#include "core/sfm/neighbour_registration.h"
#include "core/sfm/next_image.h"
#include "core/sfm/point_filter.h"
#include "core/sfm/provisional_registration.h"
#include "core/sfm/track_triangulation.h"

namespace reconar {
namespace {

using Clock = std::chrono::steady_clock;

// The reasons an image gets before the mapper tries it.
constexpr char kNoVerifiedMatches[] = "no verified matches to other images";
constexpr char kNotConnected[] = "not connected to the reconstructed images";

// The orchestration: setup, the initial pair, the growth loop (next image, registration,
// triangulation, local or global adjustment, filtering), the global refinements and the report.
class Mapper {
 public:
  Mapper(const std::vector<MapperImage>& images, const std::vector<MapperPair>& pairs, const MapperOptions& options,
         MapperReport* report, const std::set<std::pair<int, int>>& excluded_starts, InitialPairScores* scores)
      : images_(images),
        pairs_(pairs),
        opt_(options),
        report_(report),
        excluded_starts_(excluded_starts),
        initial_pair_scores_(scores) {}

  // From the best initial pair, or, with `seed`, from its registered images' poses and their
  // cameras (a merge of models, model_merge.h; a model grown while photos arrive): the seed's points
  // are triangulated again from the tracks of every pair. With a `continuation` that is not final,
  // the model is only grown (see MapperContinuation).
  Status Run(const MapperProgress& progress, const Reconstruction* seed = nullptr,
             MapperContinuation* continuation = nullptr) {
    const auto start = Clock::now();
    const bool growth_only = continuation != nullptr && !continuation->final_adjustment;
    RECONAR_RETURN_IF_ERROR(Setup());
    int last_global = 0;
    if (seed != nullptr) {
      RECONAR_RETURN_IF_ERROR(StartFromSeed(*seed, !growth_only));
      last_global = growth_only ? continuation->registered_at_last_global : model_.rec.NumRegisteredImages();
    } else {
      RECONAR_RETURN_IF_ERROR(
          InitializeFromBestPair(&model_, images_, pairs_, opt_, report_, excluded_starts_,
                                 excluded_starts_.empty() ? InitialPairOrder::kMatchCount : InitialPairOrder::kGeometry,
                                 initial_pair_scores_));
      last_global = model_.rec.NumRegisteredImages();
    }
    if (progress) progress(model_.rec.NumRegisteredImages(), static_cast<int>(images_.size()));
    while (true) {
      bool registered_one = false;
      RECONAR_ASSIGN_OR_RETURN(registered_one, RegisterNextImage());
      if (!registered_one) break;
      const int registered = model_.rec.NumRegisteredImages();
      if (registered >= opt_.global_ba_growth * last_global) {
        RECONAR_RETURN_IF_ERROR(GrowthRefinement());
        last_global = registered;
      }
      if (progress) progress(registered, static_cast<int>(images_.size()));
    }
    if (growth_only) {
      continuation->registered_at_last_global = last_global;
      FinishReport();
      report_->seconds_total = SecondsSince(start);
      return Status::Ok();
    }
    RECONAR_RETURN_IF_ERROR(GrowthRefinement());
    IntrinsicsChoice choice;
    RECONAR_ASSIGN_OR_RETURN(choice, SelectIntrinsicsModel(&model_, images_, opt_, report_));
    MapperAdjustment final_adjustment;
    final_adjustment.iterations = opt_.final_ba_iterations;
    final_adjustment.function_tolerance = opt_.final_ba_function_tolerance;
    final_adjustment.free = choice;
    RECONAR_RETURN_IF_ERROR(GlobalRefinement(final_adjustment));
    // An image taken out by the final review leaves the model adjusted with it: adjust again.
    while (taken_out_in_last_refinement_ > 0) RECONAR_RETURN_IF_ERROR(GlobalRefinement(final_adjustment));
    FinishReport();
    report_->seconds_total = SecondsSince(start);
    return Status::Ok();
  }

  Reconstruction TakeResult() { return std::move(model_.rec); }

 private:
  Status Setup() {
    const int n = static_cast<int>(images_.size());
    report_->num_images = n;
    std::vector<int> num_keypoints(static_cast<size_t>(n));
    Reconstruction& rec = model_.rec;
    rec.images.resize(static_cast<size_t>(n));
    model_.failure.assign(static_cast<size_t>(n), kNoVerifiedMatches);
    model_.tried_with.assign(static_cast<size_t>(n), -1);
    model_.neighbour_tried_with.assign(static_cast<size_t>(n), -1);
    plain_tried_with_.assign(static_cast<size_t>(n), -1);
    taken_out_.assign(static_cast<size_t>(n), 0);
    taken_out_reason_.assign(static_cast<size_t>(n), "");
    for (int i = 0; i < n; ++i) {
      const MapperImage& in = images_[static_cast<size_t>(i)];
      if (in.width <= 0 || in.height <= 0 || !(in.focal_prior > 0.0)) {
        return InvalidArgument(in.name + ": image size and focal prior must be positive");
      }
      SfmImage& image = rec.images[static_cast<size_t>(i)];
      image.name = in.name;
      image.camera_id = CameraFor(i);
      image.keypoints = in.keypoints;
      image.point3d_ids.assign(in.keypoints.size(), -1);
      num_keypoints[static_cast<size_t>(i)] = static_cast<int>(in.keypoints.size());
    }
    std::vector<PairMatches> matches;
    matches.reserve(pairs_.size());
    for (const MapperPair& pair : pairs_) {
      const PairMatches& m = pair.matches;
      if (m.image_a < 0 || m.image_a >= n || m.image_b < 0 || m.image_b >= n || m.image_a == m.image_b) {
        return InvalidArgument("mapper: a pair names a missing image");
      }
      for (const FeatureMatch& f : m.matches) {
        if (f.index_a < 0 || f.index_a >= num_keypoints[static_cast<size_t>(m.image_a)] || f.index_b < 0 ||
            f.index_b >= num_keypoints[static_cast<size_t>(m.image_b)]) {
          return InvalidArgument("mapper: a match between " + images_[static_cast<size_t>(m.image_a)].name + " and " +
                                 images_[static_cast<size_t>(m.image_b)].name + " indexes a missing keypoint");
        }
      }
      matches.push_back(m);
      model_.failure[static_cast<size_t>(m.image_a)] = model_.failure[static_cast<size_t>(m.image_b)] = kNotConnected;
    }
    model_.SetTracks(BuildTracks(num_keypoints, matches));
    model_.tag_corner_bounds.assign(static_cast<size_t>(n), {});
    for (int i = 0; i < n; ++i) {
      const MapperImage& in = images_[static_cast<size_t>(i)];
      std::vector<MapperModel::TagCornerBound>& corners = model_.tag_corner_bounds[static_cast<size_t>(i)];
      for (const MapperTag& tag : in.tags) {
        if (tag.first_keypoint < 0 || static_cast<size_t>(tag.first_keypoint) + 4 > in.keypoints.size())
          return InvalidArgument(in.name + ": a tag's corners index missing keypoints");
        double edge = 0.0;
        for (int k = 0; k < 4; ++k) {
          edge += (in.keypoints[static_cast<size_t>(tag.first_keypoint + (k + 1) % 4)] -
                   in.keypoints[static_cast<size_t>(tag.first_keypoint + k)]).norm() / 4.0;
        }
        for (int k = 0; k < 4; ++k) corners.push_back({tag.first_keypoint + k, edge});
      }
      std::sort(corners.begin(), corners.end());
    }
    report_->num_tracks = static_cast<int>(model_.tracks.tracks.size());
    report_->num_conflicting_matches = model_.tracks.num_conflicting_matches;
    return Status::Ok();
  }

  // The seed's images are found by name; each mapper camera takes the seed camera of its first
  // registered seed image. With `refine`, the seeded model is adjusted globally.
  Status StartFromSeed(const Reconstruction& seed, bool refine) {
    Reconstruction& rec = model_.rec;
    std::map<std::string, size_t> index_of;
    for (size_t i = 0; i < rec.images.size(); ++i) index_of.emplace(rec.images[i].name, i);
    std::vector<bool> camera_seeded(rec.cameras.size(), false);
    for (const SfmImage& seeded : seed.images) {
      if (!seeded.registered) continue;
      const auto it = index_of.find(seeded.name);
      if (it == index_of.end())
        return InvalidArgument("mapper: the seed model's image " + seeded.name + " is not given");
      if (seeded.camera_id < 0 || static_cast<size_t>(seeded.camera_id) >= seed.cameras.size())
        return InvalidArgument("mapper: the seed model's image " + seeded.name + " has no camera");
      SfmImage& image = rec.images[it->second];
      const SfmCamera& camera = seed.cameras[static_cast<size_t>(seeded.camera_id)];
      if (camera.width != images_[it->second].width || camera.height != images_[it->second].height)
        return InvalidArgument("mapper: the seed model's image " + seeded.name + " is of another size");
      const size_t camera_id = static_cast<size_t>(image.camera_id);
      if (!camera_seeded[camera_id]) rec.cameras[camera_id] = camera;
      camera_seeded[camera_id] = true;
      image.registered = true;
      image.cam_from_world = seeded.cam_from_world;
      model_.failure[it->second].clear();
    }
    if (model_.rec.NumRegisteredImages() < 2) return InvalidArgument("mapper: a seed model of fewer than two images");
    for (const int image : model_.RegisteredImages()) TriangulateImage(&model_, image, opt_);
    for (const SfmCamera& camera : model_.rec.cameras) growth_distortion_ |= camera.k1 != 0.0 || camera.k2 != 0.0;
    if (!refine) return Status::Ok();
    return GrowthRefinement();
  }

  // The camera of image i under the sharing rule, created when no earlier image shares it.
  int CameraFor(int i) {
    const MapperImage& in = images_[static_cast<size_t>(i)];
    for (int j = 0; j < i && opt_.camera_sharing != MapperOptions::CameraSharing::kPerImage; ++j) {
      const MapperImage& other = images_[static_cast<size_t>(j)];
      if (other.width != in.width || other.height != in.height) continue;
      const bool same =
          opt_.camera_sharing == MapperOptions::CameraSharing::kSingle ||
          (in.focal_from_exif == other.focal_from_exif && (!in.focal_from_exif || other.focal_prior == in.focal_prior));
      if (same) return model_.rec.images[static_cast<size_t>(j)].camera_id;
    }
    SfmCamera camera;
    camera.width = in.width;
    camera.height = in.height;
    camera.focal = in.focal_prior;
    camera.cx = 0.5 * (in.width - 1);
    camera.cy = 0.5 * (in.height - 1);
    model_.rec.cameras.push_back(camera);
    model_.camera_prior.push_back(in.focal_prior);
    model_.camera_from_exif.push_back(in.focal_from_exif);
    return static_cast<int>(model_.rec.cameras.size()) - 1;
  }

  // The adjustments while the model grows: the principal point fixed, the distortion refined
  // when the last global refinement chose it (GrowthRefinement; from three registered images on).
  MapperAdjustment GrowthAdjustment(int iterations) const {
    MapperAdjustment adjustment;
    adjustment.iterations = iterations;
    adjustment.free.distortion = growth_distortion_;
    return adjustment;
  }

  // Registers the next image (next_image.h) that succeeds, or else the first that registers from a
  // neighbour's two-view geometry (neighbour_registration.h), then grows the model around it; false
  // when no image registers.
  Result<bool> RegisterNextImage() {
    const std::vector<NextImageCandidate> candidates = NextImageCandidates(&model_, images_, opt_);
    // Every candidate under the plain rule (registration_min_inliers, or its tags) before any under
    // the verified one for fewer inliers: a weak pose taken early would shape the model around it.
    // A failure under the plain rule is remembered apart (plain_tried_with_), so that the image
    // still gets its try under the verified one.
    const bool two_rules = opt_.registration_min_verified_inliers < opt_.registration_min_inliers;
    MapperOptions plain = opt_;
    plain.registration_min_verified_inliers = opt_.registration_min_inliers;
    for (const MapperOptions* rule : {static_cast<const MapperOptions*>(&plain), &opt_}) {
      if (rule == &opt_ && !two_rules) break;
      for (const NextImageCandidate& candidate : candidates) {
        const size_t i = static_cast<size_t>(candidate.image);
        if (rule == &plain && two_rules) {
          if (candidate.visible <= plain_tried_with_[i]) continue;
          plain_tried_with_[i] = candidate.visible;
        } else {
          if (taken_out_[i]) continue;  // a provisional pose that failed: the plain rule only
          model_.tried_with[i] = candidate.visible;
        }
        bool focal_changed = false;
        int inliers = 0;
        if (!RegisterImage(&model_, images_, candidate.image, *rule, &focal_changed, &inliers)) continue;
        if (inliers > 0 && inliers < opt_.registration_min_inliers)
          AddProvisional(candidate.image, WeakEvidence::kFewInliers, inliers);
        RECONAR_RETURN_IF_ERROR(GrowAround(candidate.image, focal_changed));
        return true;
      }
    }
    for (int image : NeighbourRegistrationCandidates(model_, pairs_, model_.neighbour_tried_with)) {
      if (taken_out_[static_cast<size_t>(image)]) continue;
      model_.neighbour_tried_with[static_cast<size_t>(image)] = model_.CountVisiblePoints(image);
      if (!RegisterImageFromNeighbour(&model_, pairs_, image, opt_)) continue;
      ++report_->num_registered_from_neighbour;
      int observations = 0;
      for (int point : model_.rec.images[static_cast<size_t>(image)].point3d_ids) observations += point >= 0 ? 1 : 0;
      AddProvisional(image, WeakEvidence::kNeighbour, observations);
      RECONAR_RETURN_IF_ERROR(GrowAround(image, false));
      return true;
    }
    return false;
  }

  void AddProvisional(int image, WeakEvidence evidence, int inliers) {
    provisional_.push_back({image, evidence, inliers, model_.rec.NumRegisteredImages()});
    report_->provisional.push_back({images_[static_cast<size_t>(image)].name,
                                    evidence == WeakEvidence::kFewInliers ? "few inliers" : "neighbour", inliers, true});
  }

  // Checks every provisional image against the adjusted model (provisional_registration.h) and
  // takes out those that no longer hold, with the reason; they may come back only under the plain
  // rule. Returns how many were taken out.
  int ReviewProvisional() {
    int taken_out = 0;
    std::vector<ProvisionalImage> still;
    for (const ProvisionalImage& p : provisional_) {
      const std::string reason = ReviewProvisionalImage(model_, p, opt_);
      if (reason.empty()) {
        still.push_back(p);
        continue;
      }
      const size_t i = static_cast<size_t>(p.image);
      DeregisterImage(&model_, p.image, opt_);
      taken_out_[i] = 1;
      model_.tried_with[i] = model_.CountVisiblePoints(p.image);
      taken_out_reason_[i] = "registered provisionally (" + std::to_string(p.inliers) + " points, " +
                             (p.evidence == WeakEvidence::kFewInliers ? "an absolute pose"
                                                                      : "a neighbour's two-view geometry") +
                             ") and taken out at " + std::to_string(model_.rec.NumRegisteredImages()) +
                             " registered images: " + reason;
      model_.failure[i] = taken_out_reason_[i];
      for (MapperReport::Provisional& r : report_->provisional) {
        if (r.name == images_[i].name) r.kept = false;
      }
      ++taken_out;
    }
    provisional_ = std::move(still);
    return taken_out;
  }

  // Triangulates the new image's tracks and adjusts around it (globally when its registration set
  // a focal).
  Status GrowAround(int image, bool focal_changed) {
    TriangulateImage(&model_, image, opt_);
    if (focal_changed) return GrowthRefinement();
    const std::vector<int> local = LocalBundle(model_, image, opt_);
    RECONAR_RETURN_IF_ERROR(Adjust(local, GrowthAdjustment(opt_.local_ba_iterations)));
    FilterPoints(&model_, model_.PointsSeenBy(local), opt_);
    return Status::Ok();
  }

  // A bundle adjustment whose numeric failure is counted and leaves the model as it was.
  Status Adjust(const std::vector<int>& variable, const MapperAdjustment& adjustment) {
    return CountFailedAdjustment(BundleAdjust(&model_, images_, variable, adjustment, opt_, report_).status(), report_);
  }

  // Adjusts the whole model, filters, triangulates every track again, adjusts and filters again.
  // With `chosen` the first adjustment is instead the choice of the intrinsics (SelectIntrinsicsModel
  // under `chosen`'s options), and the second uses that choice.
  Status GlobalRefinement(const MapperAdjustment& adjustment, const MapperOptions* chosen = nullptr) {
    MapperAdjustment second = adjustment;
    if (chosen != nullptr) {
      RECONAR_ASSIGN_OR_RETURN(second.free, SelectIntrinsicsModel(&model_, images_, *chosen, report_));
    } else {
      RECONAR_RETURN_IF_ERROR(Adjust(model_.RegisteredImages(), adjustment));
    }
    FilterPoints(&model_, model_.AllPoints(), opt_);
    RetriangulateAll(&model_, opt_);
    RECONAR_RETURN_IF_ERROR(Adjust(model_.RegisteredImages(), second));
    FilterPoints(&model_, model_.AllPoints(), opt_);
    if (chosen != nullptr) growth_distortion_ = second.free.distortion;
    taken_out_in_last_refinement_ = ReviewProvisional();
    return Status::Ok();
  }

  // The global refinement while the model grows. The distortion is refined only when the data
  // supports it, chosen as at the end of the run (intrinsics_selection.h: the information
  // criterion, and no implausible coefficients) with the principal point held: from a few close
  // views, k1 and k2 trade against the focal, and a focal gone wrong keeps the later images from
  // registering (the AR video's 13 keyframes with the distortion always free: k2 = 0.65 and the
  // focal 20 % long at four images, k2 = -2 at five, 11 of 13 registered in the end).
  Status GrowthRefinement() {
    MapperAdjustment adjustment = GrowthAdjustment(opt_.global_ba_iterations);
    if (!opt_.refine_distortion || model_.rec.NumRegisteredImages() < 3) return GlobalRefinement(adjustment);
    MapperOptions selection = opt_;
    selection.principal_point = MapperOptions::PrincipalPoint::kFixed;
    selection.refine_aspect = false;
    selection.final_ba_iterations = adjustment.iterations;
    selection.final_ba_function_tolerance = adjustment.function_tolerance;
    return GlobalRefinement(adjustment, &selection);
  }

  void FinishReport() {
    Reconstruction& rec = model_.rec;
    report_->num_registered = rec.NumRegisteredImages();
    report_->num_points = rec.NumPoints();
    double error_sum = 0.0, length_sum = 0.0;
    size_t observations = 0;
    for (SfmPoint& point : rec.points) {
      if (point.deleted) continue;
      double sum = 0.0;
      for (const TrackElement& e : point.track)
        sum += std::sqrt(model_.SquaredError(point.position, e.image_id, e.keypoint_id));
      point.error = point.track.empty() ? 0.0 : sum / static_cast<double>(point.track.size());
      error_sum += sum;
      observations += point.track.size();
      length_sum += static_cast<double>(point.track.size());
    }
    report_->mean_reprojection_error_px = observations > 0 ? error_sum / static_cast<double>(observations) : 0.0;
    report_->mean_track_length = report_->num_points > 0 ? length_sum / report_->num_points : 0.0;
    report_->unregistered.clear();
    for (size_t i = 0; i < rec.images.size(); ++i) {
      if (rec.images[i].registered) continue;
      std::string reason = model_.failure[i];
      if (taken_out_[i] && reason != taken_out_reason_[i]) reason = taken_out_reason_[i] + "; then " + reason;
      report_->unregistered.push_back({rec.images[i].name, reason});
    }
  }

  const std::vector<MapperImage>& images_;
  const std::vector<MapperPair>& pairs_;
  const MapperOptions& opt_;
  MapperReport* report_;
  const std::set<std::pair<int, int>>& excluded_starts_;
  InitialPairScores* initial_pair_scores_;
  bool growth_distortion_ = false;  // the growth adjustments refine k1, k2 (GrowthRefinement's choice)
  MapperModel model_;
  std::vector<int> plain_tried_with_;  // per image: visible points at its last failure under the plain rule
  std::vector<ProvisionalImage> provisional_;  // registered provisionally, in order, and not confirmed out
  std::vector<char> taken_out_;                // per image: a provisional registration of it was taken out
  std::vector<std::string> taken_out_reason_;  // ... and why
  int taken_out_in_last_refinement_ = 0;
};

}  // namespace

Status MapperOptions::Check() const {
  if (init_min_points < 8) return InvalidArgument("MapperOptions: init_min_points < 8");
  if (!(init_min_median_angle_deg >= 0.0)) return InvalidArgument("MapperOptions: init_min_median_angle_deg < 0");
  if (init_max_pairs_tried < 1) return InvalidArgument("MapperOptions: init_max_pairs_tried < 1");
  if (init_max_pairs_scored < 0) return InvalidArgument("MapperOptions: init_max_pairs_scored < 0");
  if (init_min_points_floor < 8 || init_min_points_floor > init_min_points) {
    return InvalidArgument("MapperOptions: init_min_points_floor must be in [8, init_min_points]");
  }
  if (!(init_min_angle_floor_deg >= 0.0 && init_min_angle_floor_deg <= init_min_median_angle_deg)) {
    return InvalidArgument("MapperOptions: init_min_angle_floor_deg must be in [0, init_min_median_angle_deg]");
  }
  if (!(registration_max_error_px > 0.0)) return InvalidArgument("MapperOptions: registration_max_error_px <= 0");
  if (registration_min_inliers < 6) return InvalidArgument("MapperOptions: registration_min_inliers < 6");
  if (registration_min_verified_inliers < 6 || registration_min_verified_inliers > registration_min_inliers)
    return InvalidArgument("MapperOptions: registration_min_verified_inliers must be in [6, registration_min_inliers]");
  if (!(registration_min_two_view_fraction >= 0.0 && registration_min_two_view_fraction <= 1.0))
    return InvalidArgument("MapperOptions: registration_min_two_view_fraction must be in [0, 1]");
  if (!(registration_min_inlier_spread >= 0.0 && registration_min_inlier_spread <= 1.0))
    return InvalidArgument("MapperOptions: registration_min_inlier_spread must be in [0, 1]");
  if (max_models < 1) return InvalidArgument("MapperOptions: max_models < 1");
  if (min_model_images < 2) return InvalidArgument("MapperOptions: min_model_images < 2");
  if (init_max_starts < 1) return InvalidArgument("MapperOptions: init_max_starts < 1");
  if (merge_min_shared_points < 3) return InvalidArgument("MapperOptions: merge_min_shared_points < 3");
  if (!(tag_square_sigma >= 0.0 && std::isfinite(tag_square_sigma)))
    return InvalidArgument("MapperOptions: tag_square_sigma must be finite and >= 0");
  if (registration_min_baseline_points < 0)
    return InvalidArgument("MapperOptions: registration_min_baseline_points < 0");
  if (registration_min_tag_point_inliers < 0)
    return InvalidArgument("MapperOptions: registration_min_tag_point_inliers < 0");
  if (!(registration_max_tag_rms_px > 0.0)) return InvalidArgument("MapperOptions: registration_max_tag_rms_px <= 0");
  if (!(registration_min_tag_two_view_fraction >= 0.0 && registration_min_tag_two_view_fraction <= 1.0))
    return InvalidArgument("MapperOptions: registration_min_tag_two_view_fraction must be in [0, 1]");
  if (!(max_reprojection_error_px > 0.0)) return InvalidArgument("MapperOptions: max_reprojection_error_px <= 0");
  if (!(min_triangulation_angle_deg >= 0.0)) return InvalidArgument("MapperOptions: min_triangulation_angle_deg < 0");
  if (local_ba_images < 0) return InvalidArgument("MapperOptions: local_ba_images < 0");
  if (local_ba_iterations < 0 || global_ba_iterations < 0) return InvalidArgument("MapperOptions: BA iterations < 0");
  if (!(global_ba_growth > 1.0)) return InvalidArgument("MapperOptions: global_ba_growth <= 1");
  if (!(ba_loss_scale_px > 0.0)) return InvalidArgument("MapperOptions: ba_loss_scale_px <= 0");
  if (!(focal_prior_min_ratio > 0.0 && focal_prior_max_ratio >= focal_prior_min_ratio)) {
    return InvalidArgument("MapperOptions: need 0 < focal_prior_min_ratio <= focal_prior_max_ratio");
  }
  return Status::Ok();
}

namespace {

// The images joined to `image` by chains of verified pairs among `pairs`, itself included (a pair
// naming a missing image is the mapper's Setup's to refuse).
int ComponentSize(size_t num_images, const std::vector<MapperPair>& pairs, int image) {
  std::vector<std::vector<int>> neighbours(num_images);
  for (const MapperPair& pair : pairs) {
    const int a = pair.matches.image_a, b = pair.matches.image_b;
    if (a < 0 || b < 0 || static_cast<size_t>(a) >= num_images || static_cast<size_t>(b) >= num_images) continue;
    neighbours[static_cast<size_t>(a)].push_back(b);
    neighbours[static_cast<size_t>(b)].push_back(a);
  }
  std::vector<char> seen(num_images, 0);
  std::vector<int> stack = {image};
  seen[static_cast<size_t>(image)] = 1;
  int size = 0;
  while (!stack.empty()) {
    const int current = stack.back();
    stack.pop_back();
    ++size;
    for (const int next : neighbours[static_cast<size_t>(current)]) {
      if (!seen[static_cast<size_t>(next)]) seen[static_cast<size_t>(next)] = 1, stack.push_back(next);
    }
  }
  return size;
}

// One model over `pairs`, started again from the next initial pair while it is a failed start
// (MapperOptions::min_model_images, against the images its initial pair connects to); the
// largest start is kept. False, with the reason in report->failed_start, when no start could be
// made; errors other than that pass through.
Result<bool> RunWithRestarts(const std::vector<MapperImage>& images, const std::vector<MapperPair>& pairs,
                             const MapperOptions& options, const MapperProgress& progress, Reconstruction* model,
                             MapperReport* report) {
  std::set<std::pair<int, int>> excluded;
  InitialPairScores scores;
  bool any = false;
  for (int start = 1; start <= options.init_max_starts; ++start) {
    MapperReport attempt_report;
    Mapper mapper(images, pairs, options, &attempt_report, excluded, &scores);
    const Status status = mapper.Run(progress);
    if (!status.ok()) {
      if (status.code() != StatusCode::kFailedPrecondition) return status;
      if (!any) {
        *report = std::move(attempt_report);
        report->failed_start = status.message();
      }
      break;
    }
    Reconstruction attempt = mapper.TakeResult();
    excluded.insert({attempt_report.initial_image_a, attempt_report.initial_image_b});
    if (!any || attempt.NumRegisteredImages() > model->NumRegisteredImages()) {
      *model = std::move(attempt);
      *report = std::move(attempt_report);
      any = true;
    }
    report->init_starts = start;
    const int component = ComponentSize(images.size(), pairs, report->initial_image_a);
    if (model->NumRegisteredImages() >= std::min(options.min_model_images, (component + 1) / 2)) break;
  }
  return any;
}

// A join by a pair's two-view geometry (AlignModelsByTwoViewGeometry) needs this many points on
// each side to agree on the baseline, as a registration from a neighbour's geometry does
// (MapperOptions::registration_min_baseline_points' default); the joined model is verified after.
constexpr int kMinTwoViewJoinPoints = 5;

// The points of `merged` seen by a registered image of `a` and one of `b`.
int PointsSeenByBoth(const Reconstruction& merged, const Reconstruction& a, const Reconstruction& b) {
  int count = 0;
  for (const SfmPoint& point : merged.points) {
    if (point.deleted) continue;
    bool in_a = false, in_b = false;
    for (const TrackElement& e : point.track) {
      const size_t i = static_cast<size_t>(e.image_id);
      in_a |= i < a.images.size() && a.images[i].registered;
      in_b |= i < b.images.size() && b.images[i].registered;
    }
    count += in_a && in_b ? 1 : 0;
  }
  return count;
}

// Merges into the largest model every other model that aligns with it (model_merge.h), largest
// first, each union grown again over every pair and adjusted as one; a merged model leaves
// `models`. A model that does not align keeps why in its report (MapperReport::not_merged).
Status MergeIntoLargest(const std::vector<MapperImage>& images, const std::vector<MapperPair>& pairs,
                        const MapperOptions& options, std::vector<Reconstruction>* models,
                        std::vector<MapperReport>* reports) {
  ModelMergeOptions merge_options;
  merge_options.max_error_px = options.max_reprojection_error_px;
  merge_options.min_inliers = options.merge_min_shared_points;
  const std::set<std::pair<int, int>> no_excluded_starts;
  bool merged = true;
  while (merged && models->size() > 1) {
    merged = false;
    std::vector<size_t> order(models->size());
    for (size_t m = 0; m < order.size(); ++m) order[m] = m;
    std::stable_sort(order.begin(), order.end(), [models](size_t a, size_t b) {
      return (*models)[a].NumRegisteredImages() > (*models)[b].NumRegisteredImages();
    });
    const size_t main = order[0];
    for (size_t k = 1; k < order.size() && !merged; ++k) {
      const size_t other = order[k];
      MapperReport& other_report = (*reports)[other];
      Result<ModelAlignment> alignment = AlignModels((*models)[main], (*models)[other], pairs, merge_options);
      if (!alignment.ok()) {
        const Result<ModelAlignment> by_pair = AlignModelsByTwoViewGeometry(
            (*models)[main], (*models)[other], pairs, options, kMinTwoViewJoinPoints);
        if (!by_pair.ok()) {
          other_report.not_merged = alignment.status().message() + "; " + by_pair.status().message();
          continue;
        }
        alignment = by_pair;
      }
      const Reconstruction seed = CombineRegisteredImages((*models)[main], (*models)[other], alignment->to_from_from);
      MapperReport merged_report;
      Mapper mapper(images, pairs, options, &merged_report, no_excluded_starts, nullptr);
      const Status status = mapper.Run(nullptr, &seed);
      if (!status.ok()) {
        if (status.code() != StatusCode::kFailedPrecondition) return status;
        other_report.not_merged = "the merged model failed: " + status.message();
        continue;
      }
      Reconstruction merged_model = mapper.TakeResult();
      const int joint_points = PointsSeenByBoth(merged_model, (*models)[main], (*models)[other]);
      if (joint_points < options.merge_min_shared_points) {
        other_report.not_merged = "aligned by " + std::to_string(alignment->num_inliers) +
                                  " shared points, but the joined model has " + std::to_string(joint_points) +
                                  " points seen from both (need " + std::to_string(options.merge_min_shared_points) + ")";
        continue;
      }
      const MapperReport& main_report = (*reports)[main];
      merged_report.initial_pair = main_report.initial_pair;
      merged_report.initial_image_a = main_report.initial_image_a;
      merged_report.initial_image_b = main_report.initial_image_b;
      merged_report.init_starts = main_report.init_starts;
      merged_report.init_relaxations = main_report.init_relaxations;
      merged_report.init_pairs_scored = main_report.init_pairs_scored;
      merged_report.merges = main_report.merges;
      merged_report.merges.push_back(
          {other_report.initial_pair, (*models)[other].NumRegisteredImages(), alignment->num_shared_points,
           alignment->num_inliers,
           alignment->pair_to_image < 0 ? std::string("shared points")
                                        : "the two-view geometry of " + images[static_cast<size_t>(alignment->pair_to_image)].name +
                                              " + " + images[static_cast<size_t>(alignment->pair_from_image)].name});
      merged_report.seconds_total += main_report.seconds_total;
      merged_report.seconds_ba += main_report.seconds_ba;
      merged_report.num_local_ba += main_report.num_local_ba;
      merged_report.num_global_ba += main_report.num_global_ba;
      if (merged_report.first_ba_failure.empty()) merged_report.first_ba_failure = main_report.first_ba_failure;
      merged_report.num_failed_ba += main_report.num_failed_ba;
      merged_report.num_registered_from_neighbour += main_report.num_registered_from_neighbour;
      (*models)[main] = std::move(merged_model);
      (*reports)[main] = std::move(merged_report);
      models->erase(models->begin() + static_cast<std::ptrdiff_t>(other));
      reports->erase(reports->begin() + static_cast<std::ptrdiff_t>(other));
      merged = true;
    }
  }
  return Status::Ok();
}

}  // namespace

Result<Reconstruction> ContinueIncrementalMapper(const std::vector<MapperImage>& images,
                                                 const std::vector<MapperPair>& pairs, const MapperOptions& options,
                                                 const Reconstruction& previous, MapperContinuation* continuation,
                                                 MapperReport* report, const MapperProgress& progress) {
  RECONAR_RETURN_IF_ERROR(options.Check());
  MapperReport local_report;
  if (report == nullptr) report = &local_report;
  *report = MapperReport();
  if (previous.NumRegisteredImages() < 2) return InvalidArgument("mapper: continuing a model of fewer than two images");
  const std::set<std::pair<int, int>> no_excluded_starts;
  Mapper mapper(images, pairs, options, report, no_excluded_starts, nullptr);
  RECONAR_RETURN_IF_ERROR(mapper.Run(progress, &previous, continuation));
  return mapper.TakeResult();
}

Result<Reconstruction> RunIncrementalMapper(const std::vector<MapperImage>& images,
                                            const std::vector<MapperPair>& pairs, const MapperOptions& options,
                                            MapperReport* report, const MapperProgress& progress,
                                            std::vector<Reconstruction>* other_models) {
  RECONAR_RETURN_IF_ERROR(options.Check());
  MapperReport local_report;
  if (report == nullptr) report = &local_report;
  *report = MapperReport();
  if (images.size() < 2) {
    return FailedPrecondition("structure from motion needs at least two images, got " + std::to_string(images.size()));
  }
  // Each further model runs over every image, with only the pairs between images no model holds.
  std::vector<Reconstruction> models;
  std::vector<MapperReport> reports;
  std::vector<int> model_of(images.size(), -1);
  std::vector<MapperPair> remaining = pairs;
  while (models.empty() || (static_cast<int>(models.size()) < options.max_models && !remaining.empty())) {
    MapperReport model_report;
    Reconstruction model;
    RECONAR_ASSIGN_OR_RETURN(
        const bool started,
        RunWithRestarts(images, remaining, options, models.empty() ? progress : nullptr, &model, &model_report));
    if (!started) {
      if (models.empty()) {
        *report = model_report;
        return FailedPrecondition(model_report.failed_start);
      }
      break;
    }
    if (!models.empty() && model.NumRegisteredImages() < 3) break;
    for (size_t i = 0; i < model.images.size(); ++i) {
      if (model.images[i].registered) model_of[i] = static_cast<int>(models.size());
    }
    models.push_back(std::move(model));
    reports.push_back(std::move(model_report));
    std::vector<MapperPair> left;
    for (MapperPair& pair : remaining) {
      if (model_of[static_cast<size_t>(pair.matches.image_a)] < 0 &&
          model_of[static_cast<size_t>(pair.matches.image_b)] < 0)
        left.push_back(std::move(pair));
    }
    remaining = std::move(left);
  }
  if (options.merge_models) RECONAR_RETURN_IF_ERROR(MergeIntoLargest(images, pairs, options, &models, &reports));
  // The main model is the largest; the others follow from the largest down.
  std::vector<size_t> order(models.size());
  for (size_t m = 0; m < order.size(); ++m) order[m] = m;
  std::stable_sort(order.begin(), order.end(), [&models](size_t a, size_t b) {
    return models[a].NumRegisteredImages() > models[b].NumRegisteredImages();
  });
  const size_t main = order[0];
  *report = reports[main];
  report->models.clear();
  for (size_t m : order) {
    MapperReport::Model summary;
    for (const SfmImage& image : models[m].images) {
      if (image.registered) summary.images.push_back(image.name);
    }
    summary.num_points = reports[m].num_points;
    summary.initial_pair = reports[m].initial_pair;
    summary.not_merged = reports[m].not_merged;
    report->models.push_back(std::move(summary));
  }
  for (MapperReport::Unregistered& u : report->unregistered) {
    bool in_model = false;
    for (size_t k = 1; k < order.size(); ++k) {
      const std::vector<std::string>& in = report->models[k].images;
      if (std::find(in.begin(), in.end(), u.name) == in.end()) continue;
      in_model = true;
      u.reason = "in model " + std::to_string(k + 1) + " (" + std::to_string(in.size()) +
                 " images); not in this one: " + u.reason;
    }
    if (in_model) continue;
    // In no model: the first reason from a run that tried the image, else the first run's.
    std::string reason;
    for (const MapperReport& r : reports) {
      for (const MapperReport::Unregistered& other : r.unregistered) {
        if (other.name != u.name) continue;
        if (reason.empty()) reason = other.reason;
        if (other.reason != kNoVerifiedMatches && other.reason != kNotConnected &&
            (reason == kNoVerifiedMatches || reason == kNotConnected))
          reason = other.reason;
      }
    }
    if (!reason.empty()) u.reason = reason;
  }
  if (other_models != nullptr) {
    other_models->clear();
    for (size_t k = 1; k < order.size(); ++k) other_models->push_back(std::move(models[order[k]]));
  }
  return std::move(models[main]);
}

}  // namespace reconar
