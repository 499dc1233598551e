#pragma once
// Outliers of a point cloud before surface reconstruction, in two tests that both adapt to the
// local sampling density (multi-view stereo samples a surface at a spacing that grows with depth):
//  - isolated points: the mean distance d_i to a point's k nearest neighbours, divided by the
//    median d_j of those neighbours (the local outlier idea of Breunig et al. 2000, "LOF"), is
//    compared in log space against the cloud's median ratio by robust sigmas (1.4826 * median
//    absolute deviation; the statistical outlier removal of Rusu et al. 2008 with median/MAD),
//    and must exceed `min_isolation_ratio` (a regular grid has MAD 0; its edge points are sparser);
//  - small pieces: connected components of the k-NN graph whose edges are no longer than
//    `link_factor` times the smaller d of their two ends; pieces holding less than
//    `min_component_fraction` of the points that passed the first test are floaters (mismatched
//    patches hanging in front of a surface).
// Coincident points are tested as one point and share its verdict.
#include <Eigen/Core>
#include <cstdint>
#include <vector>

#include "core/base/status.h"

namespace reconar {

struct OutlierFilterOptions {
  int neighbors = 8;                     // k; >= 1
  double max_robust_sigmas = 3.0;        // isolated when the log ratio > median + this many robust sigmas
  double min_isolation_ratio = 3.0;      // ... and d_i > this multiple of its neighbours' median d_j
  double link_factor = 2.0;              // component edges up to this multiple of d; > 0
  double min_component_fraction = 0.01;  // in [0, 1); 0 keeps every piece
  int num_threads = 0;                   // 0: one per core

  Status Check() const;
};

struct OutlierFilterReport {
  size_t input_points = 0;
  size_t isolated_removed = 0;     // first test
  size_t small_piece_removed = 0;  // second test
  int pieces = 0;                  // components among the points that passed the first test
  int pieces_kept = 0;
  double median_spacing = 0.0;  // median of d_i, the cloud's units
  size_t kept_points() const { return input_points - isolated_removed - small_piece_removed; }
};

// keep[i] = 1 for the points that pass both tests. kInvalidArgument for bad options or a
// non-finite position; clouds of at most `neighbors` points are kept whole.
Result<std::vector<uint8_t>> FindInlierPoints(const std::vector<Eigen::Vector3f>& positions,
                                              const OutlierFilterOptions& options,
                                              OutlierFilterReport* report = nullptr);

}  // namespace reconar
