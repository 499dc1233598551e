#pragma once
// Fusion of PatchMatch depth maps into oriented points (Schoenberger et al. 2016 sec. 4.4, in
// the simple form of Xu & Tao 2019): a pixel whose cost is at most max_cost is checked against the
// depth maps of its source views; a source agrees when, at the pixel where the point projects, its
// depth matches (relative difference), its own point reprojects close to the pixel and the
// normals agree. A pixel with at least fusion_min_views agreeing sources becomes one point, the
// mean of its own and the agreeing sources' points and normals; those source pixels are used up.
// Only every fusion_pixel_step-th pixel of every fusion_pixel_step-th row starts a point.
#include <cstddef>
#include <vector>

#include "core/mvs/dense_view.h"
#include "core/mvs/oriented_points.h"
#include "core/mvs/patchmatch/depth_map.h"
#include "core/mvs/patchmatch/patchmatch_mvs.h"

namespace reconar {

class ThreadPool;

struct DepthFusionStats {
  size_t depth_pixels = 0;       // pixels with a depth whose cost is at most max_cost
  size_t consistent_pixels = 0;  // of them, pixels with at least fusion_min_views agreeing sources
  double seconds_consistency = 0.0;
  double seconds_fusion = 0.0;
};

// maps[v] may be empty (no depth map); sources[v] are view v's source views (indices into views).
OrientedPoints FuseDepthMaps(const std::vector<const DenseView*>& views, const std::vector<DepthMap>& maps,
                             const std::vector<std::vector<int>>& sources, const PatchMatchOptions& options,
                             ThreadPool* pool, DepthFusionStats* stats);

}  // namespace reconar
