#pragma once
// Marching cubes over the stored cells of one BlockGrid level. The per-configuration polygons
// are derived, not tabulated: on each cube face the iso-line segments cut off every run of
// inside corners (value < iso) separately, so the two cubes sharing a face always choose the same
// segments and the surface is watertight and manifold wherever all the cells it crosses are
// stored. Polygons are oriented counter-clockwise seen from the outside (value >= iso side).
#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <functional>
#include <vector>

#include "core/mesh/poisson/block_grid.h"

namespace reconar::poisson {

struct IsoSurface {
  std::vector<Eigen::Vector3f> positions;  // in node units of the grid
  std::vector<std::array<uint32_t, 3>> triangles;
  size_t cells_skipped = 0;                 // cells crossing the iso-value with an absent corner
};

// Where the iso-surface crosses the edge from `node` one step along `axis`, as a fraction in
// [0, 1], given the values v0, v1 at its ends (which straddle the iso-value).
using EdgeCrossingFn = std::function<float(const Eigen::Vector3i& node, int axis, float v0, float v1)>;

// edge_crossing: empty = linear interpolation of the corner values (exact for trilinear functions).
IsoSurface ExtractIsoSurface(const BlockGrid& grid, const std::vector<float>& values, float iso,
                             const EdgeCrossingFn& edge_crossing = {});

}  // namespace reconar::poisson
