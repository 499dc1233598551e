#pragma once
// Step 4 of texturing (texture_mesh.h): the charts, their packing and their texels.
//
// A chart is a patch's faces as its photo sees them (a patch that fills little of its bounding
// box is cut into pieces that fill more): its vertices' full-resolution pixels, scaled
// by one factor for the whole atlas (at most 1: never finer than the photos), offset to the
// chart's rectangle, with `padding` texels around. Charts are irregular (their faces fill about
// half their rectangles on the fountain), so they are packed by their shape, not their
// rectangle: per column of kChartColumnWidth texels, the rows its faces take there, widened by
// the padding + 1 rings its texels are grown over, its profile. Tallest first, each chart goes
// where its profile's top sits lowest on the skyline of those before it, the skyline a height per
// column and the chart resting on it by the bottom of its profile, so that it nests into the gaps
// its neighbours' shapes leave; the top of its profile becomes the skyline. Rectangles may
// overlap, profiles never: a chart's texels and padding are written only within its profile. Into
// the narrowest power-of-two square page that holds them all; when atlas_size does not, into pages of
// atlas_size x atlas_size (a chart goes on the first page it fits on), as many as `max_pages`, and
// when even those do not hold them at full resolution, the largest scale that fits is found by
// bisection. Each page's height is cropped to the power of two its charts reach.
// A texel whose centre lies in a face takes the photo's colour of the face's point there (through
// the camera model, so the lens distortion is followed inside the face) times the photo's gain
// plus the seam correction; then each chart's covered texels are grown into its padding, so that
// bilinear filtering and mipmaps down to log2(padding) levels read the chart's own colours.
// Faces no photo sees share a small white chart and keep their vertex colour.
#include <array>
#include <cstdint>
#include <functional>
#include <vector>

#include <Eigen/Core>

#include "core/base/image.h"
#include "core/base/status.h"
#include "core/mesh/mesh.h"
#include "core/texture/face_views.h"
#include "core/texture/seam_levelling.h"
#include "core/texture/view_labelling.h"

namespace reconar {

struct TextureChart {
  int patch = -1;  // -1: the white chart of the faces without a photo
  int photo = -1;
  std::vector<uint32_t> vertices;                    // mesh vertices; a local index is a position here
  std::vector<int> faces;                            // mesh triangles
  std::vector<std::array<uint32_t, 3>> triangles;    // local indices, one per face
  std::vector<Eigen::Vector2d> pixels;               // per local vertex: full-resolution photo pixel
  Eigen::Vector2d pixel_min = Eigen::Vector2d::Zero(), pixel_max = Eigen::Vector2d::Zero();
  int page = 0;                                      // of the atlas
  int x = 0, y = 0, width = 0, height = 0;           // rectangle in its page, padding included
  // Per column of kChartColumnWidth texels of the rectangle, from the left: the rows [first, end)
  // (from the rectangle's top) that its faces and padding may take; end <= first for none.
  std::vector<std::array<int, 2>> profile;

  // Whether the texel (page coordinates) lies within the chart's profile.
  bool Owns(int page_x, int page_y) const;
};

inline constexpr int kChartColumnWidth = 2;

struct AtlasPage {
  int width = 0, height = 0;  // texels, powers of two
};

struct AtlasLayout {
  std::vector<AtlasPage> pages;
  double scale = 1.0;  // texels per photo pixel
  int padding = 0;
  std::vector<TextureChart> charts;

  // Texel coordinates in its page (continuous: texel i spans [i, i + 1)) of a chart's local vertex.
  Eigen::Vector2d Texel(const TextureChart& chart, size_t local_vertex) const;
};

// The charts of every patch, plus the white chart when some face has no patch.
std::vector<TextureChart> MakeCharts(const Mesh& mesh, const TexturePatches& patches,
                                     const std::vector<PhotoProjector>& projectors);

// Places the charts on pages of at most atlas_size x atlas_size texels, at most `max_pages` of them.
// kResourceExhausted when even a tiny scale does not fit (more charts than the pages hold with
// their padding).
Result<AtlasLayout> PackCharts(std::vector<TextureChart> charts, int atlas_size, int padding, int max_pages);

// A photo's full-resolution pixels for the filling: *photo points to them (kept elsewhere, or
// loaded into `storage`).
using PhotoAccess = std::function<Status(size_t photo, Image<uint8_t>* storage, const Image<uint8_t>** photo_pixels)>;

struct AtlasFill {
  std::vector<Image<uint8_t>> pages;  // RGB, as the layout's pages
  double covered_fraction = 0.0;      // of all the pages' texels
};

// `gains`: per photo, multiplying its colours (photo_gains.h).
Result<AtlasFill> FillAtlas(const Mesh& mesh, const AtlasLayout& layout, const std::vector<PhotoProjector>& projectors,
                            const std::vector<Eigen::Vector3f>& gains, const PatchColourCorrection& correction,
                            const PhotoAccess& access, int num_threads);

// The colour step a viewer sees across the seams: for every seam edge, the atlas's colours of
// its two faces at the edge's midpoint, one point seen through two charts (mean absolute
// difference over the channels, 0..255), averaged; `before` the same without the levelling (the
// photos' colours as they are: no exposure gain, no seam correction).
struct SeamSteps {
  double before = 0.0, after = 0.0;
  size_t edges = 0;  // measured
};
SeamSteps MeasureSeamSteps(const Mesh& mesh, const AtlasLayout& layout, const std::vector<Image<uint8_t>>& pages,
                           const std::vector<Eigen::Vector3f>& gains, const PatchColourCorrection& correction,
                           const std::vector<SeamEdge>& edges);

// The output mesh: one vertex per chart vertex, texcoords over its chart's page (u right, v
// down), the pages' charts one after the other: page k's triangles begin at
// (*page_first_triangle)[k].
Mesh TexturedChartsMesh(const Mesh& mesh, const AtlasLayout& layout, std::vector<size_t>* page_first_triangle);

}  // namespace reconar
