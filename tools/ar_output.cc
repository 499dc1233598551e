#include "tools/ar_output.h"

#include <cstdio>

#include "core/base/json_writer.h"
#include "core/math/rigid3_json.h"

namespace reconar::tools {

namespace {

// The frame's tag report; an empty one when tags are not tracked (a project without tags).
const TagTrackerFrameReport& TagReport(const ArSession& session) {
  static const TagTrackerFrameReport kNoTags;
  return session.tags() != nullptr ? session.tags()->report() : kNoTags;
}

// How the frame was searched for tags: "none" when tags are not tracked.
const char* TagSearchName(const ArSession& session) {
  return session.tags() != nullptr ? SearchName(session.tags()->report().search) : "none";
}

}  // namespace

std::string ArFrameJson(const ArSession& session) {
  const Frame& frame = session.frame();
  const TagTrackerFrameReport& report = TagReport(session);
  const bool with_layout = session.tags() != nullptr && !session.tags()->options().layout.empty();
  JsonWriter json;
  json.BeginObject().Key("frame").String(std::string(frame.name)).Key("tags").BeginArray();
  for (const TrackedTag& tag : report.tags) {
    if (!tag.measured) continue;
    json.BeginObject().Key("id").Int(tag.id).Key("corners").BeginArray();
    for (const Eigen::Vector2d& corner : tag.detection.corners) {
      json.BeginArray().Double(corner.x()).Double(corner.y()).EndArray();
    }
    json.EndArray();
    WriteRigid3Json(json.Key("cam_from_tag"), tag.cam_from_tag);
    json.Key("rms_px").Double(tag.pose.rms_reprojection_px).Key("reacquired").Bool(tag.reacquired);
    if (with_layout) json.Key("predicted").Bool(tag.found_by_prediction);
    json.EndObject();
  }
  json.EndArray();
  if (const BoardPose* board = session.tags() != nullptr ? session.tags()->board() : nullptr) {
    WriteRigid3Json(json.Key("cam_from_layout"), board->cam_from_layout);
    json.Key("layout_tags").Int(board->tags_used).Key("layout_rms_px").Double(board->rms_reprojection_px);
  }
  if (with_layout) {
    json.Key("predicted").BeginObject().Key("searched").Int(report.predicted_searched);
    json.Key("found").Int(report.predicted_found).EndObject();
  }
  if (const MapTrackerFrameReport* map = session.sources().map_report()) {
    json.Key("source").String(PoseSourceKindName(session.sources().source()));
    json.Key("state").String(MapTrackingStateName(map->state));
    if (session.pose().found) WriteRigid3Json(json.Key("cam_from_world"), session.pose().cam_from_world);
    json.Key("map_inliers").Int(map->found ? map->inliers : 0).Key("relocalised").Bool(map->relocalised);
    json.Key("fused_map_points").Int(session.sources().fused_map_points());
    json.Key("metric").Bool(session.metric()).Key("units").String(session.metric() ? "metres" : "model");
  }
  json.Key("search").String(TagSearchName(session)).Key("ms").Double(session.pose().track_ms).EndObject();
  return json.str();
}

std::string ArFrameText(const ArSession& session) {
  const Frame& frame = session.frame();
  const TagTrackerFrameReport& report = TagReport(session);
  int measured = 0;
  for (const TrackedTag& tag : report.tags) measured += tag.measured ? 1 : 0;
  char text[256];
  std::snprintf(text, sizeof(text), "%.*s: %d tag(s)", static_cast<int>(frame.name.size()), frame.name.data(),
                measured);
  std::string line = text;
  for (const TrackedTag& tag : report.tags) {
    if (!tag.measured) continue;
    const Eigen::Vector3d& t = tag.cam_from_tag.translation;
    std::snprintf(text, sizeof(text), "  id %d at (%.3f, %.3f, %.3f) m, %.2f px", tag.id, t.x(), t.y(), t.z(),
                  tag.pose.rms_reprojection_px);
    line += text;
  }
  if (const MapTrackerFrameReport* map = session.sources().map_report()) {
    std::snprintf(text, sizeof(text), "  [map: %s, %d inliers%s; pose: %s%s]", MapTrackingStateName(map->state),
                  map->found ? map->inliers : 0, map->relocalised ? ", relocalised" : "",
                  PoseSourceKindName(session.sources().source()), session.metric() ? "" : ", model units");
    line += text;
  }
  if (report.predicted_searched > 0) {
    std::snprintf(text, sizeof(text), "  [%s + %d predicted (%d found), %.2f ms]", TagSearchName(session),
                  report.predicted_searched, report.predicted_found, session.pose().track_ms);
  } else {
    std::snprintf(text, sizeof(text), "  [%s, %.2f ms]", TagSearchName(session), session.pose().track_ms);
  }
  return line + text;
}

std::string PoseSourceSummary(const PoseSourceCounts& frames_by_source) {
  std::string text = "posed by";
  for (size_t kind = 1; kind < frames_by_source.size(); ++kind) {
    text += std::string(kind > 1 ? ", " : " ") + PoseSourceKindName(static_cast<PoseSourceKind>(kind)) + " " +
            std::to_string(frames_by_source[kind]);
  }
  return text + "; not posed " + std::to_string(frames_by_source[static_cast<size_t>(PoseSourceKind::kNone)]);
}

}  // namespace reconar::tools
