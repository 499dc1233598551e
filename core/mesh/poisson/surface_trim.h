#pragma once
// Density trim of a reconstructed surface, as PoissonRecon's SurfaceTrimmer (Kazhdan & Hoppe 2013,
// distributed with PoissonRecon) does it:
//  - every triangle is split along the line where the linearly interpolated vertex value equals
//    `trim` into a part at or above it and a part below (new vertices on the cut edges are shared,
//    so the result stays watertight where it was);
//  - the parts above and the parts below are grouped into connected components (by shared
//    vertices); a component smaller than island_area_ratio x the total area swaps sides: small
//    regions below the trim value (holes the trim would cut) are kept, small regions above it
//    (islands left in removed surface) are dropped;
//  - what remains: the large components above and the small components below.
// Colours are interpolated onto the new vertices; normals are left to the caller.
#include <vector>

#include "core/mesh/mesh.h"

namespace reconar::poisson {

struct SurfaceTrimOptions {
  float trim = 0.0f;
  float island_area_ratio = 0.001f;  // SurfaceTrimmer --aRatio default
};

// vertex_values: one per mesh->positions entry. Rewrites positions, colours (when present) and
// triangles; clears normals.
void TrimSurface(const std::vector<float>& vertex_values, const SurfaceTrimOptions& options, Mesh* mesh);

}  // namespace reconar::poisson
