#include "core/sfm/tag_registration.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <optional>
#include <set>
#include <utility>

#include "core/base/json_writer.h"
#include "core/math/rigid3_json.h"
#include "core/geometry/triangulation.h"
#include "core/math/rotation.h"
#include "core/sfm/tag_board.h"
#include "core/sfm/tag_layout.h"
#include "core/sfm/tag_squares.h"

namespace reconar {
namespace {

using Observation = std::pair<int, Eigen::Vector2d>;  // (image id, pixel)

double ReprojectionError(const Reconstruction& rec, const Observation& obs, const Eigen::Vector3d& point) {
  const SfmImage& image = rec.images[static_cast<size_t>(obs.first)];
  const Eigen::Vector3d cam = image.cam_from_world * point;
  if (!(cam.z() > 0.0)) return std::numeric_limits<double>::infinity();
  return (rec.cameras[static_cast<size_t>(image.camera_id)].Project(cam) - obs.second).norm();
}

// TriangulateMultiView (core/geometry/triangulation.h) of the undistorted corner pixels.
std::optional<Eigen::Vector3d> TriangulateViews(const Reconstruction& rec, const std::vector<Observation>& views) {
  std::vector<TriangulationView> observations(views.size());
  for (size_t v = 0; v < views.size(); ++v) {
    const SfmImage& image = rec.images[static_cast<size_t>(views[v].first)];
    const SfmCamera& camera = rec.cameras[static_cast<size_t>(image.camera_id)];
    TriangulationView& view = observations[v];
    if (!camera.Undistort(views[v].second, &view.normalised)) return std::nullopt;
    view.cam_from_world = Rigid3{image.cam_from_world.rotation, image.cam_from_world.translation};
    view.focal = camera.focal;
  }
  Eigen::Vector3d point;
  if (!TriangulateMultiView(observations, &point)) return std::nullopt;
  return point;
}

// Triangulates from the views, dropping the worst view while any error exceeds the bound.
std::optional<Eigen::Vector3d> TriangulateCorner(const Reconstruction& rec, std::vector<Observation> views,
                                                 const TagRegistrationOptions& options) {
  while (static_cast<int>(views.size()) >= options.min_views) {
    const std::optional<Eigen::Vector3d> point = TriangulateViews(rec, views);
    if (!point) return std::nullopt;
    size_t worst = 0;
    double worst_error = -1.0;
    for (size_t v = 0; v < views.size(); ++v) {
      const double error = ReprojectionError(rec, views[v], *point);
      if (error > worst_error) {
        worst_error = error;
        worst = v;
      }
    }
    if (worst_error <= options.max_reprojection_error_px) return point;
    views.erase(views.begin() + static_cast<std::ptrdiff_t>(worst));
  }
  return std::nullopt;
}

std::vector<Eigen::Vector3d> AsVector(const std::array<Eigen::Vector3d, 4>& corners) {
  return std::vector<Eigen::Vector3d>(corners.begin(), corners.end());
}

// Mean, standard deviation and largest |edge - tag_size| of `edges`.
void EdgeFigures(const std::vector<double>& edges, double tag_size, double* mean, double* std, double* max_abs_error) {
  *mean = *std = *max_abs_error = 0.0;
  for (double e : edges) *mean += e / static_cast<double>(edges.size());
  for (double e : edges) {
    *std += (e - *mean) * (e - *mean) / static_cast<double>(edges.size());
    *max_abs_error = std::max(*max_abs_error, std::abs(e - tag_size));
  }
  *std = std::sqrt(*std);
}

void ApplyToModel(const Sim3& world_from_model, Reconstruction* rec) {
  for (SfmPoint& point : rec->points) point.position = world_from_model.Apply(point.position);
  const Eigen::Matrix3d model_from_world_rotation = world_from_model.rotation.transpose();
  for (SfmImage& image : rec->images) {
    if (!image.registered) continue;
    // X_cam' = s X_cam = s R_c X_model + s t_c with X_model = R^T (X_world - t) / s.
    Rigid3& pose = image.cam_from_world;
    pose.rotation = pose.rotation * model_from_world_rotation;
    pose.translation = world_from_model.scale * pose.translation - pose.rotation * world_from_model.translation;
  }
}

// The world tag as a rigid square of edge `edge` (model units) that best reprojects into the
// views that saw its corners (cameras fixed; Gauss-Newton on its pose from the square fitted to
// `corners`): a tag of known shape seen from several views fixes its plane better than four
// corners triangulated each on its own. Returns `corners` when the fit fails or its root mean
// square reprojection error exceeds max_error_px (the tag is no square in the model).
std::array<Eigen::Vector3d, 4> RigidTagCorners(const Reconstruction& rec,
                                               const std::array<std::vector<Observation>, 4>& views,
                                               const std::array<Eigen::Vector3d, 4>& corners, double edge,
                                               double max_error_px) {
  const std::array<Eigen::Vector3d, 4> ideal = TagSquareCorners(edge);
  auto start = AlignSimilarity(AsVector(ideal), AsVector(corners), 1.0);
  if (!start.ok()) return corners;
  Eigen::Matrix3d R = start->rotation;
  Eigen::Vector3d t = start->translation;
  const auto residuals = [&](const Eigen::Matrix3d& rotation, const Eigen::Vector3d& translation, Eigen::VectorXd* r) {
    int n = 0;
    for (size_t k = 0; k < 4; ++k) n += static_cast<int>(views[k].size());
    r->resize(2 * n);
    int i = 0;
    for (size_t k = 0; k < 4; ++k) {
      const Eigen::Vector3d world = rotation * ideal[k] + translation;
      for (const Observation& obs : views[k]) {
        const SfmImage& image = rec.images[static_cast<size_t>(obs.first)];
        const Eigen::Vector3d cam = image.cam_from_world * world;
        if (!(cam.z() > 0.0)) return false;
        r->segment<2>(2 * i++) = rec.cameras[static_cast<size_t>(image.camera_id)].Project(cam) - obs.second;
      }
    }
    return r->allFinite();
  };
  Eigen::VectorXd r;
  if (!residuals(R, t, &r) || r.size() < 12) return corners;
  double cost = r.squaredNorm();
  const double step = 1e-7 * std::max(1.0, t.norm());
  for (int iteration = 0; iteration < 20; ++iteration) {
    Eigen::MatrixXd J(r.size(), 6);
    for (int d = 0; d < 6; ++d) {
      Eigen::Matrix3d R_d = R;
      Eigen::Vector3d t_d = t;
      Eigen::Vector3d delta = Eigen::Vector3d::Zero();
      delta[d % 3] = d < 3 ? 1e-7 : step;
      if (d < 3) {
        R_d = RotationFromAngleAxis(delta) * R;
      } else {
        t_d += delta;
      }
      Eigen::VectorXd r_d;
      if (!residuals(R_d, t_d, &r_d)) return corners;
      J.col(d) = (r_d - r) / delta[d % 3];
    }
    const Eigen::Matrix<double, 6, 1> dx = (J.transpose() * J).ldlt().solve(-J.transpose() * r);
    if (!dx.allFinite()) break;
    const Eigen::Matrix3d R_new = RotationFromAngleAxis(dx.head<3>()) * R;
    const Eigen::Vector3d t_new = t + dx.tail<3>();
    Eigen::VectorXd r_new;
    if (!residuals(R_new, t_new, &r_new) || r_new.squaredNorm() >= cost) break;
    R = R_new;
    t = t_new;
    r = r_new;
    cost = r.squaredNorm();
  }
  if (!(cost <= max_error_px * max_error_px * static_cast<double>(r.size() / 2))) return corners;
  std::array<Eigen::Vector3d, 4> rigid;
  for (size_t k = 0; k < 4; ++k) rigid[k] = R * ideal[k] + t;
  return rigid;
}

}  // namespace

std::vector<TagCornerKeypoint> TagCornerKeypointsOfImage(int image_id, const std::vector<TagObservation>& tags,
                                                         int first_keypoint) {
  std::map<int, int> count;
  for (const TagObservation& tag : tags) ++count[tag.tag_id];
  std::vector<TagCornerKeypoint> corners;
  int keypoint = first_keypoint;
  for (const TagObservation& tag : tags) {
    if (count[tag.tag_id] != 1) continue;
    for (int k = 0; k < 4; ++k) corners.push_back({image_id, keypoint++, tag.tag_id, k, tag.corners[static_cast<size_t>(k)]});
  }
  return corners;
}

std::vector<TagCornerKeypoint> AddTagCorrespondences(const std::vector<std::vector<TagObservation>>& observations,
                                                     double keypoint_scale, double corner_weight,
                                                     std::vector<MapperImage>* images, std::vector<MapperPair>* pairs) {
  std::vector<TagCornerKeypoint> corners;
  std::vector<std::map<int, int>> first_keypoint(images->size());  // per image: tag id -> its corner 0 keypoint
  for (size_t i = 0; i < images->size() && i < observations.size(); ++i) {
    MapperImage& image = (*images)[i];
    const std::vector<TagCornerKeypoint> image_corners =
        TagCornerKeypointsOfImage(static_cast<int>(i), observations[i], static_cast<int>(image.keypoints.size()));
    if (!observations[i].empty()) image.keypoint_weights.resize(image.keypoints.size(), 0.0f);
    for (const TagCornerKeypoint& corner : image_corners) {
      if (corner.corner == 0) {
        first_keypoint[i][corner.tag_id] = corner.keypoint_id;
        image.tags.push_back({corner.tag_id, corner.keypoint_id});
      }
      image.keypoints.push_back(corner.pixel);
      if (!image.keypoint_scales.empty()) image.keypoint_scales.push_back(static_cast<float>(keypoint_scale));
      image.keypoint_weights.push_back(static_cast<float>(corner_weight));
    }
    corners.insert(corners.end(), image_corners.begin(), image_corners.end());
  }
  std::map<std::pair<int, int>, size_t> pair_of;
  for (size_t p = 0; p < pairs->size(); ++p) {
    const PairMatches& m = (*pairs)[p].matches;
    pair_of[{std::min(m.image_a, m.image_b), std::max(m.image_a, m.image_b)}] = p;
  }
  for (size_t a = 0; a < first_keypoint.size(); ++a) {
    if (first_keypoint[a].empty()) continue;
    for (size_t b = a + 1; b < first_keypoint.size(); ++b) {
      std::vector<std::pair<int, int>> shared;  // (corner 0 keypoint in a, in b)
      for (const auto& [id, keypoint] : first_keypoint[a]) {
        const auto other = first_keypoint[b].find(id);
        if (other != first_keypoint[b].end()) shared.emplace_back(keypoint, other->second);
      }
      if (shared.empty()) continue;
      const std::pair<int, int> key(static_cast<int>(a), static_cast<int>(b));
      auto it = pair_of.find(key);
      if (it == pair_of.end()) {
        MapperPair pair;
        pair.matches.image_a = key.first;
        pair.matches.image_b = key.second;
        pair.planar = true;
        pairs->push_back(std::move(pair));
        it = pair_of.emplace(key, pairs->size() - 1).first;
      }
      PairMatches& matches = (*pairs)[it->second].matches;
      const bool swapped = matches.image_a != key.first;
      for (const auto& [in_a, in_b] : shared) {
        for (int k = 0; k < 4; ++k) {
          matches.matches.push_back(swapped ? FeatureMatch{in_b + k, in_a + k} : FeatureMatch{in_a + k, in_b + k});
        }
      }
    }
  }
  return corners;
}

Status TagRegistrationOptions::Check() const {
  if (!(tag_size_m > 0.0) || !std::isfinite(tag_size_m))
    return InvalidArgument("tag registration: the tag size must be positive");
  if (min_views < 2) return InvalidArgument("tag registration: min_views must be >= 2");
  if (!(max_reprojection_error_px > 0.0))
    return InvalidArgument("tag registration: max_reprojection_error_px must be > 0");
  return Status::Ok();
}

Result<TagRegistrationReport> RegisterToTags(const std::vector<std::vector<TagObservation>>& observations,
                                             const std::vector<TagCornerKeypoint>& corner_keypoints,
                                             const TagRegistrationOptions& options, Reconstruction* rec) {
  RECONAR_RETURN_IF_ERROR(options.Check());
  TagRegistrationReport report;
  // Observations of every corner in registered images, and the adjusted tracks that hold them.
  std::map<int, std::array<std::vector<Observation>, 4>> seen;  // tag id -> per corner
  for (size_t i = 0; i < rec->images.size() && i < observations.size(); ++i) {
    if (!rec->images[i].registered) continue;
    std::map<int, int> count;
    for (const TagObservation& tag : observations[i]) ++count[tag.tag_id];
    for (const TagObservation& tag : observations[i]) {
      if (count[tag.tag_id] != 1) continue;
      for (int k = 0; k < 4; ++k)
        seen[tag.tag_id][static_cast<size_t>(k)].emplace_back(static_cast<int>(i), tag.corners[static_cast<size_t>(k)]);
    }
  }
  std::map<int, std::array<int, 4>> corner_points;  // tag id -> the adjusted track of each corner
  for (const TagCornerPoints& tag : FindTagCornerPoints(*rec, corner_keypoints)) corner_points[tag.tag_id] = tag.points;
  report.tags_seen = static_cast<int>(seen.size());

  // Each tag's corners in the model frame.
  struct ModelTag {
    int id;
    std::array<Eigen::Vector3d, 4> corners;
    bool adjusted;
    int views;
  };
  std::vector<ModelTag> complete;
  for (const auto& [id, per_corner] : seen) {
    ModelTag tag{id, {}, true, static_cast<int>(per_corner[0].size())};
    bool ok = true;
    for (int k = 0; k < 4 && ok; ++k) {
      const auto points = corner_points.find(id);
      const int point = points == corner_points.end() ? -1 : points->second[static_cast<size_t>(k)];
      if (point >= 0) {
        tag.corners[static_cast<size_t>(k)] = rec->points[static_cast<size_t>(point)].position;
      } else {
        tag.adjusted = false;
        const std::optional<Eigen::Vector3d> triangulated =
            TriangulateCorner(*rec, per_corner[static_cast<size_t>(k)], options);
        ok = triangulated.has_value();
        if (ok) tag.corners[static_cast<size_t>(k)] = *triangulated;
      }
    }
    if (ok) complete.push_back(tag);
  }
  if (complete.empty()) {
    report.reason = report.tags_seen == 0
                        ? "no tag was detected in a registered image"
                        : std::to_string(report.tags_seen) + " tag(s) seen, none with all four corners in " +
                              std::to_string(options.min_views) + " registered views";
    return report;
  }

  // Scale from the scale tags' mean edge: those whose corners the adjustment held (as squares,
  // when the mapper had them so) whenever there are any; a tag the mapper kept no track of is
  // triangulated from few views and would pull the scale (the room's 16 photos round tag 4: two
  // such tags put the scale 3 % off the seven adjusted ones, which agreed within 0.3 %).
  const auto named = [&](int id) {
    return options.scale_tags.empty() ||
           std::find(options.scale_tags.begin(), options.scale_tags.end(), id) != options.scale_tags.end();
  };
  const bool any_adjusted =
      std::any_of(complete.begin(), complete.end(), [&](const ModelTag& tag) { return named(tag.id) && tag.adjusted; });
  std::set<int> scale_ids;
  for (const ModelTag& tag : complete) {
    if (named(tag.id) && (tag.adjusted || !any_adjusted)) scale_ids.insert(tag.id);
  }
  const auto sets_scale = [&](int id) { return scale_ids.count(id) > 0; };
  double mean_edge = 0.0;
  for (const ModelTag& tag : complete) {
    if (!sets_scale(tag.id)) continue;
    report.scale_tags.push_back(tag.id);
    for (int k = 0; k < 4; ++k) {
      mean_edge += (tag.corners[static_cast<size_t>((k + 1) % 4)] - tag.corners[static_cast<size_t>(k)]).norm() / 4.0;
    }
  }
  const auto complete_ids = [&] {
    std::string ids;
    for (const ModelTag& tag : complete) ids += (ids.empty() ? "" : ", ") + std::to_string(tag.id);
    return ids;
  };
  if (report.scale_tags.empty()) {
    report.reason = "none of the scale tags was reconstructed with all four corners; complete tags: " + complete_ids();
    return report;
  }
  mean_edge /= static_cast<double>(report.scale_tags.size());
  if (!(mean_edge > 0.0)) return FailedPrecondition("tag registration: the tags' corners coincide");
  const auto world = std::find_if(complete.begin(), complete.end(), [&](const ModelTag& tag) {
    return options.world_tag < 0 || tag.id == options.world_tag;
  });
  if (world == complete.end()) {
    return InvalidArgument("tag registration: world tag " + std::to_string(options.world_tag) +
                           " was not reconstructed; complete tags: " + complete_ids());
  }
  report.metres_per_model_unit = options.tag_size_m / mean_edge;
  if (options.layout.empty()) {
    Sim3 world_tag_from_model;
    RECONAR_ASSIGN_OR_RETURN(world_tag_from_model,
                             AlignSimilarity(AsVector(RigidTagCorners(*rec, seen.at(world->id), world->corners, mean_edge,
                                                                      options.max_reprojection_error_px)),
                                             AsVector(TagSquareCorners(options.tag_size_m)), report.metres_per_model_unit));
    // The board: the world tag (its rigid square) and every other tag held by the adjustment (all,
    // when none was), like the scale.
    const bool any_tag_adjusted =
        std::any_of(complete.begin(), complete.end(), [](const ModelTag& tag) { return tag.adjusted; });
    std::vector<BoardTag> board = {{world->id, TagSquareCorners(options.tag_size_m)}};
    for (const ModelTag& tag : complete) {
      if (tag.id == world->id || (any_tag_adjusted && !tag.adjusted)) continue;
      BoardTag placed{tag.id, {}};
      for (size_t k = 0; k < 4; ++k) placed.corners[k] = world_tag_from_model.Apply(tag.corners[k]);
      board.push_back(placed);
    }
    TagBoardFrame frame;
    RECONAR_ASSIGN_OR_RETURN(frame, FitTagBoardFrame(board, world->id, options.tag_size_m));
    report.world_from_model = world_tag_from_model;
    report.world_from_model.rotation = frame.board_from_world_tag.rotation * world_tag_from_model.rotation;
    report.world_from_model.translation =
        frame.board_from_world_tag.rotation * world_tag_from_model.translation + frame.board_from_world_tag.translation;
    report.board_plane_tags = frame.plane_tags;
    report.board_up_tags = frame.up_tags;
    report.board_turn_deg = frame.turn_deg;
  } else {
    // Every complete tag of the layout, its four corners onto their places there: the frame is
    // then as good as all those tags together, not one tag's corners.
    std::vector<Eigen::Vector3d> model_corners, layout_corners;
    for (const ModelTag& tag : complete) {
      const LayoutTag* placed = options.layout.Find(tag.id);
      if (placed == nullptr) continue;
      report.layout_tags.push_back(tag.id);
      const std::array<Eigen::Vector3d, 4> ideal = TagSquareCorners(placed->size);
      for (size_t k = 0; k < 4; ++k) {
        model_corners.push_back(tag.corners[k]);
        layout_corners.push_back(placed->layout_from_tag * ideal[k]);
      }
    }
    if (report.layout_tags.empty()) {
      return InvalidArgument("tag registration: the layout holds none of the reconstructed tags (" + complete_ids() + ")");
    }
    RECONAR_ASSIGN_OR_RETURN(report.world_from_model,
                             AlignSimilarity(model_corners, layout_corners, report.metres_per_model_unit));
    double squares = 0.0;
    for (size_t i = 0; i < model_corners.size(); ++i) {
      const double distance = (report.world_from_model.Apply(model_corners[i]) - layout_corners[i]).norm();
      squares += distance * distance;
      report.layout_max_m = std::max(report.layout_max_m, distance);
    }
    report.layout_rms_m = std::sqrt(squares / static_cast<double>(model_corners.size()));
  }
  const auto world_from_tag = [&](const std::array<Eigen::Vector3d, 4>& model_corners) -> std::optional<Rigid3> {
    std::vector<Eigen::Vector3d> corners;
    for (const Eigen::Vector3d& c : model_corners) corners.push_back(report.world_from_model.Apply(c));
    auto fit = AlignSimilarity(AsVector(TagSquareCorners(options.tag_size_m)), corners, 1.0);
    if (!fit.ok()) return std::nullopt;
    return Rigid3{fit->rotation, fit->translation};
  };
  ApplyToModel(report.world_from_model, rec);
  report.metric = true;
  report.world_tag = world->id;

  std::vector<double> edges, held_out;
  const double scale_sum = options.tag_size_m * 4.0 * static_cast<double>(report.scale_tags.size());
  for (const ModelTag& model_tag : complete) {
    RegisteredTag tag;
    tag.id = model_tag.id;
    tag.views = model_tag.views;
    tag.adjusted = model_tag.adjusted;
    for (size_t k = 0; k < 4; ++k) tag.corners[k] = report.world_from_model.Apply(model_tag.corners[k]);
    double squares = 0.0;
    int count = 0;
    for (size_t k = 0; k < 4; ++k) {
      tag.edges_m[k] = (tag.corners[(k + 1) % 4] - tag.corners[k]).norm();
      edges.push_back(tag.edges_m[k]);
      for (const Observation& view : seen.at(tag.id)[k]) {
        const double error = ReprojectionError(*rec, view, tag.corners[k]);
        if (std::isfinite(error)) {
          squares += error * error;
          ++count;
        }
      }
    }
    tag.rms_reprojection_px = count > 0 ? std::sqrt(squares / count) : 0.0;
    if (const std::optional<Rigid3> pose = world_from_tag(model_tag.corners)) tag.world_from_tag = *pose;
    // Held out: a scale tag at the scale of the other scale tags, whose edges sum to scale_sum less
    // its own; a tag that did not set the scale as it stands.
    const double own = tag.edges_m[0] + tag.edges_m[1] + tag.edges_m[2] + tag.edges_m[3];
    if (!sets_scale(tag.id)) {
      for (double e : tag.edges_m) held_out.push_back(e);
    } else if (report.scale_tags.size() >= 2) {
      const double rescale =
          options.tag_size_m * 4.0 * static_cast<double>(report.scale_tags.size() - 1) / (scale_sum - own);
      for (double e : tag.edges_m) held_out.push_back(e * rescale);
    }
    report.tags.push_back(tag);
  }
  EdgeFigures(edges, options.tag_size_m, &report.edge_mean_m, &report.edge_std_m, &report.edge_max_abs_error_m);
  report.held_out_edges = static_cast<int>(held_out.size());
  if (!held_out.empty()) {
    EdgeFigures(held_out, options.tag_size_m, &report.held_out_edge_mean_m, &report.held_out_edge_std_m,
                &report.held_out_edge_max_abs_error_m);
  }
  return report;
}

std::string TagRegistrationJson(const TagRegistrationReport& report, const std::string& family, double tag_size_m) {
  JsonWriter json(2);
  json.BeginObject();
  json.Key("metric").Bool(report.metric);
  if (!report.metric) json.Key("reason").String(report.reason);
  json.Key("family").String(family);
  json.Key("tag_size_m").Double(tag_size_m);
  json.Key("world_tag").Int(report.world_tag);
  const bool board = report.board_plane_tags.size() > 1 || report.board_up_tags.size() > 1;
  json.Key("frame").String(!report.layout_tags.empty() ? "layout" : board ? "tag_board" : "world_tag");
  if (report.layout_tags.empty() && report.metric) {
    json.Key("plane_tags").BeginArray();
    for (int id : report.board_plane_tags) json.Int(id);
    json.EndArray();
    json.Key("up_tags").BeginArray();
    for (int id : report.board_up_tags) json.Int(id);
    json.EndArray();
    json.Key("board_turn_deg").Double(report.board_turn_deg);
  }
  if (!report.layout_tags.empty()) {
    json.Key("layout_tags").BeginArray();
    for (int id : report.layout_tags) json.Int(id);
    json.EndArray();
    json.Key("layout_rms_m").Double(report.layout_rms_m);
    json.Key("layout_max_m").Double(report.layout_max_m);
  }
  json.Key("tags_seen").Int(report.tags_seen);
  json.Key("metres_per_model_unit").Double(report.metres_per_model_unit);
  if (!report.square_check.empty()) {
    double squares = 0.0, largest = 0.0;
    for (double e : report.square_check) {
      squares += e * e;
      largest = std::max(largest, std::abs(e));
    }
    json.Key("square_check").BeginObject();
    json.Key("segments").Int(static_cast<int>(report.square_check.size()));
    json.Key("rms_relative_error").Double(std::sqrt(squares / static_cast<double>(report.square_check.size())));
    json.Key("max_abs_relative_error").Double(largest);
    json.EndObject();
  }
  json.Key("scale_tags").BeginArray();
  for (int id : report.scale_tags) json.Int(id);
  json.EndArray();
  json.Key("edge_mean_m").Double(report.edge_mean_m);
  json.Key("edge_std_m").Double(report.edge_std_m);
  json.Key("edge_max_abs_error_m").Double(report.edge_max_abs_error_m);
  json.Key("held_out_edges").Int(report.held_out_edges);
  if (report.held_out_edges > 0) {
    json.Key("held_out_edge_mean_m").Double(report.held_out_edge_mean_m);
    json.Key("held_out_edge_std_m").Double(report.held_out_edge_std_m);
    json.Key("held_out_edge_max_abs_error_m").Double(report.held_out_edge_max_abs_error_m);
  }
  json.Key("tags").BeginArray();
  for (const RegisteredTag& tag : report.tags) {
    json.BeginObject();
    json.Key("id").Int(tag.id).Key("views").Int(tag.views).Key("adjusted").Bool(tag.adjusted);
    json.Key("corners").BeginArray();
    for (const Eigen::Vector3d& c : tag.corners) json.BeginArray().Double(c.x()).Double(c.y()).Double(c.z()).EndArray();
    json.EndArray();
    json.Key("edges_m").BeginArray();
    for (double e : tag.edges_m) json.Double(e);
    json.EndArray();
    json.Key("rms_reprojection_px").Double(tag.rms_reprojection_px);
    WriteRigid3Json(json.Key("world_from_tag"), tag.world_from_tag);
    json.EndObject();
  }
  json.EndArray();
  json.EndObject();
  return json.str() + "\n";
}

std::string TagLayoutText(const TagRegistrationReport& report, double tag_size_m) {
  std::vector<LayoutTag> tags;
  for (const RegisteredTag& tag : report.tags) tags.push_back(LayoutTag{tag.id, tag_size_m, tag.world_from_tag});
  return FormatTagLayout(tags);
}

}  // namespace reconar
