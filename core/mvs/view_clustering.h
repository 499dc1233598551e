#pragma once
// View clustering for dense reconstruction, after CMVS (Y. Furukawa, B. Curless, S. M. Seitz,
// R. Szeliski, "Towards Internet-scale multi-view stereo", CVPR 2010; summarised in Yang et al.
// 2013, sec. 2.2). The sparse model decides which registered images PMVS sees together:
//  1. Redundant images are dropped: taken from the lowest mean resolution up, an image goes when
//     every sparse point it sees well stays seen well by enough kept images (below).
//  2. The view graph over the kept images (edge weight: sparse points two images share) is split
//     into connected components and then by recursive normalised cuts (Shi & Malik's spectral
//     relaxation, balanced sweep of the Fiedler vector) until no part exceeds max_cluster_size.
//  3. Images are added to clusters, greedily by the number of points they make reconstructable,
//     until every kept image has at least coverage_ratio of its points covered by some cluster
//     (CMVS's per-image coverage constraint); when no cluster with room helps, a new cluster grows
//     around the worst-covered image.
// Resolution of point P in image I: f_I / depth_I(P) (pixels per world unit). P is seen "well" by
// I when that is at least resolution_ratio times its best resolution; a cluster covers P when it
// holds min(min_views_per_point, #kept good views of P) of those views. Points seen by fewer than
// two registered images are ignored.
// Without sparse points (cameras known from elsewhere, e.g. rendered scenes) the graph weights come
// from the cameras: w = exp(-d^2 / (2 (2 s)^2)) cos(angle) for optical axes closer than
// max_view_angle, d the centre distance and s the median nearest-centre distance; no image is
// removed, parts are bounded by 3/4 of max_cluster_size and each then grows in rings of its
// strongest outside neighbours up to max_cluster_size so that neighbouring clusters overlap.
// Deterministic: no randomness, ties broken by image id.
#include <vector>

#include "core/base/status.h"
#include "core/sfm/reconstruction.h"

namespace reconar {

struct ViewClusteringOptions {
  // Images given to one PMVS run: its memory grows with cluster size x pixels per image at the
  // chosen level (see core/mvs/dense_memory.h), so this is the knob that bounds it.
  int max_cluster_size = 20;
  double coverage_ratio = 0.7;  // CMVS delta
  bool remove_redundant = true;
  int min_views_per_point = 3;   // PMVS's default minimum of visible views
  double resolution_ratio = 0.7; // CMVS lambda: "comparable resolution"
  double max_view_angle = 1.0471975511965976;  // pi/3, for the fallback without points

  // InvalidArgument naming the bad field.
  Status Check() const;
};

struct ViewClustering {
  std::vector<int> kept_images;     // registered images given to some cluster, ascending ids
  std::vector<int> removed_images;  // registered images dropped as redundant, ascending ids
  std::vector<std::vector<int>> clusters;  // image ids, each ascending
  bool from_camera_geometry = false;  // true when the fallback without sparse points was used
  int points_considered = 0;          // sparse points seen by at least two registered images
  double covered_fraction = 0.0;      // of those, the part covered by some cluster
};

// InvalidArgument for bad options; FailedPrecondition when no image is registered.
Result<ViewClustering> ClusterViews(const Reconstruction& reconstruction, const ViewClusteringOptions& options);

}  // namespace reconar
