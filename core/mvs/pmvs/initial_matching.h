#pragma once
// Initial feature matching of PMVS (Furukawa & Ponce 2010, sec. 3.1). For every feature f of a
// reference image I (cells of I already holding a patch are skipped): the features of the same
// type in the neighbouring views J that lie within 2 pixels of f's epipolar line are triangulated;
// the candidates are tried in order of distance from I's centre, each as a patch with centre the
// triangulated point, normal towards I and reference I (PatchRefiner), until one is accepted.
#include <vector>

#include "core/base/thread_pool.h"
#include "core/mvs/pmvs/image_features.h"
#include "core/mvs/pmvs/patch.h"
#include "core/mvs/pmvs/patch_cell_grid.h"
#include "core/mvs/pmvs/patch_mvs.h"
#include "core/mvs/pmvs/pmvs_view.h"

namespace reconar {

// Matches the features of every image (in parallel over reference images), then inserts the
// accepted patches into *patches and *grids, dropping those whose reference cell already holds
// a neighbouring patch (the same surface found from another image). Returns the number added.
size_t MatchSeedFeatures(const std::vector<PmvsView>& views, const std::vector<std::vector<SeedFeature>>& features,
                         const PatchMvsOptions& options, ThreadPool* pool, std::vector<Patch>* patches,
                         PatchCellGrids* grids);

}  // namespace reconar
