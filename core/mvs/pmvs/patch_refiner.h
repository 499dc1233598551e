#pragma once
// PatchRefiner: turns a patch hypothesis (centre, normal, reference image) into an accepted patch
// or nothing, as PMVS does for both initial matches and expansions (Furukawa & Ponce 2010,
// sec. 3.1 and 3.2):
//   1. V(p): images other than R that see the plane within iota, in front, with the grid inside;
//   2. images of V(p) whose NCC with R reaches min_ncc - 0.3 (PMVS's looser pre-threshold, its
//      alpha0 = 0.6 before and 0.3 after refinement on 1 - NCC). A feature match (kFeatureMatch)
//      needs one such image: it seldom correlates with more while its normal is still the
//      fronto-parallel guess. An expansion (kExpansion) inherits its parent's refined normal and
//      needs gamma - 1 such images, as PMVS2 requires before refining: a hypothesis that the
//      pre-threshold already denies gamma images would have to gain them by refinement, which
//      seldom happens and costs ~50 evaluations each time;
//   3. refinement of depth along R's ray (one dof) and normal (two angles) maximising the mean NCC
//      over those images, by Nelder-Mead (PMVS uses the simplex method as well);
//   4. V(p) and T(p) = {R} + {images with NCC >= min_ncc} recomputed; accepted if |T(p)| >= gamma.
// One instance per worker; it reuses its scratch.
#include <Eigen/Core>
#include <vector>

#include "core/mvs/pmvs/patch.h"
#include "core/mvs/pmvs/patch_mvs.h"
#include "core/mvs/pmvs/patch_sampler.h"
#include "core/mvs/pmvs/pmvs_view.h"

namespace reconar {

class PatchRefiner {
 public:
  PatchRefiner(const std::vector<PmvsView>& views, const PatchMvsOptions& options);

  enum class Hypothesis { kFeatureMatch, kExpansion };

  // Returns true and fills *patch when the hypothesis becomes an accepted patch.
  bool Reconstruct(const Eigen::Vector3d& center, const Eigen::Vector3d& normal, int reference, Hypothesis kind,
                   Patch* patch);

  // Images other than `reference` that see the plane (center, normal) within the view angle and
  // with the patch inside the image.
  void VisibleImages(const Eigen::Vector3d& center, const Eigen::Vector3d& normal, int reference,
                     std::vector<int>* images) const;

  int evaluations() const { return evaluations_; }

 private:
  double MeanNcc(const Eigen::Vector3d& center, const Eigen::Vector3d& normal);

  const std::vector<PmvsView>& views_;
  PatchMvsOptions options_;
  double min_cos_view_angle_;
  PatchSampler sampler_;
  std::vector<int> visible_;
  std::vector<int> optimisation_images_;
  int evaluations_ = 0;
};

}  // namespace reconar
