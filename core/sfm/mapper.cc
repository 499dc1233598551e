#include "core/sfm/mapper.h"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <numeric>

#include "core/geometry/absolute_pose.h"
#include "core/geometry/essential_five_point.h"
#include "core/geometry/ransac.h"
#include "core/geometry/relative_pose.h"
#include "core/geometry/triangulation.h"
#include "core/math/rotation.h"
#include "core/optim/bundle_adjuster.h"

namespace reconar {
namespace {

constexpr double kDegree = M_PI / 180.0;
using Clock = std::chrono::steady_clock;

double SecondsSince(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

class Mapper {
 public:
  Mapper(const std::vector<MapperImage>& images, const std::vector<MapperPair>& pairs,
         const MapperOptions& options, MapperReport* report)
      : images_(images), pairs_(pairs), opt_(options), report_(report), distortion_free_(options.refine_distortion) {}

  Status Run(const MapperProgress& progress) {
    const auto start = Clock::now();
    RECONAR_RETURN_IF_ERROR(Setup());
    RECONAR_RETURN_IF_ERROR(Initialize());
    if (progress) progress(rec_.NumRegisteredImages(), static_cast<int>(images_.size()));
    int last_global = rec_.NumRegisteredImages();
    while (RegisterNextImage()) {
      const int registered = rec_.NumRegisteredImages();
      if (registered >= opt_.global_ba_growth * last_global) {
        GlobalRefinement(opt_.global_ba_iterations, /*refine_principal_point=*/false);
        last_global = registered;
      }
      if (progress) progress(registered, static_cast<int>(images_.size()));
    }
    GlobalRefinement(opt_.global_ba_iterations, /*refine_principal_point=*/false);
    function_tolerance_ = opt_.final_ba_function_tolerance;
    const IntrinsicsChoice choice = SelectIntrinsicsModel();
    GlobalRefinement(opt_.final_ba_iterations, choice);
    FinishReport();
    report_->seconds_total = SecondsSince(start);
    return Status::Ok();
  }

  Reconstruction TakeResult() { return std::move(rec_); }

 private:
  // ---- setup ----------------------------------------------------------------------------------

  Status Setup() {
    const int n = static_cast<int>(images_.size());
    report_->num_images = n;
    std::vector<int> num_keypoints(static_cast<size_t>(n));
    rec_.images.resize(static_cast<size_t>(n));
    failure_.assign(static_cast<size_t>(n), "no verified matches to other images");
    tried_with_.assign(static_cast<size_t>(n), -1);
    for (int i = 0; i < n; ++i) {
      const MapperImage& in = images_[static_cast<size_t>(i)];
      if (in.width <= 0 || in.height <= 0 || !(in.focal_prior > 0.0)) {
        return InvalidArgument(in.name + ": image size and focal prior must be positive");
      }
      SfmImage& image = rec_.images[static_cast<size_t>(i)];
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
      if (m.image_a < 0 || m.image_a >= n || m.image_b < 0 || m.image_b >= n ||
          m.image_a == m.image_b) {
        return InvalidArgument("mapper: a pair names a missing image");
      }
      for (const FeatureMatch& f : m.matches) {
        if (f.index_a < 0 || f.index_a >= num_keypoints[static_cast<size_t>(m.image_a)] ||
            f.index_b < 0 || f.index_b >= num_keypoints[static_cast<size_t>(m.image_b)]) {
          return InvalidArgument("mapper: a match between " + images_[static_cast<size_t>(m.image_a)].name +
                                 " and " + images_[static_cast<size_t>(m.image_b)].name +
                                 " indexes a missing keypoint");
        }
      }
      matches.push_back(m);
      failure_[static_cast<size_t>(m.image_a)] = failure_[static_cast<size_t>(m.image_b)] =
          "not connected to the reconstructed images";
    }
    tracks_ = BuildTracks(num_keypoints, matches);
    point_of_track_.assign(tracks_.tracks.size(), -1);
    report_->num_tracks = static_cast<int>(tracks_.tracks.size());
    report_->num_inconsistent_tracks = tracks_.num_inconsistent;
    return Status::Ok();
  }

  // The camera of image i under the sharing rule, created when no earlier image shares it.
  int CameraFor(int i) {
    const MapperImage& in = images_[static_cast<size_t>(i)];
    for (int j = 0; j < i && opt_.camera_sharing != MapperOptions::CameraSharing::kPerImage; ++j) {
      const MapperImage& other = images_[static_cast<size_t>(j)];
      if (other.width != in.width || other.height != in.height) continue;
      const bool same = opt_.camera_sharing == MapperOptions::CameraSharing::kSingle ||
                        (in.focal_from_exif == other.focal_from_exif &&
                         (!in.focal_from_exif || other.focal_prior == in.focal_prior));
      if (same) return rec_.images[static_cast<size_t>(j)].camera_id;
    }
    SfmCamera camera;
    camera.width = in.width;
    camera.height = in.height;
    camera.focal = in.focal_prior;
    camera.cx = 0.5 * (in.width - 1);
    camera.cy = 0.5 * (in.height - 1);
    rec_.cameras.push_back(camera);
    camera_prior_.push_back(in.focal_prior);
    camera_from_exif_.push_back(in.focal_from_exif);
    return static_cast<int>(rec_.cameras.size()) - 1;
  }

  bool CameraShared() const { return rec_.cameras.size() < rec_.images.size(); }

  // Registered images using `camera`.
  int CameraUsers(int camera) const {
    int n = 0;
    for (const SfmImage& image : rec_.images) n += (image.registered && image.camera_id == camera) ? 1 : 0;
    return n;
  }

  // ---- initialisation -------------------------------------------------------------------------

  Status Initialize() {
    std::vector<int> order;
    for (size_t p = 0; p < pairs_.size(); ++p) {
      if (!pairs_[p].planar) order.push_back(static_cast<int>(p));
    }
    std::stable_sort(order.begin(), order.end(), [this](int a, int b) {
      return pairs_[static_cast<size_t>(a)].matches.matches.size() >
             pairs_[static_cast<size_t>(b)].matches.matches.size();
    });
    if (order.empty()) {
      return FailedPrecondition(
          "no image pair has enough verified matches with parallax to start a reconstruction "
          "(the photos may be unrelated, too few, or taken from one spot)");
    }
    // Texture-poor scenes may have no pair that meets the bounds: like COLMAP's mapper, retry with
    // the point count and the angle halved, down to init_min_points_floor / init_min_angle_floor.
    std::string last_reason;
    const int tries = std::min(static_cast<int>(order.size()), opt_.init_max_pairs_tried);
    init_min_points_ = opt_.init_min_points;
    init_min_angle_deg_ = opt_.init_min_median_angle_deg;
    for (int round = 0;; ++round) {
      for (int k = 0; k < tries; ++k) {
        const MapperPair& pair = pairs_[static_cast<size_t>(order[static_cast<size_t>(k)])];
        last_reason = TryInitialPair(pair);
        if (last_reason.empty()) {
          report_->initial_pair = images_[static_cast<size_t>(pair.matches.image_a)].name + " + " +
                                  images_[static_cast<size_t>(pair.matches.image_b)].name;
          report_->init_relaxations = round;
          return Status::Ok();
        }
      }
      const int next_points = std::max(opt_.init_min_points_floor, init_min_points_ / 2);
      const double next_angle = std::max(opt_.init_min_angle_floor_deg, init_min_angle_deg_ / 2.0);
      if (next_points == init_min_points_ && next_angle == init_min_angle_deg_) break;
      init_min_points_ = next_points;
      init_min_angle_deg_ = next_angle;
    }
    return FailedPrecondition("no initial pair found among the " + std::to_string(tries) +
                              " best-matched pairs, even with the bounds relaxed to " +
                              std::to_string(init_min_points_) + " points and " +
                              std::to_string(init_min_angle_deg_) + " deg; last: " + last_reason);
  }

  // Empty on success; otherwise the reason, with the model reset.
  std::string TryInitialPair(const MapperPair& pair) {
    const int a = pair.matches.image_a, b = pair.matches.image_b;
    const SfmCamera& ca = rec_.cameras[static_cast<size_t>(rec_.images[static_cast<size_t>(a)].camera_id)];
    const SfmCamera& cb = rec_.cameras[static_cast<size_t>(rec_.images[static_cast<size_t>(b)].camera_id)];
    std::vector<Correspondence> samples;
    samples.reserve(pair.matches.matches.size());
    for (const FeatureMatch& m : pair.matches.matches) {
      const Eigen::Vector2d& xa = rec_.images[static_cast<size_t>(a)].keypoints[static_cast<size_t>(m.index_a)];
      const Eigen::Vector2d& xb = rec_.images[static_cast<size_t>(b)].keypoints[static_cast<size_t>(m.index_b)];
      samples.push_back({Eigen::Vector2d((xa.x() - ca.cx) / ca.focal, (xa.y() - ca.cy) / ca.focal),
                         Eigen::Vector2d((xb.x() - cb.cx) / cb.focal, (xb.y() - cb.cy) / cb.focal)});
    }
    RansacOptions ransac;
    ransac.max_residual = opt_.max_reprojection_error_px / std::sqrt(ca.focal * cb.focal);
    const auto essential = Ransac<EssentialFivePoint>::Run(samples.data(), static_cast<int>(samples.size()), ransac);
    const std::string pair_name = images_[static_cast<size_t>(a)].name + " + " + images_[static_cast<size_t>(b)].name;
    if (!essential.ok() || essential->status != RansacStatus::kSuccess) {
      return pair_name + ": no essential matrix";
    }
    std::vector<Correspondence> inliers;
    for (size_t i = 0; i < samples.size(); ++i) {
      if (essential->inlier_mask[i]) inliers.push_back(samples[i]);
    }
    const auto pose = RelativePoseFromEssential(essential->model, inliers.data(), static_cast<int>(inliers.size()));
    if (!pose.ok()) return pair_name + ": " + pose.status().message();

    SfmImage& ia = rec_.images[static_cast<size_t>(a)];
    SfmImage& ib = rec_.images[static_cast<size_t>(b)];
    ia.cam_from_world = Rigid3();
    ib.cam_from_world.rotation = pose->R;
    ib.cam_from_world.translation = pose->t;
    ia.registered = ib.registered = true;
    TriangulateImage(b);
    std::string reason = CheckInitialModel(pair_name);
    if (reason.empty()) {
      BundleAdjust(RegisteredImages(), opt_.global_ba_iterations, /*refine_principal_point=*/false);
      FilterPoints(AllPoints());
      reason = CheckInitialModel(pair_name);
    }
    if (!reason.empty()) {
      ResetModel();
      return reason;
    }
    return "";
  }

  std::string CheckInitialModel(const std::string& pair_name) {
    std::vector<double> angles;
    for (size_t p = 0; p < rec_.points.size(); ++p) {
      if (!rec_.points[p].deleted) angles.push_back(MaxTriangulationAngle(rec_.points[p]));
    }
    if (static_cast<int>(angles.size()) < init_min_points_) {
      return pair_name + ": only " + std::to_string(angles.size()) + " points triangulated (need " +
             std::to_string(init_min_points_) + ")";
    }
    std::nth_element(angles.begin(), angles.begin() + static_cast<std::ptrdiff_t>(angles.size() / 2), angles.end());
    const double median = angles[angles.size() / 2];
    if (median < init_min_angle_deg_ * kDegree) {
      return pair_name + ": median triangulation angle " + std::to_string(median / kDegree) +
             " deg is below " + std::to_string(init_min_angle_deg_) + " deg";
    }
    return "";
  }

  void ResetModel() {
    for (SfmImage& image : rec_.images) {
      image.registered = false;
      std::fill(image.point3d_ids.begin(), image.point3d_ids.end(), -1);
    }
    for (size_t c = 0; c < rec_.cameras.size(); ++c) {
      rec_.cameras[c].focal = camera_prior_[c];
      rec_.cameras[c].k1 = rec_.cameras[c].k2 = 0.0;
    }
    rec_.points.clear();
    track_of_point_.clear();
    std::fill(point_of_track_.begin(), point_of_track_.end(), -1);
  }

  // ---- registration ---------------------------------------------------------------------------

  // Registers the unregistered image with the most visible points that succeeds; false when
  // none does.
  bool RegisterNextImage() {
    std::vector<std::pair<int, int>> candidates;  // (visible points, image)
    for (size_t i = 0; i < rec_.images.size(); ++i) {
      if (rec_.images[i].registered) continue;
      const int visible = CountVisiblePoints(static_cast<int>(i));
      if (visible == 0) continue;
      if (visible < opt_.registration_min_inliers) {
        failure_[i] = "sees only " + std::to_string(visible) + " reconstructed points (need " +
                      std::to_string(opt_.registration_min_inliers) + ")";
        continue;
      }
      if (visible <= tried_with_[i]) continue;  // failed before and nothing new is visible
      candidates.emplace_back(visible, static_cast<int>(i));
    }
    std::stable_sort(candidates.begin(), candidates.end(),
                     [](const auto& x, const auto& y) { return x.first > y.first; });
    for (const auto& [visible, image] : candidates) {
      tried_with_[static_cast<size_t>(image)] = visible;
      needs_global_adjustment_ = false;
      if (RegisterImage(image)) {
        TriangulateImage(image);
        if (needs_global_adjustment_) {
          GlobalRefinement(opt_.global_ba_iterations, /*refine_principal_point=*/false);
        } else {
          std::vector<int> local = LocalBundle(image);
          BundleAdjust(local, opt_.local_ba_iterations, /*refine_principal_point=*/false);
          FilterPoints(PointsSeenBy(local));
        }
        return true;
      }
    }
    return false;
  }

  int CountVisiblePoints(int image) const {
    int count = 0;
    const std::vector<int>& track_of = tracks_.track_of[static_cast<size_t>(image)];
    for (int t : track_of) count += (t >= 0 && point_of_track_[static_cast<size_t>(t)] >= 0) ? 1 : 0;
    return count;
  }

  // Intrinsics guess for an image about to be registered: its camera when that camera is in use
  // or has an EXIF focal, otherwise the mean of the registered cameras of the same size without
  // EXIF (the same device, most likely), otherwise the prior.
  SfmCamera GuessCamera(int image) const {
    const int camera_id = rec_.images[static_cast<size_t>(image)].camera_id;
    SfmCamera camera = rec_.cameras[static_cast<size_t>(camera_id)];
    if (CameraUsers(camera_id) > 0 || camera_from_exif_[static_cast<size_t>(camera_id)]) return camera;
    double focal_sum = 0.0, k1_sum = 0.0, k2_sum = 0.0;
    int n = 0;
    for (size_t i = 0; i < rec_.images.size(); ++i) {
      const int other_id = rec_.images[i].camera_id;
      const SfmCamera& other = rec_.cameras[static_cast<size_t>(other_id)];
      if (!rec_.images[i].registered || other.width != camera.width || other.height != camera.height) continue;
      if (camera_from_exif_[static_cast<size_t>(other_id)]) continue;
      focal_sum += other.focal;
      k1_sum += other.k1;
      k2_sum += other.k2;
      ++n;
    }
    if (n > 0) {
      camera.focal = focal_sum / n;
      camera.k1 = k1_sum / n;
      camera.k2 = k2_sum / n;
    }
    return camera;
  }

  bool RegisterImage(int image) {
    SfmImage& img = rec_.images[static_cast<size_t>(image)];
    std::vector<Eigen::Vector2d> pixels;
    std::vector<Eigen::Vector3d> world;
    std::vector<int> keypoint_of;
    const std::vector<int>& track_of = tracks_.track_of[static_cast<size_t>(image)];
    for (size_t kp = 0; kp < track_of.size(); ++kp) {
      const int t = track_of[kp];
      if (t < 0 || point_of_track_[static_cast<size_t>(t)] < 0) continue;
      pixels.push_back(img.keypoints[kp]);
      world.push_back(rec_.points[static_cast<size_t>(point_of_track_[static_cast<size_t>(t)])].position);
      keypoint_of.push_back(static_cast<int>(kp));
    }
    SfmCamera camera = GuessCamera(image);
    const RadialCamera& pose_camera = camera;  // with its aspect ratio
    // Until three images confirm a camera's focal, the model is shaped by a prior the data has not
    // checked: register with the focal free, under a looser bound, falling back to the DLT for an
    // unknown focal; a global adjustment with the focal free follows (RegisterNextImage).
    const int camera_id = img.camera_id;
    const bool exif = images_[static_cast<size_t>(image)].focal_from_exif;
    const bool focal_confirmed = CameraUsers(camera_id) >= 3 || !opt_.refine_focal;
    AbsolutePoseOptions options;
    options.max_error_px = opt_.registration_max_error_px * (focal_confirmed ? 1.0 : 2.0);
    options.min_inliers = opt_.registration_min_inliers;
    options.refine_focal = !focal_confirmed;
    auto result = EstimateAbsolutePose(pixels, world, pose_camera, options);
    if (result.ok() && !result->success() && !focal_confirmed) {
      result = EstimateAbsolutePoseUnknownFocal(pixels, world, pose_camera, options);
    }
    if (!result.ok() || !result->success()) {
      failure_[static_cast<size_t>(image)] =
          "pose from " + std::to_string(pixels.size()) + " 2D-3D correspondences failed: " +
          (result.ok() ? result->reason : result.status().message());
      return false;
    }
    if (!focal_confirmed && result->focal > 0.0) {
      // Paper eq. 5: the EXIF focal is kept when it lies within 0.7-1.4 of the data's estimate.
      double focal = result->focal;
      const double prior = images_[static_cast<size_t>(image)].focal_prior;
      if (exif && prior > opt_.focal_prior_min_ratio * focal && prior < opt_.focal_prior_max_ratio * focal) {
        focal = prior;
      }
      camera.focal = focal;
      rec_.cameras[static_cast<size_t>(camera_id)] = camera;
      needs_global_adjustment_ = true;
    }
    img.cam_from_world.rotation = result->cam_from_world.rotation;
    img.cam_from_world.translation = result->cam_from_world.translation;
    img.registered = true;
    for (int index : result->inliers) {
      const int kp = keypoint_of[static_cast<size_t>(index)];
      const int t = track_of[static_cast<size_t>(kp)];
      AddObservation(point_of_track_[static_cast<size_t>(t)], image, kp);
    }
    failure_[static_cast<size_t>(image)].clear();
    return true;
  }

  // ---- points ---------------------------------------------------------------------------------

  double SquaredError(const Eigen::Vector3d& position, int image, int kp) const {
    const SfmImage& img = rec_.images[static_cast<size_t>(image)];
    const Eigen::Vector3d cam = img.cam_from_world * position;
    if (!(cam.z() > 0.0)) return std::numeric_limits<double>::infinity();
    const Eigen::Vector2d predicted = rec_.cameras[static_cast<size_t>(img.camera_id)].Project(cam);
    return (predicted - img.keypoints[static_cast<size_t>(kp)]).squaredNorm();
  }

  double MaxTriangulationAngle(const SfmPoint& point) const {
    const size_t n = std::min<size_t>(point.track.size(), 30);
    double best_cos = 1.0;
    for (size_t i = 0; i < n; ++i) {
      const Eigen::Vector3d ri =
          (rec_.images[static_cast<size_t>(point.track[i].image_id)].Center() - point.position).normalized();
      for (size_t j = i + 1; j < n; ++j) {
        const Eigen::Vector3d rj =
            (rec_.images[static_cast<size_t>(point.track[j].image_id)].Center() - point.position).normalized();
        best_cos = std::min(best_cos, ri.dot(rj));
      }
    }
    return std::acos(std::clamp(best_cos, -1.0, 1.0));
  }

  void AddObservation(int point_id, int image, int kp) {
    SfmPoint& point = rec_.points[static_cast<size_t>(point_id)];
    point.track.push_back({image, kp});
    rec_.images[static_cast<size_t>(image)].point3d_ids[static_cast<size_t>(kp)] = point_id;
  }

  void DeletePoint(int point_id) {
    SfmPoint& point = rec_.points[static_cast<size_t>(point_id)];
    for (const TrackElement& e : point.track) {
      rec_.images[static_cast<size_t>(e.image_id)].point3d_ids[static_cast<size_t>(e.keypoint_id)] = -1;
    }
    point.track.clear();
    point.deleted = true;
    point_of_track_[static_cast<size_t>(track_of_point_[static_cast<size_t>(point_id)])] = -1;
  }

  // TriangulateMultiView (core/geometry/triangulation.h) of the undistorted keypoints. False when
  // the views do not determine a point or a keypoint cannot be undistorted.
  bool Triangulate(const std::vector<TrackElement>& views, Eigen::Vector3d* position) const {
    std::vector<TriangulationView> observations(views.size());
    for (size_t v = 0; v < views.size(); ++v) {
      const SfmImage& img = rec_.images[static_cast<size_t>(views[v].image_id)];
      const SfmCamera& cam = rec_.cameras[static_cast<size_t>(img.camera_id)];
      TriangulationView& view = observations[v];
      if (!cam.Undistort(img.keypoints[static_cast<size_t>(views[v].keypoint_id)], &view.normalised)) return false;
      view.cam_from_world = Rigid3{img.cam_from_world.rotation, img.cam_from_world.translation};
      view.focal = cam.focal;
    }
    return TriangulateMultiView(observations, position);
  }

  // Triangulates track t from its registered views (all of them, else the best pair of them);
  // creates the point when at least two views agree within the error bound at enough angle.
  bool TriangulateTrack(int t) {
    std::vector<TrackElement> views;
    for (const TrackElement& e : tracks_.tracks[static_cast<size_t>(t)]) {
      if (rec_.images[static_cast<size_t>(e.image_id)].registered) views.push_back(e);
    }
    if (views.size() < 2) return false;
    const double max_error2 = opt_.max_reprojection_error_px * opt_.max_reprojection_error_px;
    const auto inliers_of = [&](const Eigen::Vector3d& x) {
      std::vector<TrackElement> inliers;
      for (const TrackElement& e : views) {
        if (SquaredError(x, e.image_id, e.keypoint_id) <= max_error2) inliers.push_back(e);
      }
      return inliers;
    };
    Eigen::Vector3d x;
    std::vector<TrackElement> inliers;
    if (Triangulate(views, &x)) inliers = inliers_of(x);
    if (inliers.size() < views.size()) {
      const size_t n = std::min<size_t>(views.size(), 12);
      for (size_t i = 0; i < n; ++i) {
        for (size_t j = i + 1; j < n; ++j) {
          Eigen::Vector3d y;
          if (!Triangulate({views[i], views[j]}, &y)) continue;
          std::vector<TrackElement> candidate = inliers_of(y);
          if (candidate.size() > inliers.size()) inliers.swap(candidate);
        }
      }
      if (inliers.size() < 2 || !Triangulate(inliers, &x)) return false;
      inliers = inliers_of(x);
    }
    if (inliers.size() < 2) return false;
    SfmPoint point;
    point.position = x;
    point.track = inliers;
    if (MaxTriangulationAngle(point) < opt_.min_triangulation_angle_deg * kDegree) return false;
    const int id = static_cast<int>(rec_.points.size());
    rec_.points.push_back(SfmPoint{x, {0, 0, 0}, 0.0, {}, false});
    track_of_point_.push_back(t);
    point_of_track_[static_cast<size_t>(t)] = id;
    for (const TrackElement& e : inliers) AddObservation(id, e.image_id, e.keypoint_id);
    return true;
  }

  // New points from the tracks of `image`, and its observations of existing points that the
  // pose estimate did not take (within the error bound).
  void TriangulateImage(int image) {
    const double max_error2 = opt_.max_reprojection_error_px * opt_.max_reprojection_error_px;
    SfmImage& img = rec_.images[static_cast<size_t>(image)];
    const std::vector<int>& track_of = tracks_.track_of[static_cast<size_t>(image)];
    for (size_t kp = 0; kp < track_of.size(); ++kp) {
      const int t = track_of[kp];
      if (t < 0 || img.point3d_ids[kp] >= 0) continue;
      const int point_id = point_of_track_[static_cast<size_t>(t)];
      if (point_id < 0) {
        TriangulateTrack(t);
      } else if (SquaredError(rec_.points[static_cast<size_t>(point_id)].position, image,
                              static_cast<int>(kp)) <= max_error2) {
        AddObservation(point_id, image, static_cast<int>(kp));
      }
    }
  }

  void RetriangulateAll() {
    for (size_t t = 0; t < tracks_.tracks.size(); ++t) {
      if (point_of_track_[t] < 0) TriangulateTrack(static_cast<int>(t));
    }
    // Observations in registered images of already triangulated tracks.
    const double max_error2 = opt_.max_reprojection_error_px * opt_.max_reprojection_error_px;
    for (size_t p = 0; p < rec_.points.size(); ++p) {
      if (rec_.points[p].deleted) continue;
      const int t = track_of_point_[p];
      for (const TrackElement& e : tracks_.tracks[static_cast<size_t>(t)]) {
        const SfmImage& img = rec_.images[static_cast<size_t>(e.image_id)];
        if (!img.registered || img.point3d_ids[static_cast<size_t>(e.keypoint_id)] >= 0) continue;
        if (SquaredError(rec_.points[p].position, e.image_id, e.keypoint_id) <= max_error2) {
          AddObservation(static_cast<int>(p), e.image_id, e.keypoint_id);
        }
      }
    }
  }

  // Drops observations beyond the error bound, then points left with fewer than two views or
  // too little parallax.
  void FilterPoints(const std::vector<int>& point_ids) {
    const double max_error2 = opt_.max_reprojection_error_px * opt_.max_reprojection_error_px;
    for (int id : point_ids) {
      SfmPoint& point = rec_.points[static_cast<size_t>(id)];
      if (point.deleted) continue;
      size_t kept = 0;
      for (const TrackElement& e : point.track) {
        if (SquaredError(point.position, e.image_id, e.keypoint_id) <= max_error2) {
          point.track[kept++] = e;
        } else {
          rec_.images[static_cast<size_t>(e.image_id)].point3d_ids[static_cast<size_t>(e.keypoint_id)] = -1;
        }
      }
      point.track.resize(kept);
      if (kept < 2 || MaxTriangulationAngle(point) < opt_.min_triangulation_angle_deg * kDegree) {
        DeletePoint(id);
      }
    }
  }

  std::vector<int> AllPoints() const {
    std::vector<int> ids;
    for (size_t p = 0; p < rec_.points.size(); ++p) {
      if (!rec_.points[p].deleted) ids.push_back(static_cast<int>(p));
    }
    return ids;
  }

  std::vector<int> PointsSeenBy(const std::vector<int>& images) const {
    std::vector<char> seen(rec_.points.size(), 0);
    for (int image : images) {
      for (int id : rec_.images[static_cast<size_t>(image)].point3d_ids) {
        if (id >= 0) seen[static_cast<size_t>(id)] = 1;
      }
    }
    std::vector<int> ids;
    for (size_t p = 0; p < seen.size(); ++p) {
      if (seen[p]) ids.push_back(static_cast<int>(p));
    }
    return ids;
  }

  std::vector<int> RegisteredImages() const {
    std::vector<int> ids;
    for (size_t i = 0; i < rec_.images.size(); ++i) {
      if (rec_.images[i].registered) ids.push_back(static_cast<int>(i));
    }
    return ids;
  }

  // The new image and the registered images sharing the most points with it.
  std::vector<int> LocalBundle(int image) const {
    std::vector<int> shared(rec_.images.size(), 0);
    for (int id : rec_.images[static_cast<size_t>(image)].point3d_ids) {
      if (id < 0) continue;
      for (const TrackElement& e : rec_.points[static_cast<size_t>(id)].track) {
        if (e.image_id != image) ++shared[static_cast<size_t>(e.image_id)];
      }
    }
    std::vector<int> order;
    for (size_t i = 0; i < shared.size(); ++i) {
      if (shared[i] > 0) order.push_back(static_cast<int>(i));
    }
    std::stable_sort(order.begin(), order.end(),
                     [&](int x, int y) { return shared[static_cast<size_t>(x)] > shared[static_cast<size_t>(y)]; });
    if (static_cast<int>(order.size()) > opt_.local_ba_images) order.resize(static_cast<size_t>(opt_.local_ba_images));
    order.insert(order.begin(), image);
    return order;
  }

  // ---- bundle adjustment ---------------------------------------------------------------------

  double ObservationWeight(const TrackElement& e) const {
    const std::vector<float>& weights = images_[static_cast<size_t>(e.image_id)].keypoint_weights;
    if (!weights.empty() && weights[static_cast<size_t>(e.keypoint_id)] > 0.0f) {
      return weights[static_cast<size_t>(e.keypoint_id)];
    }
    const std::vector<float>& scales = images_[static_cast<size_t>(e.image_id)].keypoint_scales;
    if (!opt_.weight_by_scale || scales.empty()) return 1.0;
    const double scale = scales[static_cast<size_t>(e.keypoint_id)];
    return scale > opt_.base_scale_px ? opt_.base_scale_px / scale : 1.0;
  }

  // Adjusts the cameras `variable`, every point they see, and holds the other registered
  // cameras that see those points constant.
  // Returns the final cost (infinity when the adjustment failed and the model was left as is).
  double BundleAdjust(const std::vector<int>& variable, int iterations, bool refine_principal_point) {
    return BundleAdjust(variable, iterations, IntrinsicsChoice{refine_principal_point, distortion_free_, false});
  }

  struct IntrinsicsChoice {
    bool principal_point = false;
    bool distortion = false;
    bool aspect = false;
  };

  double BundleAdjust(const std::vector<int>& variable, int iterations, const IntrinsicsChoice& free) {
    const auto start = Clock::now();
    std::vector<int> slot_of_image(rec_.images.size(), -1);
    std::vector<int> image_of_slot;
    std::vector<char> constant;
    for (int image : variable) {
      slot_of_image[static_cast<size_t>(image)] = static_cast<int>(image_of_slot.size());
      image_of_slot.push_back(image);
      constant.push_back(0);
    }
    const std::vector<int> point_ids = PointsSeenBy(variable);
    RadialProblem problem;
    problem.points.reserve(3 * point_ids.size());
    for (size_t j = 0; j < point_ids.size(); ++j) {
      const SfmPoint& point = rec_.points[static_cast<size_t>(point_ids[j])];
      problem.points.insert(problem.points.end(), point.position.data(), point.position.data() + 3);
      for (const TrackElement& e : point.track) {
        int& slot = slot_of_image[static_cast<size_t>(e.image_id)];
        if (slot < 0) {
          slot = static_cast<int>(image_of_slot.size());
          image_of_slot.push_back(e.image_id);
          constant.push_back(1);
        }
        const Eigen::Vector2d& x = rec_.images[static_cast<size_t>(e.image_id)].keypoints[static_cast<size_t>(e.keypoint_id)];
        problem.observations.push_back({slot, static_cast<int>(j), x.x(), x.y(), ObservationWeight(e)});
      }
    }
    for (int image : image_of_slot) {
      const SfmImage& img = rec_.images[static_cast<size_t>(image)];
      const SfmCamera& cam = rec_.cameras[static_cast<size_t>(img.camera_id)];
      const Eigen::Vector3d w = AngleAxisFromRotation(img.cam_from_world.rotation);
      const Eigen::Vector3d& t = img.cam_from_world.translation;
      const double block[12] = {w.x(), w.y(), w.z(), t.x(), t.y(), t.z(), cam.focal, cam.k1, cam.k2, cam.cx, cam.cy, cam.aspect};
      problem.cameras.insert(problem.cameras.end(), block, block + 12);
    }
    BundleAdjustmentOptions options;
    options.max_iterations = iterations;
    options.function_tolerance = function_tolerance_;
    options.loss.type = LossType::kCauchy;
    options.loss.scale = opt_.ba_loss_scale_px;
    options.num_threads = opt_.num_threads;
    options.linear_solver = image_of_slot.size() > 200 ? BundleAdjustmentOptions::LinearSolver::kSparseCholesky
                                                       : BundleAdjustmentOptions::LinearSolver::kDenseCholesky;
    BundleAdjustmentConstancy constancy;
    constancy.constant_cameras = constant;
    const bool global = variable.size() == static_cast<size_t>(rec_.NumRegisteredImages());
    // A shared camera is adjusted only when all its images are (global adjustment).
    const bool intrinsics = rec_.NumRegisteredImages() >= 3 && (global || !CameraShared());
    if (CameraShared()) {
      options.linear_solver = BundleAdjustmentOptions::LinearSolver::kDenseCholesky;
      for (int image : image_of_slot) constancy.intrinsics_group.push_back(rec_.images[static_cast<size_t>(image)].camera_id);
    }
    if (!opt_.refine_focal || !intrinsics) constancy.constant_camera_parameters.push_back(6);
    if (!free.distortion || !intrinsics) {
      constancy.constant_camera_parameters.push_back(7);
      constancy.constant_camera_parameters.push_back(8);
    }
    if (!free.principal_point) {
      constancy.constant_camera_parameters.push_back(9);
      constancy.constant_camera_parameters.push_back(10);
    }
    if (!free.aspect) constancy.constant_camera_parameters.push_back(11);
    const auto summary = SolveBundleAdjustment(options, constancy, &problem);
    report_->seconds_ba += SecondsSince(start);
    if (global) {
      ++report_->num_global_ba;
    } else {
      ++report_->num_local_ba;
    }
    if (!summary.ok() || summary->termination == BundleAdjustmentSummary::Termination::kNumericFailure) {
      return std::numeric_limits<double>::infinity();
    }
    for (size_t slot = 0; slot < image_of_slot.size(); ++slot) {
      if (constant[slot]) continue;
      SfmImage& img = rec_.images[static_cast<size_t>(image_of_slot[slot])];
      SfmCamera& cam = rec_.cameras[static_cast<size_t>(img.camera_id)];
      const double* block = problem.camera(static_cast<int>(slot));
      img.cam_from_world.rotation = RotationFromAngleAxis(Eigen::Vector3d(block[0], block[1], block[2]));
      img.cam_from_world.translation = Eigen::Vector3d(block[3], block[4], block[5]);
      cam.focal = block[6];
      cam.k1 = block[7];
      cam.k2 = block[8];
      cam.cx = block[9];
      cam.cy = block[10];
      cam.aspect = block[11];
    }
    for (size_t j = 0; j < point_ids.size(); ++j) {
      rec_.points[static_cast<size_t>(point_ids[j])].position = Eigen::Vector3d(problem.point(static_cast<int>(j)));
    }
    return summary->final_cost;
  }

  void GlobalRefinement(int iterations, const IntrinsicsChoice& free) {
    BundleAdjust(RegisteredImages(), iterations, free);
    FilterPoints(AllPoints());
    RetriangulateAll();
    BundleAdjust(RegisteredImages(), iterations, free);
    FilterPoints(AllPoints());
  }
  void GlobalRefinement(int iterations, bool refine_principal_point) {
    GlobalRefinement(iterations, IntrinsicsChoice{refine_principal_point, distortion_free_, false});
  }

  struct Snapshot {
    std::vector<SfmCamera> cameras;
    std::vector<Rigid3> poses;
    std::vector<Eigen::Vector3d> points;
  };
  Snapshot Save() const {
    Snapshot snapshot{rec_.cameras, {}, {}};
    for (const SfmImage& image : rec_.images) snapshot.poses.push_back(image.cam_from_world);
    for (const SfmPoint& point : rec_.points) snapshot.points.push_back(point.position);
    return snapshot;
  }
  void Restore(const Snapshot& snapshot) {
    rec_.cameras = snapshot.cameras;
    for (size_t i = 0; i < rec_.images.size(); ++i) rec_.images[i].cam_from_world = snapshot.poses[i];
    for (size_t p = 0; p < rec_.points.size(); ++p) rec_.points[p].position = snapshot.points[p];
  }

  // Chooses which intrinsics beyond the focal the final adjustment refines: the principal point
  // (MapperOptions::principal_point), the distortion (refine_distortion; k1 = k2 = 0 otherwise)
  // and the pixel aspect ratio (refine_aspect), by forward selection under the Bayesian
  // information criterion (Schwarz 1978): BIC = 2 cost / s^2 + (free intrinsics) ln(residuals),
  // s^2 the residual variance of the model with everything allowed free. Every candidate is
  // adjusted from the same state on the same observations. Leaves the model in the chosen state.
  IntrinsicsChoice SelectIntrinsicsModel() {
    using PP = MapperOptions::PrincipalPoint;
    const Snapshot start = Save();
    const auto adjust = [&](const IntrinsicsChoice& choice, Snapshot* result) {
      Restore(start);
      if (!choice.distortion) ZeroDistortion();
      const double cost = BundleAdjust(RegisteredImages(), opt_.final_ba_iterations, choice);
      *result = Save();
      return cost;
    };
    IntrinsicsChoice richest;
    richest.principal_point = opt_.principal_point != PP::kFixed;
    richest.distortion = opt_.refine_distortion;
    richest.aspect = opt_.refine_aspect;
    IntrinsicsChoice chosen;
    chosen.principal_point = opt_.principal_point == PP::kRefine;
    Snapshot chosen_state;
    double chosen_cost = adjust(chosen, &chosen_state);
    const bool optional_pp = opt_.principal_point == PP::kAuto;
    if (optional_pp || richest.distortion || richest.aspect) {
      Snapshot richest_state;
      const double richest_cost = adjust(richest, &richest_state);
      double residuals = 0.0;
      for (const SfmPoint& point : rec_.points) residuals += point.deleted ? 0.0 : 2.0 * static_cast<double>(point.track.size());
      const double s2 = std::max(2.0 * richest_cost / std::max(residuals, 1.0), 1e-12);
      const double cameras = static_cast<double>(rec_.cameras.size());
      const auto bic = [&](const IntrinsicsChoice& c, double cost) {
        const double parameters = cameras * (2.0 * c.principal_point + 2.0 * c.distortion + 1.0 * c.aspect);
        return 2.0 * cost / s2 + parameters * std::log(std::max(residuals, 2.0));
      };
      double chosen_bic = bic(chosen, chosen_cost);
      // Forward selection: add the group that lowers the BIC most, while one does.
      while (true) {
        IntrinsicsChoice best_choice;
        Snapshot best_state;
        double best_cost = 0.0, best_bic = chosen_bic;
        bool improved = false;
        for (int group = 0; group < 3; ++group) {
          IntrinsicsChoice c = chosen;
          if (group == 0) {
            if (!optional_pp || c.principal_point) continue;
            c.principal_point = true;
          } else if (group == 1) {
            if (!richest.distortion || c.distortion) continue;
            c.distortion = true;
          } else {
            if (!richest.aspect || c.aspect) continue;
            c.aspect = true;
          }
          Snapshot state;
          const double cost = adjust(c, &state);
          const double b = bic(c, cost);
          if (std::isfinite(cost) && b < best_bic) {
            best_choice = c;
            best_state = std::move(state);
            best_cost = cost;
            best_bic = b;
            improved = true;
          }
        }
        if (!improved) break;
        chosen = best_choice;
        chosen_state = std::move(best_state);
        chosen_cost = best_cost;
        chosen_bic = best_bic;
      }
    }
    Restore(chosen_state);
    distortion_free_ = chosen.distortion;
    report_->principal_point_refined = chosen.principal_point;
    report_->distortion_refined = chosen.distortion;
    report_->aspect_refined = chosen.aspect;
    return chosen;
  }

  void ZeroDistortion() {
    for (SfmCamera& camera : rec_.cameras) camera.k1 = camera.k2 = 0.0;
  }

  void FinishReport() {
    report_->num_registered = rec_.NumRegisteredImages();
    report_->num_points = rec_.NumPoints();
    double error_sum = 0.0, length_sum = 0.0;
    size_t observations = 0;
    for (SfmPoint& point : rec_.points) {
      if (point.deleted) continue;
      double sum = 0.0;
      for (const TrackElement& e : point.track) sum += std::sqrt(SquaredError(point.position, e.image_id, e.keypoint_id));
      point.error = point.track.empty() ? 0.0 : sum / static_cast<double>(point.track.size());
      error_sum += sum;
      observations += point.track.size();
      length_sum += static_cast<double>(point.track.size());
    }
    report_->mean_reprojection_error_px = observations > 0 ? error_sum / static_cast<double>(observations) : 0.0;
    report_->mean_track_length = report_->num_points > 0 ? length_sum / report_->num_points : 0.0;
    report_->unregistered.clear();
    for (size_t i = 0; i < rec_.images.size(); ++i) {
      if (!rec_.images[i].registered) report_->unregistered.push_back({rec_.images[i].name, failure_[i]});
    }
  }

  const std::vector<MapperImage>& images_;
  const std::vector<MapperPair>& pairs_;
  const MapperOptions& opt_;
  int init_min_points_ = 0;          // the initial-pair bounds in force (relaxed by Initialize)
  double init_min_angle_deg_ = 0.0;
  MapperReport* report_;
  Reconstruction rec_;
  TrackSet tracks_;
  std::vector<int> point_of_track_;  // track -> point id or -1
  std::vector<int> track_of_point_;  // point id -> track
  std::vector<std::string> failure_;  // per image: why it is not registered (yet)
  std::vector<int> tried_with_;       // per image: visible points at the last failed attempt
  std::vector<double> camera_prior_;  // per camera: focal prior
  double function_tolerance_ = 1e-6;  // of the bundle adjustments; tighter for the final one
  bool distortion_free_ = true;       // k1, k2 refined (from three registered images on)
  bool needs_global_adjustment_ = false;  // the last registration changed a camera's focal
  std::vector<bool> camera_from_exif_;
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
                                            const std::vector<MapperPair>& pairs,
                                            const MapperOptions& options, MapperReport* report,
                                            const MapperProgress& progress) {
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
