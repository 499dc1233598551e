#include "core/mvs/patchmatch/patchmatch_view.h"

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <utility>

#include "core/base/prng.h"
#include "core/base/thread_pool.h"
#include "core/mvs/patchmatch/warp_sums.h"

namespace reconar {
namespace {

// A warped source window whose weighted grey variance is below this (one grey level squared, in
// [0, 1] units) carries no texture: its NCC is noise. The reference's floor is the options'.
constexpr float kMinTextureVariance = 1.0f / (255.0f * 255.0f);
constexpr int kFarSteps = 5;                   // far neighbours 3, 5, ..., 2 kFarSteps + 1 pixels away
constexpr float kDepthPerturbation = 0.1f;     // relative depth range of a perturbation in sweep 0, ...
constexpr float kNormalPerturbation = 0.5f;    // ... and of a normal's (added vector); both halve each sweep
constexpr int kInitialisationSweep = 1 << 20;  // the random stream of the initial planes
// The fill of texture-poor pixels (PatchMatchOptions::fill_min_support): its agreement tests, and
// a plane found for a pixel.
struct FillThresholds {
  float max_relative_depth;
  float min_normal_cos;
};
struct PlaneFill {
  size_t pixel;
  float depth;
  Eigen::Vector3f normal;
  float cost;
};

// A per-pixel SplitMix64 stream keyed by (view seed, pixel, sweep), so the result does not depend
// on the thread count.
class PixelRandom {
 public:
  PixelRandom(uint64_t seed, size_t pixel, int sweep)
      : generator_(
            SplitMix64(seed ^ (static_cast<uint64_t>(pixel) * 0x9E3779B97F4A7C15ull + static_cast<uint64_t>(sweep)))
                .Next()) {}
  float Uniform() { return static_cast<float>(generator_.Next() >> 40) * 0x1.0p-24f; }  // [0, 1)

 private:
  SplitMix64 generator_;
};

struct SourceGeometry {
  const Image<float>* grey = nullptr;
  const DepthMap* depth = nullptr;  // may be null or empty
  // Plane-induced homography H = A + b m^T / (n . X) (see PatchMatchViewSolver::Cost).
  Eigen::Matrix3f a;
  Eigen::Vector3f b;
  Eigen::Matrix3d source_from_reference_rotation;
  Eigen::Vector3d source_from_reference_translation;
  Eigen::Matrix3d reference_from_source_rotation;
  Eigen::Vector3d reference_from_source_translation;
  double fx = 0.0, fy = 0.0, cx = 0.0, cy = 0.0;
};

// Per-worker scratch, sized once: the reference window of the current pixel and the per-source costs.
struct Scratch {
  std::vector<float> reference;  // centred grey values of the active window samples
  std::vector<float> weights;    // their bilateral weights
  std::vector<float> offset_x;   // their offsets (the samples inside the reference image)
  std::vector<float> offset_y;
  std::vector<std::pair<float, int>> ranked;  // (cost, source) of the scored sources
  int scored = 0;                             // entries of `ranked` filled by the last Cost
  std::vector<std::pair<float, int>> winner;  // `ranked` of the best candidate so far
  std::vector<int> fill_west, fill_east;      // FillTexturePoor's row scans
  int winner_count = 0;
  int count = 0;
  int padded_count = 0;  // count rounded up to kWarpLanes (the padding has weight 0)
  float weight_sum = 0.0f;
  float variance = 0.0f;
  float min_x = 0.0f, max_x = 0.0f, min_y = 0.0f, max_y = 0.0f;  // bounding box of the offsets
};

class PatchMatchViewSolver {
 public:
  PatchMatchViewSolver(const PatchMatchViewInput& input, const PatchMatchOptions& options, ThreadPool* pool,
                       DepthMap* map)
      : input_(input), options_(options), pool_(pool), map_(*map), view_(*input.reference) {
    inv_fx_ = 1.0 / view_.fx;
    inv_fy_ = 1.0 / view_.fy;
    const float min_std = static_cast<float>(options.MinTextureStd() / 255.0);
    min_reference_variance_ = std::max(kMinTextureVariance, min_std * min_std);
    // The samples of the square window within the disc of radius r + step / 2: the corners, whose
    // spatial weights are the smallest (0.06 for r = 5, sigma 3), are left out; with r = 5 and
    // step 2 that leaves 32 of 36 samples, whole SIMD steps of 8 and 4 lanes.
    const int r = options.window_radius, step = options.window_step;
    const double disc = r + 0.5 * step;
    for (int oy = -r; oy <= r; oy += step) {
      for (int ox = -r; ox <= r; ox += step) {
        if (ox * ox + oy * oy > disc * disc) continue;
        offset_x_.push_back(ox);
        offset_y_.push_back(oy);
        spatial_.push_back(
            static_cast<float>(std::exp(-(ox * ox + oy * oy) / (2.0 * options.sigma_spatial * options.sigma_spatial))));
      }
    }
    for (int d = 0; d < 256; ++d) {
      color_[d] = static_cast<float>(std::exp(-(d * d) / (2.0 * options.sigma_color * options.sigma_color)));
    }
    const Eigen::Matrix3d& rr = view_.cam_from_world.rotation;
    const Eigen::Vector3d& tr = view_.cam_from_world.translation;
    Eigen::Matrix3d k_inv_r;
    k_inv_r << inv_fx_, 0.0, -view_.cx * inv_fx_, 0.0, inv_fy_, -view_.cy * inv_fy_, 0.0, 0.0, 1.0;
    for (size_t k = 0; k < input.sources.size(); ++k) {
      const DenseView& s = *input.sources[k];
      SourceGeometry g;
      g.grey = input.source_greys[k];
      g.depth = k < input.source_depths.size() ? input.source_depths[k] : nullptr;
      g.source_from_reference_rotation = s.cam_from_world.rotation * rr.transpose();
      g.source_from_reference_translation = s.cam_from_world.translation - g.source_from_reference_rotation * tr;
      g.reference_from_source_rotation = g.source_from_reference_rotation.transpose();
      g.reference_from_source_translation = -(g.reference_from_source_rotation * g.source_from_reference_translation);
      Eigen::Matrix3d k_s;
      k_s << s.fx, 0.0, s.cx, 0.0, s.fy, s.cy, 0.0, 0.0, 1.0;
      g.a = (k_s * g.source_from_reference_rotation * k_inv_r).cast<float>();
      g.b = (k_s * g.source_from_reference_translation).cast<float>();
      g.fx = s.fx;
      g.fy = s.fy;
      g.cx = s.cx;
      g.cy = s.cy;
      sources_.push_back(g);
    }
    const int num_sources = static_cast<int>(sources_.size());
    top_k_ = std::min(options.cost_top_k, num_sources);
    all_sources_ = num_sources >= 32 ? ~0u : (1u << num_sources) - 1u;
    subset_size_ = options.source_subset == 0 ? num_sources : std::clamp(options.source_subset, top_k_, num_sources);
    scratch_.resize(static_cast<size_t>(pool->num_threads()));
    for (Scratch& s : scratch_) {
      const size_t padded = static_cast<size_t>(PaddedWarpCount(static_cast<int>(offset_x_.size())));
      s.reference.resize(padded);
      s.weights.resize(padded);
      s.offset_x.resize(padded);
      s.offset_y.resize(padded);
      s.ranked.resize(sources_.size());
      s.winner.resize(sources_.size());
    }
  }

