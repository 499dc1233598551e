#pragma once
// The capture's preview (`reconar capture --out-preview DIR`): the live frame with what the person
// holding the camera should see at a glance, drawn on the CPU (no display needed):
//  - a border in the gate's verdict: green a keyframe, blue keep moving (too close), red a frame
//    the gate refused (blurred, badly exposed, lost);
//  - along the bottom, one square per keyframe: green once registered in the live model, grey
//    until then;
//  - top right, the coverage ring: the directions from which the live model has seen the object
//    (ViewCoverage), green where a registered keyframe stands, dark where none does yet;
//  - the tags in view, outlined in yellow;
//  - top left, on a dark band, the gate's advice ("move sideways", "too fast", ...) and the count
//    of keyframes taken and registered, in the built-in font (bitmap_text.h).
#include <Eigen/Core>
#include <array>
#include <string>
#include <vector>

#include "core/base/image.h"
#include "tracker/keyframe_gate.h"

namespace reconar {

struct CapturePreviewState {
  GateVerdict verdict = GateVerdict::kTooClose;
  std::vector<bool> keyframe_registered;  // one per keyframe taken, in order
  std::vector<bool> coverage;             // sectors counter-clockwise, sector 0 centred on the right
  std::vector<std::array<Eigen::Vector2d, 4>> tags;  // corners of the tags in view, pixels
  std::string advice;                                // GateFrameReport::advice
};

// Draws onto `rgb` (3 channels, interleaved) in place.
void DrawCapturePreview(const CapturePreviewState& state, Image<uint8_t>* rgb);

}  // namespace reconar
