#include "core/sfm/mapper.h"

#include <chrono>
#include <cmath>
#include <utility>

#include "core/base/elapsed.h"
#include "core/sfm/image_registration.h"
#include "core/sfm/initial_pair.h"
#include "core/sfm/intrinsics_selection.h"
#include "core/sfm/mapper_adjustment.h"
#include "core/sfm/mapper_model.h"
#include "core/sfm/next_image.h"
#include "core/sfm/point_filter.h"
#include "core/sfm/track_triangulation.h"

namespace reconar {
namespace {

using Clock = std::chrono::steady_clock;

// The orchestration: setup, the initial pair, the growth loop (next image, registration,
// triangulation, local or global adjustment, filtering), the global refinements and the report.
class Mapper {
 public:
  Mapper(const std::vector<MapperImage>& images, const std::vector<MapperPair>& pairs, const MapperOptions& options,
         MapperReport* report)
      : images_(images), pairs_(pairs), opt_(options), report_(report) {}

  Status Run(const MapperProgress& progress) {
    const auto start = Clock::now();
    RECONAR_RETURN_IF_ERROR(Setup());
    RECONAR_RETURN_IF_ERROR(InitializeFromBestPair(&model_, images_, pairs_, opt_, report_));
    if (progress) progress(model_.rec.NumRegisteredImages(), static_cast<int>(images_.size()));
    int last_global = model_.rec.NumRegisteredImages();
    while (true) {
      bool registered_one = false;
      RECONAR_ASSIGN_OR_RETURN(registered_one, RegisterNextImage());
      if (!registered_one) break;
      const int registered = model_.rec.NumRegisteredImages();
      if (registered >= opt_.global_ba_growth * last_global) {
        RECONAR_RETURN_IF_ERROR(GlobalRefinement(GrowthAdjustment(opt_.global_ba_iterations)));
        last_global = registered;
      }
      if (progress) progress(registered, static_cast<int>(images_.size()));
    }
    RECONAR_RETURN_IF_ERROR(GlobalRefinement(GrowthAdjustment(opt_.global_ba_iterations)));
    IntrinsicsChoice choice;
    RECONAR_ASSIGN_OR_RETURN(choice, SelectIntrinsicsModel(&model_, images_, opt_, report_));
    MapperAdjustment final_adjustment;
    final_adjustment.iterations = opt_.final_ba_iterations;
    final_adjustment.function_tolerance = opt_.final_ba_function_tolerance;
    final_adjustment.free = choice;
    RECONAR_RETURN_IF_ERROR(GlobalRefinement(final_adjustment));
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
    model_.failure.assign(static_cast<size_t>(n), "no verified matches to other images");
    model_.tried_with.assign(static_cast<size_t>(n), -1);
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
      model_.failure[static_cast<size_t>(m.image_a)] = model_.failure[static_cast<size_t>(m.image_b)] =
          "not connected to the reconstructed images";
    }
    model_.SetTracks(BuildTracks(num_keypoints, matches));
    report_->num_tracks = static_cast<int>(model_.tracks.tracks.size());
    report_->num_inconsistent_tracks = model_.tracks.num_inconsistent;
    return Status::Ok();
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
  // with MapperOptions::refine_distortion (from three registered images on).
  MapperAdjustment GrowthAdjustment(int iterations) const {
    MapperAdjustment adjustment;
    adjustment.iterations = iterations;
    adjustment.free.distortion = opt_.refine_distortion;
    return adjustment;
  }

  // Registers the next image (next_image.h) that succeeds, triangulates its tracks and adjusts
  // around it (globally when its registration set a focal); false when no image registers.
  Result<bool> RegisterNextImage() {
    for (const NextImageCandidate& candidate : NextImageCandidates(&model_, images_, opt_)) {
      model_.tried_with[static_cast<size_t>(candidate.image)] = candidate.visible;
      bool focal_changed = false;
      if (!RegisterImage(&model_, images_, candidate.image, opt_, &focal_changed)) continue;
      TriangulateImage(&model_, candidate.image, opt_);
      if (focal_changed) {
        RECONAR_RETURN_IF_ERROR(GlobalRefinement(GrowthAdjustment(opt_.global_ba_iterations)));
      } else {
        const std::vector<int> local = LocalBundle(model_, candidate.image, opt_);
        RECONAR_RETURN_IF_ERROR(Adjust(local, GrowthAdjustment(opt_.local_ba_iterations)));
        FilterPoints(&model_, model_.PointsSeenBy(local), opt_);
      }
      return true;
    }
    return false;
  }

  // A bundle adjustment whose numeric failure is counted and leaves the model as it was.
  Status Adjust(const std::vector<int>& variable, const MapperAdjustment& adjustment) {
    return CountFailedAdjustment(BundleAdjust(&model_, images_, variable, adjustment, opt_, report_).status(), report_);
  }

  Status GlobalRefinement(const MapperAdjustment& adjustment) {
    RECONAR_RETURN_IF_ERROR(Adjust(model_.RegisteredImages(), adjustment));
    FilterPoints(&model_, model_.AllPoints(), opt_);
    RetriangulateAll(&model_, opt_);
    RECONAR_RETURN_IF_ERROR(Adjust(model_.RegisteredImages(), adjustment));
    FilterPoints(&model_, model_.AllPoints(), opt_);
    return Status::Ok();
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
      if (!rec.images[i].registered) report_->unregistered.push_back({rec.images[i].name, model_.failure[i]});
    }
  }

  const std::vector<MapperImage>& images_;
  const std::vector<MapperPair>& pairs_;
  const MapperOptions& opt_;
  MapperReport* report_;
  MapperModel model_;
};

}  // namespace

Status MapperOptions::Check() const {
  if (init_min_points < 8) return InvalidArgument("MapperOptions: init_min_points < 8");
  if (!(init_min_median_angle_deg >= 0.0)) return InvalidArgument("MapperOptions: init_min_median_angle_deg < 0");
  if (init_max_pairs_tried < 1) return InvalidArgument("MapperOptions: init_max_pairs_tried < 1");
  if (init_min_points_floor < 8 || init_min_points_floor > init_min_points) {
    return InvalidArgument("MapperOptions: init_min_points_floor must be in [8, init_min_points]");
  }
  if (!(init_min_angle_floor_deg >= 0.0 && init_min_angle_floor_deg <= init_min_median_angle_deg)) {
    return InvalidArgument("MapperOptions: init_min_angle_floor_deg must be in [0, init_min_median_angle_deg]");
  }
  if (!(registration_max_error_px > 0.0)) return InvalidArgument("MapperOptions: registration_max_error_px <= 0");
  if (registration_min_inliers < 6) return InvalidArgument("MapperOptions: registration_min_inliers < 6");
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

Result<Reconstruction> RunIncrementalMapper(const std::vector<MapperImage>& images,
                                            const std::vector<MapperPair>& pairs, const MapperOptions& options,
                                            MapperReport* report, const MapperProgress& progress) {
  RECONAR_RETURN_IF_ERROR(options.Check());
  MapperReport local_report;
  if (report == nullptr) report = &local_report;
  *report = MapperReport();
  if (images.size() < 2) {
    return FailedPrecondition("structure from motion needs at least two images, got " + std::to_string(images.size()));
  }
  Mapper mapper(images, pairs, options, report);
  RECONAR_RETURN_IF_ERROR(mapper.Run(progress));
  return mapper.TakeResult();
}

}  // namespace reconar