  void Initialise() {
    Reset();
    ForRows([&](int y, Scratch* s) {
      for (int x = 0; x < map_.width; ++x) {
        const size_t i = map_.Index(x, y);
        PixelRandom random(input_.seed, i, kInitialisationSweep);
        const float depth = RandomDepth(&random);
        const Eigen::Vector3f normal = RandomNormal(&random, Ray(x, y));
        texture_poor_[i] = !ReferenceWindow(x, y, s);
        Store(i, depth, normal, texture_poor_[i] ? kNoDepthCost : FullCost(i, x, y, depth, normal, false, s));
      }
    });
  }

  // Every pixel starts from the plane of the nearest pixel of `coarse_map` (the same camera at
  // half resolution: x_coarse = (x + 0.5) / 2 - 0.5), intersected with its own ray; a random
  // plane where that has none or it leaves the depth range.
  void InitialiseFromCoarse(const DepthMap& coarse_map, const DenseView& coarse_view) {
    Reset();
    ForRows([&](int y, Scratch* s) {
      const int cy = std::clamp(static_cast<int>(std::lround((y + 0.5) / 2.0 - 0.5)), 0, coarse_map.height - 1);
      for (int x = 0; x < map_.width; ++x) {
        const size_t i = map_.Index(x, y);
        const int cx = std::clamp(static_cast<int>(std::lround((x + 0.5) / 2.0 - 0.5)), 0, coarse_map.width - 1);
        const size_t c = coarse_map.Index(cx, cy);
        const Eigen::Vector3f ray = Ray(x, y);
        Eigen::Vector3f normal = coarse_map.Normal(c);
        float depth = -1.0f;
        if (coarse_map.cost[c] < kNoDepthCost && normal.dot(ray) < 0.0f) {
          const Eigen::Vector3f coarse_ray(static_cast<float>((cx - coarse_view.cx) / coarse_view.fx),
                                           static_cast<float>((cy - coarse_view.cy) / coarse_view.fy), 1.0f);
          depth = coarse_map.depth[c] * normal.dot(coarse_ray) / normal.dot(ray);
        }
        // The coarse pixel's sources serve its plane here too; a random plane is scored on all.
        const uint32_t coarse_mask = c < coarse_map.source_masks.size() ? coarse_map.source_masks[c] : all_sources_;
        if (!(depth >= input_.depth_min && depth <= input_.depth_max)) {
          PixelRandom random(input_.seed, i, kInitialisationSweep);
          depth = RandomDepth(&random);
          normal = RandomNormal(&random, ray);
        } else {
          map_.source_masks[i] = coarse_mask;
        }
        float cost = kNoDepthCost;
        texture_poor_[i] = !ReferenceWindow(x, y, s);
        if (!texture_poor_[i]) {
          cost = map_.source_masks[i] == all_sources_ ? FullCost(i, x, y, depth, normal, false, s)
                                                      : Cost(x, y, depth, normal, false, map_.source_masks[i], s);
        }
        Store(i, depth, normal, cost);
      }
    });
  }

