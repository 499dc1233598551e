#pragma once
// Patch expansion of PMVS (Furukawa & Ponce 2010, sec. 3.2). For every patch p and every image i
// of T(p), the 4-neighbours of p's cell in i that hold no patch become hypotheses: the centre is
// where the ray through the cell centre meets p's plane, the normal and reference those of p;
// PatchRefiner decides. Runs in waves: the hypotheses of a wave (one per empty cell) are refined
// in parallel, merged in a fixed order (a cell filled earlier in the same wave drops later
// hypotheses), and the accepted patches form the next wave. A cell is tried at most once per
// call. Deterministic for any thread count.
#include <vector>

#include "core/base/thread_pool.h"
#include "core/mvs/pmvs/patch.h"
#include "core/mvs/pmvs/patch_cell_grid.h"
#include "core/mvs/pmvs/patch_mvs.h"
#include "core/mvs/pmvs/pmvs_view.h"

namespace reconar {

// Expands from the patches listed in `seeds` (indices into *patches) until no wave adds one.
// Returns the number of patches added.
size_t ExpandPatches(const std::vector<PmvsView>& views, const PatchMvsOptions& options, std::vector<int> seeds,
                     ThreadPool* pool, std::vector<Patch>* patches, PatchCellGrids* grids);

}  // namespace reconar
