#pragma once
// PatchSampler: the photometric side of a patch (Furukawa & Ponce 2010, sec. 2.2). The mu x mu
// grid lies on the patch plane and is spanned by the back-projections of one-pixel steps in the
// reference image R, so it projects onto an axis-aligned pixel grid in R; the grid is projected
// into any other image by one homogeneous projection per sample and sampled bilinearly from the
// grey image. One instance per worker: it holds fixed scratch and allocates nothing.
#include <Eigen/Core>
#include <array>
#include <vector>

#include "core/mvs/pmvs/ncc.h"
#include "core/mvs/pmvs/pmvs_view.h"

namespace reconar {

class PatchSampler {
 public:
  static constexpr int kMaxPatchSize = 15;
  static constexpr int kMaxSamples = PaddedNccCount(kMaxPatchSize * kMaxPatchSize);

  // patch_size is odd and at most kMaxPatchSize (PatchMvsOptions::Check); min_texture_std in grey
  // levels (PatchMvsOptions::min_texture_std).
  PatchSampler(const std::vector<PmvsView>& views, int patch_size, double min_texture_std);

  // Places the grid on the plane (center, normal) and samples the reference view. False when the
  // plane is seen edge-on from R, the grid leaves R, or the standard deviation of R's samples is
  // below min_texture_std.
  bool SetPatch(const Eigen::Vector3d& center, const Eigen::Vector3d& normal, int reference);
  // NCC of the grid in `image` against R (SetPatch succeeded); -1 when the grid leaves the image.
  float Ncc(int image);
  // Mean RGB of the grid in the reference image (SetPatch succeeded).
  Eigen::Vector3f MeanReferenceColor() const;

  int reference() const { return reference_; }
  // World offset of one grid step along the reference image's x axis (one pixel in R).
  const Eigen::Vector3d& axis_x() const { return axis_x_; }

 private:
  // Fills out[0, count) with bilinear grey samples; false when a sample is outside or behind.
  bool Sample(const PmvsView& view, float* out) const;

  const std::vector<PmvsView>& views_;
  const NccKernel& kernel_;
  int patch_size_;
  int count_;
  float min_texture_std_;
  int reference_ = -1;
  Eigen::Vector3d origin_ = Eigen::Vector3d::Zero();  // grid sample (0, 0)
  Eigen::Vector3d axis_x_ = Eigen::Vector3d::Zero();
  Eigen::Vector3d axis_y_ = Eigen::Vector3d::Zero();
  alignas(32) std::array<float, kMaxSamples> reference_samples_{};
  alignas(32) std::array<float, kMaxSamples> samples_{};
};

}  // namespace reconar
