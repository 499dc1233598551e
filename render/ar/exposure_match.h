#pragma once
// The textured model brought to the video's exposure. The texture holds the photos' colours at
// their common exposure (core/texture's exposure gains), while a camera exposes each frame for
// what it frames, so an unmatched model shows as a step in tone at its border. Every frame the
// model is drawn alone, small, unlit (ExposureMatchOptions::sample_width wide), and compared
// with the frame reduced to the same size by box averaging: per channel, the median over the
// pixels the model covers (those not of the background key colour), where neither is clipped
// (below 8 or above 247 of 255), of the frame's value over the model's. Medians, so that a person
// or a hand in front of the model, or a misregistered border, does not pull the gain while it
// covers less than half of the model. The gains are clamped to [min_gain, max_gain] and smoothed
// over time (geometric, weight `smoothing` to the new estimate), as a camera's exposure drifts
// over a few frames, except that an estimate more than jump_ratio from the running gain in some
// channel (a cut, a jump of the auto-exposure, the next photo of a folder) is taken at once; a
// frame whose model is hidden keeps the last gain. This is the colour
// correction the phone AR runtimes give their virtual content (ARCore's light estimation, ARKit's
// ambient intensity), from the model's own texture rather than a neutral grey. The small drawing
// is of a proxy (ExposureProxy): the textured mesh welded, coloured from its texture at the
// vertices and simplified to proxy_max_faces, since at that size a texel more or less changes
// nothing and the full mesh would cost a software renderer a second full vertex pass per frame.
#include <array>
#include <cstdint>
#include <optional>
#include <vector>

#include "core/base/image.h"
#include "core/base/status.h"
#include "core/mesh/mesh.h"

namespace reconar {

struct ExposureMatchOptions {
  int sample_width = 80;  // pixels of the small drawing (its height by the frame's aspect)
  double smoothing = 0.5;
  double jump_ratio = 1.25;  // an estimate this far from the running gain is taken at once
  double min_gain = 0.25, max_gain = 4.0;
  int min_pixels = 64;  // covered, unclipped pixels an estimate needs
  size_t proxy_max_faces = 20000;
};

// The textured mesh as a vertex-coloured mesh for the small drawing: each vertex the texture's
// colour at its texcoord (on its triangles' page) times its own colour, vertices at one position
// (the charts' shared borders) welded with their colours averaged, then simplified to max_faces.
// The mesh must have texcoords and `texture` its pages (ValidateTexturePages).
Result<Mesh> ExposureProxy(const Mesh& textured, const std::vector<TexturePage>& texture, size_t max_faces);

// The frame (RGB, frame_width x frame_height) reduced by box averaging to *reduced's size (RGB).
void BoxReduce(ImageView<const uint8_t> frame_rgb, int frame_width, int frame_height, Image<uint8_t>* reduced);

class ExposureMatcher {
 public:
  explicit ExposureMatcher(const ExposureMatchOptions& options = ExposureMatchOptions()) : options_(options) {}

  // Per channel, the median of frame / model over the pixels where the model is drawn (not
  // `background`) and neither value is clipped; nothing when fewer than min_pixels qualify.
  // `model` and `frame` are RGB of one size. Allocates only while its scratch grows.
  std::optional<std::array<float, 3>> Estimate(const Image<uint8_t>& model, const Image<uint8_t>& frame,
                                               const std::array<uint8_t, 3>& background);
  // Takes a new estimate into the running gain.
  void Update(const std::optional<std::array<float, 3>>& estimate);
  const std::array<float, 3>& gain() const { return gain_; }
  const ExposureMatchOptions& options() const { return options_; }

 private:
  ExposureMatchOptions options_;
  bool has_estimate_ = false;
  std::array<float, 3> gain_ = {1.0f, 1.0f, 1.0f};
  std::array<std::vector<float>, 3> ratios_;  // scratch
};

}  // namespace reconar
