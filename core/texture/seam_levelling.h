#pragma once
// Step 3 of texturing (texture_mesh.h): colours that match across the patches' borders.
//
// Samples: at every vertex of a seam edge (two faces of different patches), the colour of each
// of the two patches' photos there (the reduced photos of face_views.h, times the photo's gain).
// Global: one RGB offset per patch minimising the sum over samples of
// |colour_p + offset_p - colour_q - offset_q|^2 (Huber-weighted over three rounds, so that a
// sample on an occlusion border does not pull a whole patch) plus, per patch,
// kConsensusWeight * faces * |offset_p - consensus_p|^2 (view_labelling.h's PatchConsensus: each of
// the patch's faces seen by three photos or more pulls it, a tenth as hard as one seam sample,
// towards the median of the photos; a patch without such faces towards no offset, as if it had
// one). That fixes the free common shift, and keeps the texture's tone that of most photos rather
// than that of the photos that happened to win large patches. Solved by conjugate gradients on the
// patches' graph Laplacian.
// Local: at each seam vertex, every patch meeting there is moved the rest of the way to their mean
// colour; the move fades linearly to zero over `blend_rings` rings of vertices into the patch.
// The texel colour is the photo's plus its patch's offset plus the barycentric mix of its face's
// vertex moves.
#include <array>
#include <cstdint>
#include <unordered_map>
#include <vector>

#include <Eigen/Core>

#include "core/mesh/mesh.h"
#include "core/texture/face_views.h"
#include "core/texture/view_labelling.h"

namespace reconar {

struct PatchColourCorrection {
  std::vector<Eigen::Vector3f> patch_offset;                           // per patch
  std::vector<std::unordered_map<uint32_t, Eigen::Vector3f>> vertex_move;  // per patch, where non-zero

  // Offset of patch p at mesh vertex v.
  Eigen::Vector3f At(int patch, uint32_t vertex) const;
};

// An edge between faces of two patches.
struct SeamEdge {
  uint32_t a = 0, b = 0;  // mesh vertices
  int face_a = -1, face_b = -1;
  int patch_a = -1, patch_b = -1;
};

std::vector<SeamEdge> FindSeamEdges(const Mesh& mesh, const TexturePatches& patches,
                                    const std::vector<std::array<int, 3>>& neighbours);

// No correction at all (every offset zero) for `num_patches` patches.
PatchColourCorrection NoCorrection(size_t num_patches);

PatchColourCorrection LevelSeams(const Mesh& mesh, const TexturePatches& patches, const std::vector<SeamEdge>& edges,
                                 const std::vector<PhotoProjector>& projectors,
                                 const std::vector<ReducedPhoto>& reduced, const std::vector<Eigen::Vector3f>& gains,
                                 const PatchConsensus& consensus, int blend_rings);

}  // namespace reconar
