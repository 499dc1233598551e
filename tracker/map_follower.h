#pragma once
// MapFollower: the camera followed against a map that is replaced while it runs, as the live
// model's is at each of its global adjustments (core/pipeline/live_reconstruction.h, LiveMap).
// TakeUp() switches to a newer map: the tracker is built again over it, and the similarity that
// takes the old map's frame into the new one's (from the centres of the keyframes both maps
// hold) is returned, so that what the caller holds in the old frame (the keyframe gate's last
// keyframe pose) can be carried over. Track() poses a frame against the map taken up last.
#include <memory>
#include <optional>

#include "core/base/image.h"
#include "core/base/status.h"
#include "core/math/camera_intrinsics.h"
#include "core/math/sim3.h"
#include "core/sfm/localization_map.h"
#include "core/sfm/localizer.h"
#include "tracker/map_tracker.h"

namespace reconar {

// The similarity taking map `from`'s frame into map `to`'s, from the centres of the keyframes both
// hold (by name). Unset with fewer than 3 shared (or all on one spot).
std::optional<Sim3> MapFromMap(const LocalizationMap& to, const LocalizationMap& from);

struct MapSwitch {
  std::optional<Sim3> new_from_old;  // unset for the first map or maps without 3 shared keyframes
  double milliseconds = 0.0;         // to build the tracker over the new map
};

class MapFollower {
 public:
  // options.intrinsics is replaced at each TakeUp by the map's camera scaled to the frame.
  explicit MapFollower(const MapTrackerOptions& options) : options_(options) {}

  // The map `version` (its localizer may be null: one is built), for frames of the given size.
  // `map` must outlive the follower's use of it (it is shared). Errors of MapTracker::Create.
  Result<MapSwitch> TakeUp(int version, std::shared_ptr<const LocalizationMap> map,
                           std::shared_ptr<const Localizer> localizer, const CameraIntrinsics& map_intrinsics,
                           int frame_width, int frame_height);

  // The frame against the map taken up last; FailedPrecondition before the first TakeUp.
  Status Track(ImageView<const uint8_t> gray, MapTrackerFrameReport* report);

  bool following() const { return tracker_ != nullptr; }
  int version() const { return version_; }  // of the map taken up last; 0: none

 private:
  MapTrackerOptions options_;
  int version_ = 0;
  std::shared_ptr<const LocalizationMap> map_;
  std::shared_ptr<const Localizer> localizer_;
  std::unique_ptr<MapTracker> tracker_;  // borrows map_ or localizer_
};

}  // namespace reconar