  // Recomputes every pixel's cost for its current plane.
  void Rescore(bool geometric) {
    map_.source_masks.assign(map_.depth.size(), all_sources_);
    texture_poor_.resize(map_.depth.size());
    ForRows([&](int y, Scratch* s) {
      for (int x = 0; x < map_.width; ++x) {
        const size_t i = map_.Index(x, y);
        // A texture-poor pixel keeps its cost: kNoDepthCost, or that of its filled plane.
        texture_poor_[i] = !ReferenceWindow(x, y, s);
        if (!texture_poor_[i]) map_.cost[i] = FullCost(i, x, y, map_.depth[i], map_.Normal(i), geometric, s);
      }
    });
  }

  // The planes of texture-poor pixels from reliable neighbours (PatchMatchOptions::fill_min_support).
  // Only planes matched photometrically serve: the filled ones are written after all are found.
  // The first reliable pixel along each direction comes from scans: rows for east and west, and
  // from the row above (below) for the three directions up (down), kept per pixel as the number
  // of steps (0: none within fill_max_distance); 13 bytes per pixel of one view while it runs.
  void FillTexturePoor() {
    if (options_.fill_min_support <= 0) return;
    const int width = map_.width, height = map_.height;
    const size_t n = map_.depth.size();
    const float max_cost = static_cast<float>(options_.max_cost);
    // Reliable: a pixel with texture whose cost is below max_cost.
    std::vector<uint8_t> reliable(n);
    bool any_texture_poor = false;
    for (size_t i = 0; i < n; ++i) {
      reliable[i] = !texture_poor_[i] && map_.cost[i] < max_cost;
      any_texture_poor |= texture_poor_[i] != 0;
    }
    if (!any_texture_poor) return;
    // steps[6 i + d]: to the first reliable pixel from pixel i, d = 3 (0 up, 1 down) + dx + 1.
    const int max_distance =
        std::clamp(static_cast<int>(options_.fill_max_distance * std::max(width, height)), 1, 65535);
    std::vector<uint16_t> steps(6 * n, 0);
    for (int half = 0; half < 2; ++half) {  // 0: up (rows top to bottom), 1: down (bottom to top)
      const int dy = half == 0 ? -1 : 1;
      for (int k = 0; k < height; ++k) {
        const int y = half == 0 ? k : height - 1 - k, py = y + dy;
        if (py < 0 || py >= height) continue;
        for (int x = 0; x < width; ++x) {
          for (int dx = -1; dx <= 1; ++dx) {
            const int d = 3 * half + dx + 1, px = x + dx;
            if (px < 0 || px >= width) continue;
            const size_t q = map_.Index(px, py);
            uint16_t step = 0;
            if (reliable[q]) {
              step = 1;
            } else if (steps[6 * q + d] != 0 && steps[6 * q + d] < max_distance) {
              step = static_cast<uint16_t>(steps[6 * q + d] + 1);
            }
            steps[6 * map_.Index(x, y) + static_cast<size_t>(d)] = step;
          }
        }
      }
    }
    std::vector<std::vector<PlaneFill>> fills(static_cast<size_t>(height));
    const FillThresholds thresholds{static_cast<float>(options_.fill_max_relative_depth),
                                    static_cast<float>(std::cos(options_.fill_max_normal_deg * M_PI / 180.0))};
    ForRows([&](int y, Scratch* s) {
      // Along the row: the nearest reliable pixel to the west and to the east of each pixel.
      std::vector<int>& west = s->fill_west;
      std::vector<int>& east = s->fill_east;
      west.assign(static_cast<size_t>(width), -1);
      east.assign(static_cast<size_t>(width), -1);
      for (int x = 1, last = -1; x < width; ++x) {
        if (reliable[map_.Index(x - 1, y)]) last = x - 1;
        west[static_cast<size_t>(x)] = last >= 0 && x - last <= max_distance ? last : -1;
      }
      for (int x = width - 2, last = -1; x >= 0; --x) {
        if (reliable[map_.Index(x + 1, y)]) last = x + 1;
        east[static_cast<size_t>(x)] = last >= 0 && last - x <= max_distance ? last : -1;
      }
      for (int x = 0; x < width; ++x) {
        const size_t i = map_.Index(x, y);
        if (!texture_poor_[i]) continue;
        // Directions in a circle, so that d and d + 4 are opposite: E, SE, S, SW, W, NW, N, NE.
        int qx[8], qy[8];
        qx[0] = east[static_cast<size_t>(x)], qy[0] = y;
        qx[4] = west[static_cast<size_t>(x)], qy[4] = y;
        static constexpr int kCircle[6] = {5, 6, 7, 3, 2, 1};  // steps index (up: dx -1, 0, 1; down) -> circle
        for (int d = 0; d < 6; ++d) {
          const int step = steps[6 * i + static_cast<size_t>(d)];
          const int c = kCircle[d];
          qx[c] = step == 0 ? -1 : x + step * (d % 3 - 1);
          qy[c] = y + step * (d < 3 ? -1 : 1);
        }
        FillPixel(x, y, qx, qy, thresholds, &fills[static_cast<size_t>(y)]);
      }
    });
    for (const std::vector<PlaneFill>& row : fills) {
      for (const PlaneFill& f : row) Store(f.pixel, f.depth, f.normal, f.cost);
    }
  }

