#pragma once
// The Stanford Bunny's ten real Cyberware range scans (../shared/data/stanford_bunny/range_scans,
// see its SOURCE.txt) as one oriented point cloud: a realistic, noisy, partially overlapping
// input for Poisson meshing, whose answer is compared with reconstruction/bun_zipper.ply.
// Test support and benchmarks only.
#include <string>

#include "core/base/status.h"
#include "core/mesh/mesh.h"

namespace reconar::testing {

// Reads bun.conf and every scan it names ("bmesh FILE tx ty tz qx qy qz qw") from
// `range_scans_dir`, and returns their vertices in the common frame with unit normals.
// - Alignment (verified on the data, see SOURCE.txt): p_aligned = R(q)^T * p_scan + t, where
//   R(q) is the rotation of the unit quaternion (qw the real part); normals turn by R(q)^T.
// - Normals: each scan's "range_grid" (num_rows x num_cols cells, row-major, holding 0 or 1
//   vertex index) is triangulated, each 2x2 block of cells giving two triangles (one when a
//   corner is missing), split along the shorter diagonal; triangles with an edge longer than
//   4x the scan's median grid-neighbour distance (depth discontinuities) are dropped. A vertex's
//   normal is the area-weighted mean of its triangles' normals, oriented towards the scanner
//   (+z of the scan frame, the side the grid's winding faces). Vertices in no kept triangle are
//   dropped: every returned point has a normal.
// The result is a point cloud (no triangles), positions in metres, scans in bun.conf order.
// Errors: kNotFound for a missing bun.conf or scan, kCorruptData naming the file and the reason
// for anything that does not parse (header, counts, grid indices).
Result<Mesh> LoadBunnyRangeScans(const std::string& range_scans_dir);

}  // namespace reconar::testing
