#pragma once
// The recorded AR video of ../shared/data/apriltag_ar_video_id12 (SOURCE.txt): 93 frames 640x480 of
// tag36h11 id 12, its camera matrix, tag size and reference corners (libapriltag decimate 1 output
// in libapriltag's corner order; corners.txt has libapriltag's pixel convention, the centre of the
// top-left pixel at (0.5, 0.5), and ReadArVideoFrames converts them to the program's, (0, 0), as
// TagDetector does).
// Header-only: used by tests and by the benchmarks.
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "core/math/camera_intrinsics.h"

namespace reconar::testing {

inline std::string ArVideoDir() { return std::string(RECONAR_SHARED_DATA_DIR) + "/apriltag_ar_video_id12"; }

inline constexpr double kArVideoTagSize = 0.14;  // edge of the black square, metres

// K = [823.8 0 304.8; 0 822.8 236.3; 0 0 1], no distortion ("Given. Do not change").
inline CameraIntrinsics ArVideoCamera() {
  CameraIntrinsics camera;
  camera.width = 640;
  camera.height = 480;
  camera.fx = 823.8;
  camera.fy = 822.8;
  camera.cx = 304.8;
  camera.cy = 236.3;
  return camera;
}

struct ArVideoFrame {
  std::string name;            // "frame0000.jpg"
  Eigen::Vector2d corners[4];  // reference corners a..d, the program's pixel convention
};

// corners.txt in file order; empty when the file cannot be read.
inline std::vector<ArVideoFrame> ReadArVideoFrames() {
  std::vector<ArVideoFrame> frames;
  std::ifstream file(ArVideoDir() + "/corners.txt");
  for (std::string line; std::getline(file, line);) {
    if (line.empty() || line[0] == '#') continue;
    std::istringstream fields(line);
    ArVideoFrame frame;
    fields >> frame.name;
    for (Eigen::Vector2d& c : frame.corners) {
      fields >> c.x() >> c.y();
      c -= Eigen::Vector2d(0.5, 0.5);
    }
    if (fields) frames.push_back(frame);
  }
  return frames;
}

}  // namespace reconar::testing