  // The fill of texture-poor pixel (x, y) from the reliable pixels (qx[d], qy[d]) in the 8
  // directions of the circle (qx[d] < 0: none), appended to `fills` when enough agree.
  void FillPixel(int x, int y, const int qx[8], const int qy[8], const FillThresholds& thresholds,
                 std::vector<PlaneFill>* fills) const {
    const float max_relative_depth = thresholds.max_relative_depth, min_normal_cos = thresholds.min_normal_cos;
    const Eigen::Vector3f ray = Ray(x, y);
    float depth[8], cost[8];
    Eigen::Vector3f normal[8];
    bool found[8] = {};
    for (int d = 0; d < 8; ++d) {
      if (qx[d] < 0) continue;
      const size_t q = map_.Index(qx[d], qy[d]);
      depth[d] = PropagatedDepth(qx[d], qy[d], ray);
      normal[d] = map_.Normal(q);
      cost[d] = map_.cost[q];
      found[d] = depth[d] > 0.0f;
    }
    int best_count = 0, best_mask = 0;
    for (int d = 0; d < 8; ++d) {
      if (!found[d]) continue;
      int mask = 0, count = 0;
      for (int e = 0; e < 8; ++e) {
        if (found[e] && std::abs(depth[e] - depth[d]) <= max_relative_depth * depth[d] &&
            normal[e].dot(normal[d]) >= min_normal_cos) {
          mask |= 1 << e;
          ++count;
        }
      }
      const bool opposite = (mask & (mask >> 4) & 0xF) != 0;  // agreeing planes on both sides
      if (opposite && count > best_count) {
        best_count = count;
        best_mask = mask;
      }
    }
    if (best_count < options_.fill_min_support) return;
    float depth_sum = 0.0f, cost_sum = 0.0f;
    Eigen::Vector3f normal_sum = Eigen::Vector3f::Zero();
    for (int d = 0; d < 8; ++d) {
      if (!(best_mask >> d & 1)) continue;
      depth_sum += depth[d];
      cost_sum += cost[d];
      normal_sum += normal[d];
    }
    const float fill_depth = depth_sum / static_cast<float>(best_count);
    const Eigen::Vector3f fill_normal = normal_sum.normalized();
    if (!(fill_depth >= input_.depth_min && fill_depth <= input_.depth_max) || !(fill_normal.dot(ray) < 0.0f)) return;
    fills->push_back({map_.Index(x, y), fill_depth, fill_normal, cost_sum / static_cast<float>(best_count)});
  }

  // Red pixels ((x + y) even), then black ones: a pixel reads only pixels of the other colour.
  void Sweep(int sweep, bool geometric) {
    for (int colour = 0; colour < 2; ++colour) {
      ForRows([&](int y, Scratch* s) {
        for (int x = (y + colour) & 1; x < map_.width; x += 2) UpdatePixel(x, y, sweep, geometric, s);
      });
    }
  }

 private:
  template <typename Fn>
  void ForRows(const Fn& fn) {
    pool_->ParallelFor(0, static_cast<size_t>(map_.height),
                       [&](size_t y, int worker) { fn(static_cast<int>(y), &scratch_[static_cast<size_t>(worker)]); });
  }

  void Reset() {
    map_.Reset(view_.width(), view_.height());
    texture_poor_.assign(map_.depth.size(), 0);
    map_.source_masks.assign(map_.depth.size(), all_sources_);
  }

  // The cost over all sources, remembering pixel i's best subset_size_ of them for its next sweep.
  float FullCost(size_t i, int x, int y, float depth, const Eigen::Vector3f& normal, bool geometric, Scratch* s) {
    return Cost(x, y, depth, normal, geometric, all_sources_, s, &map_.source_masks[i]);
  }

