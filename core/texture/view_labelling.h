#pragma once
// Step 2 of texturing (texture_mesh.h): a photo per face.
//
// Photo consistency: a face seen by three photos or more keeps the candidates whose colour lies
// near the median of its candidates' colours (no farther than 3 robust standard deviations, and
// never refused within kMinColourDistance): a passer-by or a reflection in one photo loses the
// face to the photos that agree.
//
// Data term: a candidate's quality is its projected area (close and frontal views win: they hold
// the most pixels of the face) times min(1, its sharpness / the median sharpness of the face's
// candidates). Waechter et al. integrate the gradient magnitude instead; across views of one
// face the texture is the same, so a gradient that differs comes from blur (lower) or from an
// occlusion edge or a highlight crossing the face (higher): the ratio, capped at 1, penalises a
// blurred view without rewarding a face seen against its silhouette.
// It is divided by 1 + (d / kMinColourDistance)^2, d the distance of the candidate's colour from
// the median of the face's candidates: where the photos disagree about a face (the mesh is not
// where the surface is: Poisson's skirts past a wall's edge, thin parts inflated), each photo
// shows whatever lies behind, and the one nearest to what most show is the least wrong from a
// viewpoint no photo had.
//
// Labelling: minimises E = sum over faces of (1 - quality / the face's best quality) plus
// `smoothness` for every edge whose two faces take different photos, by iterated conditional
// modes (each face in turn takes the photo that minimises its own terms, sweeps until none
// changes) from every face's best photo. Each move lowers E, so it ends in a few sweeps; with the
// data term normalised per face, the only faces ICM leaves in a poor local minimum are those
// whose photos are nearly equally good, where the choice costs little. Waechter et al. use loopy
// belief propagation on the same energy; ours is deterministic and allocation-free per sweep.
#include <array>
#include <cstddef>
#include <vector>

#include <Eigen/Core>

#include "core/texture/face_views.h"

namespace reconar {

inline constexpr float kMinColourDistance = 30.0f;  // RGB, 0..255

// The candidates of every face, grouped: face f's are candidates[begin[f] .. begin[f + 1]).
struct FaceCandidateTable {
  std::vector<size_t> begin;
  std::vector<FaceCandidate> candidates;
};

// Groups the candidates (any order) of `num_faces` faces, each face's in photo order.
FaceCandidateTable GroupByFace(size_t num_faces, const std::vector<std::vector<FaceCandidate>>& per_photo);

// Sets every candidate's quality from its area and sharpness (above).
void WeighCandidates(FaceCandidateTable* table);

// Removes the inconsistent candidates; returns how many.
size_t DropInconsistentCandidates(FaceCandidateTable* table);

struct LabellingReport {
  int sweeps = 0;
  double energy_start = 0.0, energy_end = 0.0;
};

// Per face, the chosen photo, or -1 for a face without candidates.
std::vector<int> LabelFaces(const FaceCandidateTable& table, const std::vector<std::array<int, 3>>& neighbours,
                            double smoothness, int max_sweeps, LabellingReport* report);

}  // namespace reconar

namespace reconar {

// Connected faces (across shared edges) with the same photo.
struct TexturePatches {
  std::vector<int> patch_of_face;       // -1 for a face without a photo
  std::vector<int> photo;               // per patch
  std::vector<std::vector<int>> faces;  // per patch, ascending
};

TexturePatches FindPatches(const std::vector<int>& labels, const std::vector<std::array<int, 3>>& neighbours);

// Faces of patches of fewer than `min_faces` faces take the photo most of their neighbours
// outside the patch have, when it is one of their candidates: every small patch costs a chart's
// padding in the atlas and a seam. Returns how many faces changed.
size_t MergeSmallPatches(const FaceCandidateTable& table, const std::vector<std::array<int, 3>>& neighbours,
                         size_t min_faces, std::vector<int>* labels);

// How far each patch's photo stands from what all the photos that see the patch agree on: per
// patch, the mean over its faces seen by three photos or more of (the median of the face's
// candidate colours - the colour of the face in the patch's photo), and how many faces that is.
// One photo's colour is its exposure and its tone mapping of the moment; the median of several is
// closer to what another photo of the place shows (seam_levelling.h pulls the patch towards it).
struct PatchConsensus {
  std::vector<Eigen::Vector3f> offset;  // per patch
  std::vector<size_t> faces;            // per patch
};
PatchConsensus FindPatchConsensus(const FaceCandidateTable& table, const TexturePatches& patches);

}  // namespace reconar
