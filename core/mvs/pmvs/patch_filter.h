#pragma once
// Patch filtering of PMVS (Furukawa & Ponce 2010, sec. 3.3) plus a free-space pass of ours, each computed in
// parallel against the cell grids and applied at once (patches compacted, grids rebuilt):
//   1. visibility consistency: p is an outlier when |T(p)| s(p) < sum of s(q) over the patches q
//      that p occludes (q in p's cell of an image of T(p), not p's neighbour, farther from that
//      camera); s is the mean NCC, PMVS's 1 - g*;
//   1b. free-space consistency (ours, not in the paper): images outside T(p) that see p's place
//      (in frame, facing within iota, no non-neighbour patch in front in that cell) and give an
//      NCC below min_ncc say the place is empty; p goes when they outnumber T(p). It removes
//      foreground fattening at silhouettes against textureless background, where no patch
//      behind or in front gives the other filters evidence;
//   2. depth-map consistency: images of T(p) in which a non-neighbour patch lies in front of p
//      are removed from T(p); p goes when its reference is among them or |T(p)| < gamma;
//   3. regularisation: p goes when fewer than a quarter of the patches in its own and the 8
//      adjacent cells (over the images of T(p)) are its neighbours, or none is.
// Neighbours are judged with rho = cell_size pixels of p's reference image.
#include <vector>

#include "core/base/thread_pool.h"
#include "core/mvs/pmvs/patch.h"
#include "core/mvs/pmvs/patch_cell_grid.h"
#include "core/mvs/pmvs/patch_mvs.h"
#include "core/mvs/pmvs/pmvs_view.h"

namespace reconar {

// Runs the passes; returns the number of patches removed.
size_t FilterPatches(const std::vector<PmvsView>& views, const PatchMvsOptions& options, ThreadPool* pool,
                     std::vector<Patch>* patches, PatchCellGrids* grids);

}  // namespace reconar