  Eigen::Vector3f Ray(int x, int y) const {
    return Eigen::Vector3f(static_cast<float>((x - view_.cx) * inv_fx_), static_cast<float>((y - view_.cy) * inv_fy_),
                           1.0f);
  }
  void Store(size_t i, float depth, const Eigen::Vector3f& normal, float cost) {
    map_.depth[i] = depth;
    map_.SetNormal(i, normal);
    map_.cost[i] = cost;
  }

  // Inverse depth uniform in [1 / depth_max, 1 / depth_min]: equal steps in disparity.
  float RandomDepth(PixelRandom* random) const {
    const double inv_min = 1.0 / input_.depth_max, inv_max = 1.0 / input_.depth_min;
    return static_cast<float>(1.0 / (inv_min + (inv_max - inv_min) * random->Uniform()));
  }
  // Uniform on the half sphere facing the camera (n . ray < 0).
  static Eigen::Vector3f RandomNormal(PixelRandom* random, const Eigen::Vector3f& ray) {
    const float z = 2.0f * random->Uniform() - 1.0f;
    const float phi = 2.0f * static_cast<float>(M_PI) * random->Uniform();
    const float r = std::sqrt(std::max(0.0f, 1.0f - z * z));
    const Eigen::Vector3f n(r * std::cos(phi), r * std::sin(phi), z);
    return n.dot(ray) > 0.0f ? Eigen::Vector3f(-n) : n;
  }
  static float PerturbDepth(PixelRandom* random, float depth, float scale) {
    return depth * (1.0f + kDepthPerturbation * scale * (2.0f * random->Uniform() - 1.0f));
  }
  // The normal plus a random vector of the cube [-s, s]^3, s = kNormalPerturbation scale; the
  // normal itself when the result would not face the camera.
  static Eigen::Vector3f PerturbNormal(PixelRandom* random, const Eigen::Vector3f& normal, float scale,
                                       const Eigen::Vector3f& ray) {
    const float s = kNormalPerturbation * scale;
    Eigen::Vector3f n = normal;
    for (int c = 0; c < 3; ++c) n[c] += s * (2.0f * random->Uniform() - 1.0f);
    const float length = n.norm();
    if (!(length > 1e-6f)) return normal;
    n /= length;
    return n.dot(ray) < 0.0f ? n : normal;
  }

  // The window of (x, y): bilateral weights against the centre's grey level, samples outside the
  // image left out. False when it is textureless.
  bool ReferenceWindow(int x, int y, Scratch* s) const {
    const Image<float>& grey = *input_.reference_grey;
    const int centre = view_.gray.row(y)[x];
    const int w = grey.width(), h = grey.height();
    s->count = 0;
    float weight_sum = 0.0f, sum = 0.0f, sum_squares = 0.0f;
    int min_x = 0, max_x = 0, min_y = 0, max_y = 0;
    for (size_t o = 0; o < offset_x_.size(); ++o) {
      const int px = x + offset_x_[o], py = y + offset_y_[o];
      if (px < 0 || py < 0 || px >= w || py >= h) continue;
      const float value = grey.row(py)[px];
      const float weight = spatial_[o] * color_[std::abs(view_.gray.row(py)[px] - centre)];
      const size_t j = static_cast<size_t>(s->count);
      if (j == 0) {
        min_x = max_x = offset_x_[o];
        min_y = max_y = offset_y_[o];
      }
      min_x = std::min(min_x, offset_x_[o]);
      max_x = std::max(max_x, offset_x_[o]);
      min_y = std::min(min_y, offset_y_[o]);
      max_y = std::max(max_y, offset_y_[o]);
      s->offset_x[j] = static_cast<float>(offset_x_[o]);
      s->offset_y[j] = static_cast<float>(offset_y_[o]);
      s->reference[j] = value;
      s->weights[j] = weight;
      ++s->count;
      weight_sum += weight;
      sum += weight * value;
      sum_squares += weight * value * value;
    }
    if (s->count < 4 || !(weight_sum > 0.0f)) return false;
    const float mean = sum / weight_sum;
    s->variance = sum_squares / weight_sum - mean * mean;
    s->weight_sum = weight_sum;
    s->min_x = static_cast<float>(min_x);
    s->max_x = static_cast<float>(max_x);
    s->min_y = static_cast<float>(min_y);
    s->max_y = static_cast<float>(max_y);
    if (!(s->variance >= min_reference_variance_)) return false;
    for (int j = 0; j < s->count; ++j) s->reference[static_cast<size_t>(j)] -= mean;
    // Padding for the kernels: weight 0 at the first sample's offset (inside the checked box).
    s->padded_count = PaddedWarpCount(s->count);
    for (size_t j = static_cast<size_t>(s->count); j < static_cast<size_t>(s->padded_count); ++j) {
      s->offset_x[j] = s->offset_x[0];
      s->offset_y[j] = s->offset_y[0];
      s->reference[j] = 0.0f;
      s->weights[j] = 0.0f;
    }
    return true;
  }

