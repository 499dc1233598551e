#pragma once
// Texturing a mesh from the registered photos (after Waechter, Moehrle and Goesele, "Let There Be
// Color! Large-Scale Texturing of 3D Reconstructions", ECCV 2014), in four steps:
//
// 1. Candidates (face_views.h): in each photo, a depth buffer of the whole mesh decides which faces
//    the photo sees; a seen face gets a quality (its projected area times the photo's local
//    gradient magnitude: close, frontal and sharp views win) and its mean colour there.
// 2. Labels: each photo's exposure is levelled to all the others' at once (photo_gains.h); per face
//    (view_labelling.h), candidates whose colour disagrees with the others' (a passer-by, a
//    reflection) are dropped; then each face takes a photo so that its own quality
//    and its neighbours' agreement are best together (a Potts labelling). Connected faces with the
//    same photo form a patch.
// 3. Seams (seam_levelling.h): one colour offset per patch, by least squares over the patches'
//    colours at the seam vertices, then per-vertex offsets that meet at the seam and fade into
//    each patch.
// 4. Atlas (texture_atlas.h): each patch's faces keep their photo's projection as their chart,
//    the charts are packed into one texture and filled from the full-resolution photo through
//    the camera model, with the offsets added; every chart is padded against bleeding at mipmaps.
//
// Faces no photo sees keep their vertex colour (glTF's COLOR_0 times a white texel).
#include <cstddef>
#include <functional>
#include <string>
#include <vector>

#include "core/base/image.h"
#include "core/base/status.h"
#include "core/math/rigid3.h"
#include "core/mesh/mesh.h"
#include "core/sfm/reconstruction.h"

namespace reconar {

struct TexturePhoto {
  std::string name;
  SfmCamera camera;
  Rigid3 cam_from_world;
};

// The photo's pixels as the camera saw them (RGB, camera.width x camera.height), e.g. decoded
// from disk. Called from several threads at once, and more than once per photo when the photos do
// not all fit in the memory budget.
using PhotoLoader = std::function<Result<Image<uint8_t>>(size_t photo_index)>;

struct TextureOptions {
  int atlas_size = 4096;    // largest side of a texture page, texels (a power of two)
  // More pages when one does not hold the charts at the photos' resolution, up to this many, and
  // fewer when the memory budget is set: the pages may take half of it.
  int max_pages = 4;
  int padding_texels = 4;   // around each chart: clean down to mip level log2(padding)
  // The depth buffers and the candidates' colours are computed on the photo reduced by a power of
  // two to at most this long side.
  int raster_long_side = 1024;
  // A face is a candidate in a photo only when it faces the camera at least this much (cosine of
  // the angle between its normal and the line of sight).
  double min_view_cosine = 0.2;
  // Depth test: a sample passes when no farther than the buffer's depth times (1 + this).
  double depth_tolerance = 0.01;
  // Potts weight: the cost of a neighbour in another photo, against a data cost of
  // 1 - quality / best quality of the face.
  double smoothness = 0.3;
  int max_labelling_sweeps = 30;
  bool check_photo_consistency = true;
  bool level_exposure = true;  // a gain per photo and channel (photo_gains.h)
  bool level_seams = true;
  int blend_rings = 6;  // how far into a patch the local seam correction fades
  // A photo stays decoded from the views to the atlas while the process, with it, stays under this
  // less what the atlas will take (texels, coverage, PNG); the others are decoded again for their
  // charts. 0: all kept.
  size_t memory_budget_bytes = 0;
  int num_threads = 0;             // 0: one per core
  bool show_progress = false;

  Status Check() const;
};

struct TextureReport {
  size_t faces = 0, photos = 0;
  size_t photos_used = 0;       // photos that texture at least one face
  size_t candidates = 0;        // (face, photo) pairs seen
  size_t inconsistent_candidates = 0;  // dropped by the colour check
  double min_gain = 1.0, max_gain = 1.0;  // the photos' exposure gains, over photos and channels
  size_t textured_faces = 0, untextured_faces = 0;
  size_t patches = 0;
  size_t faces_merged = 0;  // faces of small patches that joined a neighbouring patch's photo
  int labelling_sweeps = 0;
  double labelling_energy_start = 0.0, labelling_energy_end = 0.0;
  // Mean colour difference (0..255, mean over the channels) across the patches' borders in the
  // atlas, at the seam edges' midpoints, before levelling (the photos as they are) and after
  // (exposure gains, patch offsets and local moves; texture_atlas.h).
  double seam_step_before = 0.0, seam_step_after = 0.0;
  size_t seam_edges = 0;
  int atlas_width = 0, atlas_height = 0;  // the first page's
  size_t atlas_pages = 0;
  double texels_per_pixel = 0.0;  // the charts' scale against the photos' full resolution
  double atlas_fill = 0.0;        // fraction of the pages' texels that some face covers
  size_t photos_kept_decoded = 0;  // from the views to the atlas (memory_budget_bytes)
  std::vector<Eigen::Vector3f> photo_gains;  // per photo, in order: its exposure gain (1 unlevelled)
  double seconds_candidates = 0.0, seconds_labelling = 0.0, seconds_seams = 0.0, seconds_atlas = 0.0;
  double seconds = 0.0;
};

struct TexturedMesh {
  // Positions, normals (when the input has them) and texcoords (u right, v down, over their
  // page); colours only when some face is untextured (white on textured vertices). A vertex is
  // repeated in every chart it borders.
  Mesh mesh;
  std::vector<TexturePage> pages;  // RGB, the first at triangle 0
};

// The mesh textured from `photos`. The mesh must pass ValidateMesh and have triangles.
// FailedPrecondition when no photo sees any face (the caller keeps the untextured model);
// a photo the loader cannot deliver is an error naming it.
Result<TexturedMesh> TextureMesh(const Mesh& mesh, const std::vector<TexturePhoto>& photos, const PhotoLoader& load,
                                 const TextureOptions& options, TextureReport* report);

}  // namespace reconar
