#pragma once
// Step 2a of texturing (texture_mesh.h): a gain per photo and channel that brings its colours to
// the photos' common exposure.
//
// Photos of one scene differ in exposure and white balance: a camera on automatic exposes each
// frame for what it frames, so a photo of a dark corner comes out bright. A texture made of several
// photos shows that as patches of another brightness, and as a tone that drifts across the model.
//
// In logs, a candidate k (photo p, face f; view_labelling.h) of colour c_k brought to the common
// exposure is log c_k + a_p, a_p = log gain, and should equal the face's own log colour r_f.
// Per channel, over every face seen by two photos or more at once, the gains minimise
//   sum_k w_k (log c_k + a_p - r_f)^2.
// Eliminating each r_f (the weighted mean of its candidates) leaves a linear system in the a_p
// alone: a weighted graph Laplacian of the photos, every face adding the clique of its photos.
// Solving it at once levels every photo against all the others through the chains of faces they
// share; levelling each photo against the median of its own faces only (the one-shot ratio used
// before) leaves each at its neighbours' mean exposure, and the texture's tone drifted across a
// room by up to 1.5x.
//
// Robust: iteratively reweighted, Huber weights on each candidate's RMS log residual over the
// channels (one weight for the three channels: a passer-by is off in all of them), the scale from
// the median residual. Candidates darker than kMinGainColour or brighter than kMaxGainColour in a
// channel are left out (noise in the log; clipping does not scale). A tiny ridge pulls each a_p
// towards 0: it fixes the common shift of each group of photos that share faces and leaves a
// photo that shares none at gain 1. Then one common scale per channel keeps the mean colour of all
// the candidates as the photos show it.
#include <cstddef>
#include <vector>

#include <Eigen/Core>

#include "core/texture/view_labelling.h"

namespace reconar {

inline constexpr float kMinGainColour = 16.0f;   // RGB, 0..255
inline constexpr float kMaxGainColour = 250.0f;

struct PhotoGainOptions {
  // Reweighting ends when no log gain moves by more than `tolerance` (0.1 %), or after `max_rounds`
  // (the first unweighted).
  int max_rounds = 30;
  double tolerance = 1e-3;
};

std::vector<Eigen::Vector3f> EstimatePhotoGains(const FaceCandidateTable& table, size_t num_photos,
                                                const PhotoGainOptions& options = {});

// Multiplies every candidate's colour by its photo's gain.
void ApplyPhotoGains(const std::vector<Eigen::Vector3f>& gains, FaceCandidateTable* table);

}  // namespace reconar