  // 1 - weighted NCC of the reference window (in `s`) and its warp by `h` into the source;
  // kNoDepthCost when the window reaches outside the source image or behind its camera, or the
  // warped window is textureless. The check is made on the corners of the offsets' bounding box:
  // h's third row is affine in the offset, so positive at the corners means positive inside, and
  // then h maps the box to the convex quadrilateral of the corners' images, which holds every
  // sample. The corners keep kBorderMargin pixels from the last column and row, more than the
  // float rounding of any sample, so the bilinear reads stay inside the image.
  float WindowCost(const SourceGeometry& g, const Eigen::Matrix3f& h, int x, int y, const Scratch& s) const {
    constexpr float kBorderMargin = 0.01f;
    const float fx = static_cast<float>(x), fy = static_cast<float>(y);
    const float h0x = h(0, 0) * fx + h(0, 1) * fy + h(0, 2);
    const float h0y = h(1, 0) * fx + h(1, 1) * fy + h(1, 2);
    const float h0z = h(2, 0) * fx + h(2, 1) * fy + h(2, 2);
    const Image<float>& grey = *g.grey;
    const int width = grey.width();
    const float max_u = static_cast<float>(width - 1) - kBorderMargin;
    const float max_v = static_cast<float>(grey.height() - 1) - kBorderMargin;
    for (int corner = 0; corner < 4; ++corner) {
      const float ox = (corner & 1) ? s.max_x : s.min_x, oy = (corner & 2) ? s.max_y : s.min_y;
      const float hz = h0z + h(2, 0) * ox + h(2, 1) * oy;
      if (!(hz > 1e-6f)) return kNoDepthCost;
      // u = hx / hz in [margin, max_u] without dividing (hz > 0); likewise v.
      const float hx = h0x + h(0, 0) * ox + h(0, 1) * oy, hy = h0y + h(1, 0) * ox + h(1, 1) * oy;
      if (!(hx >= kBorderMargin * hz && hy >= kBorderMargin * hz && hx <= max_u * hz && hy <= max_v * hz)) {
        return kNoDepthCost;
      }
    }
    const WarpHomography warp{h0x, h0y, h0z, h(0, 0), h(1, 0), h(2, 0), h(0, 1), h(1, 1), h(2, 1)};
    const WarpWindow window{s.offset_x.data(), s.offset_y.data(), s.weights.data(), s.reference.data(), s.padded_count};
    const WarpSums sums = warp_sums_(warp, window, grey.data(), width);
    const float sum = sums.sum, sum_squares = sums.sum_squares, sum_products = sums.sum_products;
    const float mean = sum / s.weight_sum;
    const float variance = sum_squares / s.weight_sum - mean * mean;
    if (!(variance >= kMinTextureVariance)) return kNoDepthCost;
    // The reference is centred, so sum_products / weight_sum is the weighted covariance.
    const float ncc = sum_products / s.weight_sum / std::sqrt(s.variance * variance);
    return 1.0f - std::clamp(ncc, -1.0f, 1.0f);
  }

  // Forward-backward reprojection error (pixels, capped) of the reference point through the
  // source's depth map: project into the source, take its depth there, back into the reference.
  float GeometricError(const SourceGeometry& g, const Eigen::Vector3d& point, int x, int y) const {
    const double max_error = options_.geometric_max_error_px;
    if (g.depth == nullptr || g.depth->empty()) return static_cast<float>(max_error);
    const Eigen::Vector3d in_source = g.source_from_reference_rotation * point + g.source_from_reference_translation;
    if (!(in_source.z() > 0.0)) return static_cast<float>(max_error);
    const double u = g.fx * in_source.x() / in_source.z() + g.cx, v = g.fy * in_source.y() / in_source.z() + g.cy;
    if (!(u >= -0.5 && v >= -0.5 && u < g.depth->width - 0.5 && v < g.depth->height - 0.5)) {
      return static_cast<float>(max_error);
    }
    const int qx = static_cast<int>(std::lround(u)), qy = static_cast<int>(std::lround(v));
    const size_t q = g.depth->Index(qx, qy);
    const double depth = g.depth->depth[q];
    if (!(depth > 0.0) || !(g.depth->cost[q] < kNoDepthCost)) return static_cast<float>(max_error);
    const Eigen::Vector3d back = g.reference_from_source_rotation *
                                     Eigen::Vector3d(depth * (qx - g.cx) / g.fx, depth * (qy - g.cy) / g.fy, depth) +
                                 g.reference_from_source_translation;
    if (!(back.z() > 0.0)) return static_cast<float>(max_error);
    const double du = view_.fx * back.x() / back.z() + view_.cx - x, dv = view_.fy * back.y() / back.z() + view_.cy - y;
    return static_cast<float>(std::min(std::sqrt(du * du + dv * dv), max_error));
  }

