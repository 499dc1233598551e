#include "tracker/map_follower.h"

#include <chrono>
#include <map>
#include <string>
#include <utility>
#include <vector>

#include "core/math/rigid3.h"

namespace reconar {

std::optional<Sim3> MapFromMap(const LocalizationMap& to, const LocalizationMap& from) {
  std::map<std::string, Eigen::Vector3d> from_centres;
  for (const MapKeyframe& keyframe : from.keyframes)
    from_centres[keyframe.name] = CameraCenterInWorld(keyframe.cam_from_world);
  std::vector<Eigen::Vector3d> from_points, to_points;
  for (const MapKeyframe& keyframe : to.keyframes) {
    const auto found = from_centres.find(keyframe.name);
    if (found == from_centres.end()) continue;
    from_points.push_back(found->second);
    to_points.push_back(CameraCenterInWorld(keyframe.cam_from_world));
  }
  if (from_points.size() < 3) return std::nullopt;
  Result<Sim3> to_from_from = AlignSimilarity(from_points, to_points);
  if (!to_from_from.ok()) return std::nullopt;
  return *to_from_from;
}

Result<MapSwitch> MapFollower::TakeUp(int version, std::shared_ptr<const LocalizationMap> map,
                                      std::shared_ptr<const Localizer> localizer,
                                      const CameraIntrinsics& map_intrinsics, int frame_width, int frame_height) {
  if (map == nullptr) return InvalidArgument("MapFollower::TakeUp: no map");
  const auto start = std::chrono::steady_clock::now();
  MapSwitch result;
  tracker_.reset();  // it borrows the old map
  if (map_ != nullptr) result.new_from_old = MapFromMap(*map, *map_);
  map_ = std::move(map);
  localizer_ = std::move(localizer);
  version_ = version;
  MapTrackerOptions options = options_;
  options.intrinsics = ScaledIntrinsics(map_intrinsics, frame_width, frame_height);
  RECONAR_ASSIGN_OR_RETURN(tracker_, localizer_ ? MapTracker::Create(localizer_, options)
                                                : MapTracker::Create(map_.get(), options));
  result.milliseconds =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  return result;
}

Status MapFollower::Track(ImageView<const uint8_t> gray, MapTrackerFrameReport* report) {
  if (tracker_ == nullptr) return FailedPrecondition("MapFollower::Track: no map taken up");
  return tracker_->Track(gray, nullptr, report);
}

}  // namespace reconar
