#pragma once
// OrientedPoints: the dense stage's output, a point cloud with one unit normal, colour and
// confidence per point (the input of Poisson surface reconstruction). World coordinates, the frame
// of the sparse model; normals point from the surface towards the cameras that saw it.
#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <vector>

namespace reconar {

struct OrientedPoints {
  std::vector<Eigen::Vector3f> positions;
  std::vector<Eigen::Vector3f> normals;           // unit length
  std::vector<std::array<uint8_t, 3>> colors;     // RGB
  std::vector<float> scores;                      // photometric consistency, e.g. mean NCC in [-1, 1]

  size_t size() const { return positions.size(); }
};

}  // namespace reconar
