#include "tracker/tag_layout.h"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <limits>
#include <sstream>

#include <Eigen/Geometry>

namespace reconar {

Status TagLayout::Add(const LayoutTag& tag) {
  if (tag.id < 0) return InvalidArgument("tag id must be >= 0, got " + std::to_string(tag.id));
  if (!(tag.size > 0.0) || !std::isfinite(tag.size)) {
    return InvalidArgument("tag " + std::to_string(tag.id) + ": size must be > 0, got " + std::to_string(tag.size));
  }
  if (!tag.layout_from_tag.rotation.allFinite() || !tag.layout_from_tag.translation.allFinite()) {
    return InvalidArgument("tag " + std::to_string(tag.id) + ": pose is not finite");
  }
  const auto it = std::lower_bound(tags_.begin(), tags_.end(), tag.id,
                                   [](const LayoutTag& a, int id) { return a.id < id; });
  if (it != tags_.end() && it->id == tag.id) {
    return InvalidArgument("tag " + std::to_string(tag.id) + " is listed twice");
  }
  tags_.insert(it, tag);
  return Status::Ok();
}

const LayoutTag* TagLayout::Find(int id) const {
  const auto it =
      std::lower_bound(tags_.begin(), tags_.end(), id, [](const LayoutTag& a, int key) { return a.id < key; });
  return it != tags_.end() && it->id == id ? &*it : nullptr;
}

bool TagLayout::IsPlanar() const {
  for (const LayoutTag& tag : tags_) {
    if (std::abs(tag.layout_from_tag.translation.z()) > 1e-9) return false;
    if ((tag.layout_from_tag.rotation.col(2) - Eigen::Vector3d::UnitZ()).norm() > 1e-9) return false;
  }
  return true;
}

Result<TagLayout> ParseTagLayout(const std::string& text, const std::string& name_for_errors) {
  TagLayout layout;
  std::istringstream lines(text);
  std::string line;
  int line_number = 0;
  while (std::getline(lines, line)) {
    ++line_number;
    const std::string where = name_for_errors + ":" + std::to_string(line_number) + ": ";
    const size_t hash = line.find('#');
    if (hash != std::string::npos) line.resize(hash);
    std::istringstream fields(line);
    std::vector<std::string> tokens;
    for (std::string token; fields >> token;) tokens.push_back(token);
    if (tokens.empty()) continue;
    std::vector<double> values;
    for (const std::string& token : tokens) {
      char* end = nullptr;
      const double value = std::strtod(token.c_str(), &end);
      if (end == token.c_str() || *end != '\0' || !std::isfinite(value)) {
        return CorruptData(where + "'" + token + "' is not a finite number");
      }
      values.push_back(value);
    }
    if (values.size() != 4 && values.size() != 5 && values.size() != 9) {
      return CorruptData(where + "expected 'id size x y z qw qx qy qz' (9 fields) or 'id size cx cy [angle_deg]' "
                                 "(4 or 5 fields), got " + std::to_string(values.size()) + " fields");
    }
    if (values[0] != std::floor(values[0]) || values[0] < 0 || values[0] > std::numeric_limits<int>::max()) {
      return CorruptData(where + "tag id must be a non-negative integer, got " + tokens[0]);
    }
    LayoutTag tag;
    tag.id = static_cast<int>(values[0]);
    tag.size = values[1];
    if (values.size() == 9) {
      tag.layout_from_tag.translation = Eigen::Vector3d(values[2], values[3], values[4]);
      const Eigen::Quaterniond q(values[5], values[6], values[7], values[8]);
      if (!(q.norm() > 1e-9)) return CorruptData(where + "the quaternion is zero");
      tag.layout_from_tag.rotation = q.normalized().toRotationMatrix();
    } else {
      tag.layout_from_tag.translation = Eigen::Vector3d(values[2], values[3], 0.0);
      const double angle = values.size() == 5 ? values[4] * M_PI / 180.0 : 0.0;
      tag.layout_from_tag.rotation = Eigen::AngleAxisd(angle, Eigen::Vector3d::UnitZ()).toRotationMatrix();
    }
    const Status added = layout.Add(tag);
    if (!added.ok()) return InvalidArgument(where + added.message());
  }
  if (layout.empty()) return InvalidArgument(name_for_errors + ": the layout lists no tags");
  return layout;
}

Result<TagLayout> ReadTagLayout(const std::string& path) {
  std::ifstream file(path, std::ios::binary);
  if (!file) return FileError(StatusCode::kNotFound, path, "cannot open the tag layout file");
  std::ostringstream content;
  content << file.rdbuf();
  if (file.bad()) return FileError(StatusCode::kIoError, path, "read failed");
  return ParseTagLayout(content.str(), path);
}

Result<BoardPose> EstimateBoardPose(const TagLayout& layout, const TagDetectionList& detections,
                                    const CameraIntrinsics& intrinsics, const BoardPoseOptions& options) {
  if (!intrinsics.valid()) return InvalidArgument("EstimateBoardPose: intrinsics need fx > 0 and fy > 0");
  constexpr int kMaxTags = kMaxRefinementPoints / 4;
  Eigen::Vector3d world[kMaxRefinementPoints];
  Eigen::Vector2d pixels[kMaxRefinementPoints];
  const LayoutTag* used_tags[kMaxTags];
  const TagDetection* used_detections[kMaxTags];
  int tags = 0;
  for (const TagDetection& detection : detections) {
    if (tags >= kMaxTags) break;
    if (detection.hamming > options.max_hamming) continue;
    const LayoutTag* tag = layout.Find(detection.id);
    if (tag == nullptr) continue;
    bool duplicate = false;
    for (int i = 0; i < tags; ++i) duplicate |= used_tags[i]->id == detection.id;
    if (duplicate) continue;
    const std::array<Eigen::Vector3d, 4> corners = TagCornersInTagFrame(tag->size);
    for (int k = 0; k < 4; ++k) {
      world[4 * tags + k] = tag->layout_from_tag * corners[k];
      pixels[4 * tags + k] = detection.corners[k];
    }
    used_tags[tags] = tag;
    used_detections[tags] = &detection;
    ++tags;
  }
  if (tags == 0) return FailedPrecondition("EstimateBoardPose: no tag of the layout was detected");
  const int count = 4 * tags;
  BoardPose board;
  board.tags_used = tags;
  board.corners_used = count;
  if (layout.IsPlanar()) {
    Eigen::Vector2d plane[kMaxRefinementPoints];
    for (int i = 0; i < count; ++i) plane[i] = world[i].head<2>();
    Result<TagPose> pose = EstimatePlanarPose(plane, pixels, count, intrinsics, options.pose);
    if (!pose.ok()) return pose.status();
    board.cam_from_layout = pose->cam_from_tag;
    board.rms_reprojection_px = pose->rms_reprojection_px;
    return board;
  }
  Eigen::Vector2d normalized[kMaxRefinementPoints];
  for (int i = 0; i < count; ++i) normalized[i] = intrinsics.Unproject(ToIntrinsicsPixel(pixels[i]));
  double best_rms = std::numeric_limits<double>::infinity();
  for (int i = 0; i < tags; ++i) {
    Result<TagPose> pose = EstimateTagPose(used_detections[i]->corners, used_tags[i]->size, intrinsics, options.pose);
    if (!pose.ok()) continue;
    for (const Rigid3& cam_from_tag : {pose->cam_from_tag, pose->alternative_cam_from_tag}) {
      const Rigid3 candidate = cam_from_tag * used_tags[i]->layout_from_tag.Inverse();
      const double rms = RmsReprojectionErrorPx(candidate, world, normalized, count, intrinsics);
      if (rms < best_rms) {
        best_rms = rms;
        board.cam_from_layout = candidate;
      }
    }
  }
  if (!std::isfinite(best_rms)) return FailedPrecondition("EstimateBoardPose: no tag gave a pose in front of the camera");
  board.rms_reprojection_px =
      options.pose.refine
          ? RefinePoseOnPoints(world, pixels, count, intrinsics, options.pose.lm, &board.cam_from_layout)
          : best_rms;
  return board;
}

}  // namespace reconar
