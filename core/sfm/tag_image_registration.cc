#include "core/sfm/tag_image_registration.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <utility>

#include "core/geometry/absolute_pose.h"
#include "core/sfm/image_registration.h"
#include "core/sfm/tag_observations.h"
#include "core/sfm/two_view_check.h"

namespace reconar {
namespace {

// The tag's corner keypoints lie within the image's keypoints and its tracks.
bool ValidTag(const MapperModel& model, const std::vector<MapperImage>& images, int image, const MapperTag& tag) {
  if (image < 0 || static_cast<size_t>(image) >= images.size() ||
      static_cast<size_t>(image) >= model.tracks.track_of.size() || tag.first_keypoint < 0)
    return false;
  const size_t end = static_cast<size_t>(tag.first_keypoint) + 4;
  return end <= model.tracks.track_of[static_cast<size_t>(image)].size() &&
         end <= images[static_cast<size_t>(image)].keypoints.size();
}

// The model point of corner k of `tag` in `image`, or -1.
int CornerPoint(const MapperModel& model, int image, const MapperTag& tag, int k) {
  const int t = model.tracks.track_of[static_cast<size_t>(image)][static_cast<size_t>(tag.first_keypoint + k)];
  return t < 0 ? -1 : model.point_of_track[static_cast<size_t>(t)];
}

// The mean edge (model units) of the tags in registered images whose four corners are points; 0
// when there is none.
double ModelTagEdge(const MapperModel& model, const std::vector<MapperImage>& images) {
  double sum = 0.0;
  int count = 0;
  for (size_t i = 0; i < images.size() && i < model.rec.images.size(); ++i) {
    if (!model.rec.images[i].registered) continue;
    for (const MapperTag& tag : images[i].tags) {
      if (!ValidTag(model, images, static_cast<int>(i), tag)) continue;
      std::array<int, 4> points;
      for (int k = 0; k < 4; ++k) points[static_cast<size_t>(k)] = CornerPoint(model, static_cast<int>(i), tag, k);
      if (*std::min_element(points.begin(), points.end()) < 0) continue;
      for (size_t k = 0; k < 4; ++k) {
        sum += (model.rec.points[static_cast<size_t>(points[(k + 1) % 4])].position -
                model.rec.points[static_cast<size_t>(points[k])].position)
                   .norm();
        ++count;
      }
    }
  }
  return count > 0 ? sum / count : 0.0;
}

// The corners of tag `tag_id` from its pose in the registered image that shows it largest (P3P on
// the four corners of a tag of edge `edge`), or false when no registered image gives one.
bool CornersFromOneView(const MapperModel& model, const std::vector<MapperImage>& images, int tag_id, double edge,
                        const MapperOptions& options, std::array<Eigen::Vector3d, 4>* corners) {
  int best_image = -1;
  const MapperTag* best = nullptr;
  double best_perimeter = 0.0;
  for (size_t i = 0; i < images.size() && i < model.rec.images.size(); ++i) {
    if (!model.rec.images[i].registered) continue;
    for (const MapperTag& tag : images[i].tags) {
      if (tag.tag_id != tag_id || !ValidTag(model, images, static_cast<int>(i), tag)) continue;
      double perimeter = 0.0;
      const std::vector<Eigen::Vector2d>& keypoints = images[i].keypoints;
      for (int k = 0; k < 4; ++k) {
        perimeter += (keypoints[static_cast<size_t>(tag.first_keypoint + (k + 1) % 4)] -
                      keypoints[static_cast<size_t>(tag.first_keypoint + k)])
                         .norm();
      }
      if (perimeter > best_perimeter) {
        best_perimeter = perimeter;
        best_image = static_cast<int>(i);
        best = &tag;
      }
    }
  }
  if (best == nullptr) return false;
  std::vector<Eigen::Vector2d> pixels;
  std::vector<Eigen::Vector3d> ideal;
  for (int k = 0; k < 4; ++k) {
    pixels.push_back(images[static_cast<size_t>(best_image)].keypoints[static_cast<size_t>(best->first_keypoint + k)]);
    ideal.emplace_back(kTagCornerUnits[k][0] * edge / 2.0, kTagCornerUnits[k][1] * edge / 2.0, 0.0);
  }
  const SfmImage& view = model.rec.images[static_cast<size_t>(best_image)];
  AbsolutePoseOptions pose_options;
  pose_options.max_error_px = options.registration_max_error_px;
  pose_options.min_inliers = 4;
  const auto pose =
      EstimateAbsolutePose(pixels, ideal, model.rec.cameras[static_cast<size_t>(view.camera_id)], pose_options);
  if (!pose.ok() || !pose->success()) return false;
  const Rigid3 world_from_tag = view.cam_from_world.Inverse() * pose->cam_from_world;
  for (size_t k = 0; k < 4; ++k) (*corners)[k] = world_from_tag * ideal[k];
  return true;
}

// 2D-3D correspondences of the image: the known tags' corners first (4 per tag), then the other
// keypoints whose track has a point.
struct Correspondences {
  std::vector<Eigen::Vector2d> pixels;
  std::vector<Eigen::Vector3d> world;
  std::vector<int> keypoint;  // the image's keypoint
  std::vector<int> point;     // its model point, -1 for a derived corner
  int num_corners = 0;
  // The image's other keypoints' matches to registered images on tracks without a point yet.
  std::vector<TwoViewMatch> two_view;
};

Correspondences Gather(const MapperModel& model, const std::vector<MapperImage>& images, int image,
                       const std::vector<KnownTag>& known) {
  Correspondences c;
  const MapperImage& in = images[static_cast<size_t>(image)];
  std::vector<char> corner(in.keypoints.size(), 0);
  for (const KnownTag& tag : known) {
    for (int k = 0; k < 4; ++k) {
      const int kp = tag.first_keypoint + k;
      corner[static_cast<size_t>(kp)] = 1;
      c.pixels.push_back(in.keypoints[static_cast<size_t>(kp)]);
      c.world.push_back(tag.corners[static_cast<size_t>(k)]);
      c.keypoint.push_back(kp);
      c.point.push_back(tag.points[static_cast<size_t>(k)]);
    }
  }
  c.num_corners = static_cast<int>(c.pixels.size());
  const std::vector<int>& track_of = model.tracks.track_of[static_cast<size_t>(image)];
  for (size_t kp = 0; kp < track_of.size() && kp < in.keypoints.size(); ++kp) {
    const int t = track_of[kp];
    if (corner[kp] || t < 0 || model.point_of_track[static_cast<size_t>(t)] < 0) continue;
    c.pixels.push_back(in.keypoints[kp]);
    c.world.push_back(model.rec.points[static_cast<size_t>(model.point_of_track[static_cast<size_t>(t)])].position);
    c.keypoint.push_back(static_cast<int>(kp));
    c.point.push_back(model.point_of_track[static_cast<size_t>(t)]);
  }
  c.two_view = GatherTwoViewMatches(model, image, &corner);
  return c;
}

// A pose judged by the tag rule.
struct Verdict {
  std::vector<int> inliers;  // indices into the correspondences
  int tags_fitting = 0;
  int tags_off = 0;  // known tags with a corner beyond the bound
  int other_inliers = 0;
  double corner_rms_px = 0.0;   // over the known tags' corners
  int two_view_consistent = 0;  // two-view matches within the bound of their epipolar line
};

Verdict Judge(const MapperModel& model, const Correspondences& c, const RadialCamera& camera,
              const Rigid3& cam_from_world, const MapperOptions& options) {
  Verdict v;
  const double bound = options.registration_max_error_px * options.registration_max_error_px;
  double corner_squares = 0.0;
  for (size_t i = 0; i < c.pixels.size(); ++i) {
    const double squared =
        SquaredPixelError(camera, cam_from_world.rotation, cam_from_world.translation, c.world[i], c.pixels[i]);
    if (squared < bound) v.inliers.push_back(static_cast<int>(i));
    if (static_cast<int>(i) < c.num_corners) corner_squares += squared;
  }
  if (c.num_corners > 0) v.corner_rms_px = std::sqrt(corner_squares / c.num_corners);
  v.two_view_consistent =
      CountEpipolarConsistent(model, c.two_view, cam_from_world, camera.focal, options.registration_max_error_px);
  std::vector<int> per_tag(static_cast<size_t>(c.num_corners / 4), 0);
  for (int i : v.inliers) {
    if (i < c.num_corners) {
      ++per_tag[static_cast<size_t>(i / 4)];
    } else {
      ++v.other_inliers;
    }
  }
  for (int n : per_tag) (n == 4 ? v.tags_fitting : v.tags_off) += 1;
  return v;
}

std::string FormatPixels(double px) {
  char text[32];
  std::snprintf(text, sizeof(text), "%.2f px", px);
  return text;
}

bool Accepted(const Verdict& v, const Correspondences& c, const MapperOptions& options) {
  const int two_view = static_cast<int>(c.two_view.size());
  const bool epipolar = two_view < options.registration_min_tag_point_inliers ||
                        v.two_view_consistent >= options.registration_min_tag_two_view_fraction * two_view;
  return v.tags_off == 0 && v.corner_rms_px <= options.registration_max_tag_rms_px && epipolar &&
         TagsCanRegister(v.tags_fitting, v.other_inliers, options);
}

}  // namespace

std::vector<KnownTag> KnownTags(const MapperModel& model, const std::vector<MapperImage>& images, int image,
                                const MapperOptions& options) {
  std::vector<KnownTag> known;
  if (image < 0 || static_cast<size_t>(image) >= images.size()) return known;
  double edge = -1.0;  // computed when first needed
  for (const MapperTag& tag : images[static_cast<size_t>(image)].tags) {
    if (!ValidTag(model, images, image, tag)) continue;
    KnownTag k;
    k.tag_id = tag.tag_id;
    k.first_keypoint = tag.first_keypoint;
    int missing = -1, num_missing = 0;
    for (int c = 0; c < 4; ++c) {
      k.points[static_cast<size_t>(c)] = CornerPoint(model, image, tag, c);
      if (k.points[static_cast<size_t>(c)] < 0) {
        missing = c;
        ++num_missing;
      } else {
        k.corners[static_cast<size_t>(c)] =
            model.rec.points[static_cast<size_t>(k.points[static_cast<size_t>(c)])].position;
      }
    }
    if (num_missing == 1) {
      // The parallelogram: corner m = corner m-1 + corner m+1 - corner m+2.
      const auto at = [&](int c) { return k.corners[static_cast<size_t>((c + 4) % 4)]; };
      k.corners[static_cast<size_t>(missing)] = at(missing - 1) + at(missing + 1) - at(missing + 2);
    } else if (num_missing > 1) {
      if (edge < 0.0) edge = ModelTagEdge(model, images);
      if (!(edge > 0.0) || !CornersFromOneView(model, images, tag.tag_id, edge, options, &k.corners)) continue;
      k.points = {-1, -1, -1, -1};
    }
    known.push_back(k);
  }
  return known;
}

bool TagsCanRegister(int known_tags, int other_points, const MapperOptions& options) {
  return known_tags >= 2 || (known_tags == 1 && other_points >= options.registration_min_tag_point_inliers);
}

bool RegisterImageByTags(MapperModel* model, const std::vector<MapperImage>& images, int image,
                         const MapperOptions& options, std::string* reason) {
  const int camera_id = model->rec.images[static_cast<size_t>(image)].camera_id;
  if (model->CameraUsers(camera_id) < 3 && options.refine_focal) {
    *reason = "by tags: its camera's focal is not confirmed yet";
    return false;
  }
  const std::vector<KnownTag> known = KnownTags(*model, images, image, options);
  const Correspondences c = Gather(*model, images, image, known);
  const int num_tags = static_cast<int>(known.size());
  if (!TagsCanRegister(num_tags, static_cast<int>(c.pixels.size()) - c.num_corners, options)) {
    *reason = "by tags: sees " + std::to_string(num_tags) + " tag(s) the model holds and " +
              std::to_string(c.pixels.size() - static_cast<size_t>(c.num_corners)) + " other points";
    return false;
  }
  const SfmCamera camera = GuessCamera(*model, image);
  AbsolutePoseOptions pose_options;
  pose_options.max_error_px = options.registration_max_error_px;
  pose_options.min_inliers = 4;
  // Two candidate poses: RANSAC over all correspondences, and, with two tags or more, over the
  // tag corners alone (refined on all inliers), so that many wrong points cannot outvote the tags.
  std::vector<Rigid3> poses;
  auto all = EstimateAbsolutePose(c.pixels, c.world, camera, pose_options);
  if (all.ok() && all->success()) poses.push_back(all->cam_from_world);
  if (num_tags >= 2) {
    const std::vector<Eigen::Vector2d> corner_pixels(c.pixels.begin(), c.pixels.begin() + c.num_corners);
    const std::vector<Eigen::Vector3d> corner_world(c.world.begin(), c.world.begin() + c.num_corners);
    auto corners = EstimateAbsolutePose(corner_pixels, corner_world, camera, pose_options);
    if (corners.ok() && corners->success()) {
      Rigid3 pose = corners->cam_from_world;
      const Verdict v = Judge(*model, c, camera, pose, options);
      if (static_cast<int>(v.inliers.size()) >= 4) {
        RadialCamera refined_camera = camera;
        auto refined = RefineAbsolutePose(c.pixels, c.world, v.inliers, pose_options.refinement, &refined_camera,
                                          &pose.rotation, &pose.translation);
        if (!refined.ok()) pose = corners->cam_from_world;
      }
      poses.push_back(pose);
    }
  }
  int best = -1;
  Verdict best_verdict;
  std::string judged;
  for (size_t p = 0; p < poses.size(); ++p) {
    Verdict v = Judge(*model, c, camera, poses[p], options);
    judged += (judged.empty() ? "" : ", ") + std::to_string(v.tags_fitting) + " of " + std::to_string(num_tags) +
              " tags and " + std::to_string(v.other_inliers) + " other points fit, corners rms " +
              FormatPixels(v.corner_rms_px) + ", " + std::to_string(v.two_view_consistent) + " of " +
              std::to_string(c.two_view.size()) + " two-view matches on their epipolar lines";
    if (Accepted(v, c, options) && (best < 0 || v.inliers.size() > best_verdict.inliers.size())) {
      best = static_cast<int>(p);
      best_verdict = std::move(v);
    }
  }
  if (best < 0) {
    *reason = "by tags: " + std::to_string(num_tags) + " known tag(s), " +
              (poses.empty() ? std::string("no pose found") : "no pose fits them all (" + judged + ")");
    return false;
  }
  std::vector<std::pair<int, int>> observations;  // (keypoint, point)
  for (int i : best_verdict.inliers) {
    if (c.point[static_cast<size_t>(i)] >= 0)
      observations.emplace_back(c.keypoint[static_cast<size_t>(i)], c.point[static_cast<size_t>(i)]);
  }
  AcceptRegistration(model, image, poses[static_cast<size_t>(best)], observations);
  return true;
}

}  // namespace reconar