  // The cost of plane (depth, normal) at (x, y): the mean of the best top_k_ costs of the sources
  // in `mask` and of the `known` (cost, source) pairs already in s->ranked; with best_subset, the
  // subset_size_ cheapest of them all are stored there as a mask. For
  // points X on the plane n . X = n . X0 (X0 = depth K^-1 (x, y, 1)), X_s = R X + t = (R + t n^T /
  // (n . X0)) X, so the homography is K_s (R + t n^T / (n . X0)) K_r^-1 = A + b m^T / (n . X0)
  // with A = K_s R K_r^-1, b = K_s t, m = K_r^-T n.
  float Cost(int x, int y, float depth, const Eigen::Vector3f& normal, bool geometric, uint32_t mask, Scratch* s,
             uint32_t* best_subset = nullptr, int known = 0) const {
    const Eigen::Vector3d ray((x - view_.cx) * inv_fx_, (y - view_.cy) * inv_fy_, 1.0);
    const Eigen::Vector3d n = normal.cast<double>();
    const double plane = depth * n.dot(ray);
    if (!(plane < 0.0)) return kNoDepthCost;
    const Eigen::Vector3d m(n.x() * inv_fx_, n.y() * inv_fy_,
                            n.z() - n.x() * view_.cx * inv_fx_ - n.y() * view_.cy * inv_fy_);
    const Eigen::Vector3f m_scaled = (m / plane).cast<float>();
    const Eigen::Vector3d point = depth * ray;
    int scored = known;
    for (size_t k = 0; k < sources_.size(); ++k) {
      if (!(mask >> k & 1u)) continue;
      const SourceGeometry& g = sources_[k];
      const Eigen::Matrix3f h = g.a + g.b * m_scaled.transpose();
      float cost = WindowCost(g, h, x, y, *s);
      if (geometric) cost += static_cast<float>(options_.geometric_weight) * GeometricError(g, point, x, y);
      s->ranked[static_cast<size_t>(scored++)] = {cost, static_cast<int>(k)};
    }
    s->scored = scored;
    const int k_used = std::min(top_k_, scored);
    if (k_used == 0) return kNoDepthCost;
    const auto ranked_end = s->ranked.begin() + scored;
    if (best_subset != nullptr && subset_size_ < scored) {
      std::nth_element(s->ranked.begin(), s->ranked.begin() + (subset_size_ - 1), ranked_end);
      uint32_t subset = 0;
      for (int k = 0; k < subset_size_; ++k) subset |= 1u << s->ranked[static_cast<size_t>(k)].second;
      *best_subset = subset;
      std::partial_sort(s->ranked.begin(), s->ranked.begin() + k_used, s->ranked.begin() + subset_size_);
    } else {
      std::partial_sort(s->ranked.begin(), s->ranked.begin() + k_used, ranked_end);
    }
    float sum = 0.0f;
    for (int k = 0; k < k_used; ++k) sum += s->ranked[static_cast<size_t>(k)].first;
    return sum / static_cast<float>(k_used);
  }

  // The depth at the ray `ray` of the plane stored at pixel q; <= 0 when the ray misses its front.
  float PropagatedDepth(int qx, int qy, const Eigen::Vector3f& ray) const {
    const size_t q = map_.Index(qx, qy);
    const Eigen::Vector3f n = map_.Normal(q);
    const float denominator = n.dot(ray);
    if (!(denominator < 0.0f)) return -1.0f;
    return map_.depth[q] * n.dot(Ray(qx, qy)) / denominator;
  }

  void UpdatePixel(int x, int y, int sweep, bool geometric, Scratch* s) {
    const size_t i = map_.Index(x, y);
    if (texture_poor_[i]) return;  // no plane, or a filled one
    ReferenceWindow(x, y, s);
    const Eigen::Vector3f ray = Ray(x, y);
    float best_depth = map_.depth[i], best_cost = map_.cost[i];
    Eigen::Vector3f best_normal = map_.Normal(i);
    const float depth_min = static_cast<float>(input_.depth_min), depth_max = static_cast<float>(input_.depth_max);
    // Candidates are scored on the sources that served the pixel's current plane best; that plane's
    // cost on them equals its cost on all (top_k_ <= subset_size_), so the comparison is fair.
    const uint32_t mask = map_.source_masks[i];
    bool changed = false;
    auto consider = [&](float depth, const Eigen::Vector3f& normal) {
      if (!(depth >= depth_min && depth <= depth_max)) return;
      const float cost = Cost(x, y, depth, normal, geometric, mask, s);
      if (cost < best_cost) {
        changed = true;
        std::copy(s->ranked.begin(), s->ranked.begin() + s->scored, s->winner.begin());
        s->winner_count = s->scored;
        best_cost = cost;
        best_depth = depth;
        best_normal = normal;
      }
    };
    static constexpr int kDirections[4][2] = {{-1, 0}, {1, 0}, {0, -1}, {0, 1}};
    // In each direction the cheapest of the pixels at odd distances (the other colour), the
    // adjacent one among them or, with options.separate_near_neighbours, tested on its own too.
    const int first_far = options_.separate_near_neighbours ? 3 : 1;
    for (const auto& d : kDirections) {
      if (options_.separate_near_neighbours) {
        const int nx = x + d[0], ny = y + d[1];
        if (nx >= 0 && ny >= 0 && nx < map_.width && ny < map_.height && map_.cost[map_.Index(nx, ny)] < kNoDepthCost) {
          consider(PropagatedDepth(nx, ny, ray), map_.Normal(map_.Index(nx, ny)));
        }
      }
      int far_x = -1, far_y = -1;
      float far_cost = kNoDepthCost;
      for (int k = first_far; k <= 2 * kFarSteps + 1; k += 2) {
        const int fx = x + k * d[0], fy = y + k * d[1];
        if (fx < 0 || fy < 0 || fx >= map_.width || fy >= map_.height) break;
        const float c = map_.cost[map_.Index(fx, fy)];
        if (c < far_cost) {
          far_cost = c;
          far_x = fx;
          far_y = fy;
        }
      }
      if (far_x >= 0) consider(PropagatedDepth(far_x, far_y, ray), map_.Normal(map_.Index(far_x, far_y)));
    }
    // Refinement around the best plane so far: random and perturbed depth and normal.
    PixelRandom random(input_.seed, i, sweep);
    const float scale = std::ldexp(1.0f, -std::min(sweep, 20));
    const float depth = best_depth;
    const Eigen::Vector3f normal = best_normal;
    const float random_depth = RandomDepth(&random);
    const Eigen::Vector3f random_normal = RandomNormal(&random, ray);
    const float perturbed_depth = PerturbDepth(&random, depth, scale);
    const Eigen::Vector3f perturbed_normal = PerturbNormal(&random, normal, scale, ray);
    // The random planes serve the first sweeps; later ones (at a finer level, from its planes) refine.
    if (sweep < options_.iterations) {
      consider(random_depth, normal);
      consider(depth, random_normal);
    }
    consider(perturbed_depth, perturbed_normal);
    consider(perturbed_depth, normal);
    consider(depth, perturbed_normal);
    // The winner on all sources: those of the subset are scored already.
    if (changed && mask != all_sources_) {
      std::copy(s->winner.begin(), s->winner.begin() + s->winner_count, s->ranked.begin());
      best_cost = Cost(x, y, best_depth, best_normal, geometric, all_sources_ & ~mask, s, &map_.source_masks[i],
                       s->winner_count);
    }
    Store(i, best_depth, best_normal, best_cost);
  }

  const PatchMatchViewInput& input_;
  const PatchMatchOptions& options_;
  ThreadPool* pool_;
  DepthMap& map_;
  const DenseView& view_;
  double inv_fx_ = 0.0, inv_fy_ = 0.0;
  float min_reference_variance_ = kMinTextureVariance;
  std::vector<int> offset_x_, offset_y_;
  std::vector<float> spatial_;
  float color_[256];
  std::vector<SourceGeometry> sources_;
  int top_k_ = 1;
  int subset_size_ = 1;
  uint32_t all_sources_ = 0;
  std::vector<Scratch> scratch_;
  std::vector<uint8_t> texture_poor_;  // per pixel: the reference window is below the texture floor
  WarpSumsFn warp_sums_ = ActiveWarpSumsKernel().sums;
};

}  // namespace

void RunPhotometricPatchMatch(const PatchMatchViewInput& input, const PatchMatchOptions& options, ThreadPool* pool,
                              DepthMap* map) {
  PatchMatchViewSolver solver(input, options, pool, map);
  solver.Initialise();
  for (int sweep = 0; sweep < options.iterations; ++sweep) solver.Sweep(sweep, false);
  solver.FillTexturePoor();
}

void RunPatchMatchFromCoarse(const PatchMatchViewInput& input, const DepthMap& coarse_map, const DenseView& coarse_view,
                             const PatchMatchOptions& options, ThreadPool* pool, DepthMap* map) {
  PatchMatchViewSolver solver(input, options, pool, map);
  solver.InitialiseFromCoarse(coarse_map, coarse_view);
  for (int k = 0; k < options.fine_iterations; ++k) solver.Sweep(options.iterations + k, false);
  solver.FillTexturePoor();
}

void RunGeometricPatchMatch(const PatchMatchViewInput& input, const PatchMatchOptions& options, ThreadPool* pool,
                            DepthMap* map) {
  PatchMatchViewSolver solver(input, options, pool, map);
  solver.Rescore(true);
  const int first = options.iterations + (options.coarse_levels > 0 ? options.fine_iterations : 0);
  for (int k = 0; k < options.geometric_iterations; ++k) solver.Sweep(first + k, true);
  solver.Rescore(false);
}

}  // namespace reconar
