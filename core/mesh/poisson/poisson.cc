#include "core/mesh/poisson/poisson.h"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstring>
#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "core/base/progress.h"
#include "core/base/thread_pool.h"
#include "core/mesh/poisson/block_grid.h"
#include "core/mesh/poisson/fem_level.h"
#include "core/mesh/poisson/marching_cubes.h"
#include "core/mesh/poisson/surface_trim.h"

namespace reconar {
namespace {

using poisson::BlockGrid;
using poisson::FemLevel;
using poisson::kBlockNodes;
using poisson::kBlockSize;

constexpr int kCoarsestBandDepth = 5;     // levels up to this depth are complete grids
constexpr int kBandRadius = 2;            // band: nodes within this many cells of a seed cell
constexpr int kCoarseIterations = 400;    // CG on the complete coarsest grid
constexpr double kCoarseTolerance = 1e-6;
constexpr int kBandIterations = 40;       // CG per band level, warm-started by the coarser level
constexpr double kBandTolerance = 1e-3;

double Seconds(std::chrono::steady_clock::time_point since) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - since).count();
}

// Trilinear weights of `p` (node units) over the corners of its cell; returns the cell.
Eigen::Vector3i CellAndWeights(const Eigen::Vector3f& p, int cells, float weights[8]) {
  Eigen::Vector3i cell;
  float t[3];
  for (int a = 0; a < 3; ++a) {
    cell[a] = std::min(cells - 1, std::max(0, static_cast<int>(std::floor(p[a]))));
    t[a] = std::min(1.0f, std::max(0.0f, p[a] - static_cast<float>(cell[a])));
  }
  for (int c = 0; c < 8; ++c) {
    weights[c] = ((c & 1) ? t[0] : 1.0f - t[0]) * ((c & 2) ? t[1] : 1.0f - t[1]) * ((c & 4) ? t[2] : 1.0f - t[2]);
  }
  return cell;
}

// Interpolates per-node `values` of `grid` at unit-cube point `unit`; nullopt when a corner is absent.
std::optional<float> Interpolate(const BlockGrid& grid, const std::vector<float>& values, const Eigen::Vector3f& unit) {
  float weights[8];
  const Eigen::Vector3i cell = CellAndWeights(unit * static_cast<float>(grid.cells_per_axis()),
                                              grid.cells_per_axis(), weights);
  float sum = 0.0f;
  for (int c = 0; c < 8; ++c) {
    const int64_t index = grid.NodeIndex(cell.x() + (c & 1), cell.y() + ((c >> 1) & 1), cell.z() + ((c >> 2) & 1));
    if (index < 0) return std::nullopt;
    sum += weights[c] * values[index];
  }
  return sum;
}

// Adds `value` with trilinear weights to the nodes of p's cell (the blocks must exist).
void Splat(const BlockGrid& grid, const Eigen::Vector3f& unit, float value, std::vector<float>* values) {
  float weights[8];
  const Eigen::Vector3i cell = CellAndWeights(unit * static_cast<float>(grid.cells_per_axis()),
                                              grid.cells_per_axis(), weights);
  for (int c = 0; c < 8; ++c) {
    const int64_t index = grid.NodeIndex(cell.x() + (c & 1), cell.y() + ((c >> 1) & 1), cell.z() + ((c >> 2) & 1));
    (*values)[index] += weights[c] * value;
  }
}

// Adds `value` to the 3^3 nodes nearest to p with second-order B-spline weights (PoissonRecon's
// default normal splat): a smoother vector field than the trilinear splat.
void SplatQuadratic(const BlockGrid& grid, const Eigen::Vector3f& unit, const Eigen::Vector3f& value,
                    std::vector<float>* x, std::vector<float>* y, std::vector<float>* z) {
  const Eigen::Vector3f p = unit * static_cast<float>(grid.cells_per_axis());
  Eigen::Vector3i centre;
  float w[3][3];
  for (int a = 0; a < 3; ++a) {
    centre[a] = static_cast<int>(std::lround(p[a]));
    const float t = p[a] - static_cast<float>(centre[a]);
    w[a][0] = 0.5f * (0.5f - t) * (0.5f - t);
    w[a][1] = 0.75f - t * t;
    w[a][2] = 0.5f * (0.5f + t) * (0.5f + t);
  }
  for (int k = -1; k <= 1; ++k) {
    for (int j = -1; j <= 1; ++j) {
      for (int i = -1; i <= 1; ++i) {
        const int64_t index = grid.NodeIndex(centre.x() + i, centre.y() + j, centre.z() + k);
        if (index < 0) continue;
        const float weight = w[0][i + 1] * w[1][j + 1] * w[2][k + 1];
        (*x)[index] += weight * value.x();
        (*y)[index] += weight * value.y();
        (*z)[index] += weight * value.z();
      }
    }
  }
}

// Adds `value` to the 3^3 cells around p with the weights of their quadratic B-splines (the
// degree-2 basis itself, so V lies in the space of the solve).
void SplatCellCentred(const BlockGrid& grid, const Eigen::Vector3f& unit, const Eigen::Vector3f& value,
                      std::vector<float>* x, std::vector<float>* y, std::vector<float>* z) {
  Eigen::Vector3i indices[poisson::kMaxSupport];
  float weights[poisson::kMaxSupport];
  const int count = poisson::BasisAt(2, grid.depth(), unit, indices, weights);
  for (int k = 0; k < count; ++k) {
    const int64_t index = grid.NodeIndex(indices[k].x(), indices[k].y(), indices[k].z());
    if (index < 0) continue;
    (*x)[index] += weights[k] * value.x();
    (*y)[index] += weights[k] * value.y();
    (*z)[index] += weights[k] * value.z();
  }
}

Eigen::Vector3i CellOf(const Eigen::Vector3f& unit, int depth) {
  const int cells = 1 << depth;
  Eigen::Vector3i cell;
  for (int a = 0; a < 3; ++a) {
    cell[a] = std::min(cells - 1, std::max(0, static_cast<int>(std::floor(unit[a] * static_cast<float>(cells)))));
  }
  return cell;
}

// Sampling density at every depth from 1 to the kernel depth: each sample splatted with trilinear
// weights on the nodes of each depth, so a value is "samples per node" of that depth.
class SampleDensity {
 public:
  SampleDensity(const std::vector<Eigen::Vector3f>& unit, int kernel_depth) {
    for (int d = 1; d <= kernel_depth; ++d) {
      grids_.push_back(std::make_unique<BlockGrid>(d));
      BlockGrid& grid = *grids_.back();
      for (const Eigen::Vector3f& u : unit) {
        const Eigen::Vector3i c = CellOf(u, d);
        grid.AddBlocksCoveringNodes(c, c.array() + 1);
      }
      values_.emplace_back(grid.num_node_slots(), 0.0f);
      for (const Eigen::Vector3f& u : unit) Splat(grid, u, 1.0f, &values_.back());
    }
  }

  int kernel_depth() const { return static_cast<int>(grids_.size()); }

  // Samples per node of `depth` at unit-cube point u (0 where no sample reaches).
  float SamplesPerNode(int depth, const Eigen::Vector3f& u) const {
    return Interpolate(*grids_[depth - 1], values_[depth - 1], u).value_or(0.0f);
  }

  // PoissonRecon's density value (the `value` SurfaceTrimmer reads): the depth at which a node
  // would hold `samples_per_node` samples, kernel_depth + log4(samples per kernel node / spn)
  // where that is at least 1; where it is less, the depth is found between the coarser depths
  // whose wider nodes first hold enough samples, log-interpolated.
  float SampleDepth(const Eigen::Vector3f& u, double samples_per_node) const {
    const float unit = static_cast<float>(samples_per_node);
    int d = kernel_depth();
    float weight = SamplesPerNode(d, u) / unit;
    if (weight >= 1.0f) return static_cast<float>(d) + std::log(weight) / std::log(4.0f);
    float finer = weight;
    while (weight < 1.0f && d > 1) {
      finer = weight;
      weight = SamplesPerNode(--d, u) / unit;
    }
    if (!(weight > 0.0f)) return -1.0f;  // no sample anywhere near
    if (!(weight > finer)) return static_cast<float>(d) + std::log(weight) / std::log(4.0f);
    return static_cast<float>(d) + std::log(weight) / std::log(weight / finer);
  }

 private:
  std::vector<std::unique_ptr<BlockGrid>> grids_;
  std::vector<std::vector<float>> values_;
};

// Samples of one cell merged: area-weighted centroid (unit cube) and total area.
struct CellSample {
  Eigen::Vector3i cell;
  Eigen::Vector3f centroid;
  float area;
};

std::vector<CellSample> MergeByCell(const std::vector<CellSample>& samples, int depth) {
  const uint64_t cells = uint64_t{1} << depth;
  std::vector<std::pair<uint64_t, uint32_t>> keyed(samples.size());
  for (size_t i = 0; i < samples.size(); ++i) {
    const Eigen::Vector3i c = CellOf(samples[i].centroid, depth);
    keyed[i] = {(static_cast<uint64_t>(c.z()) * cells + static_cast<uint64_t>(c.y())) * cells + static_cast<uint64_t>(c.x()),
                static_cast<uint32_t>(i)};
  }
  std::sort(keyed.begin(), keyed.end());
  std::vector<CellSample> merged;
  for (size_t i = 0; i < keyed.size();) {
    size_t j = i;
    Eigen::Vector3d weighted = Eigen::Vector3d::Zero();
    double area = 0.0;
    for (; j < keyed.size() && keyed[j].first == keyed[i].first; ++j) {
      const CellSample& s = samples[keyed[j].second];
      weighted += static_cast<double>(s.area) * s.centroid.cast<double>();
      area += s.area;
    }
    CellSample m;
    m.cell = CellOf(samples[keyed[i].second].centroid, depth);
    m.centroid = area > 0.0 ? (weighted / area).cast<float>() : samples[keyed[i].second].centroid;
    m.area = static_cast<float>(area);
    merged.push_back(m);
    i = j;
  }
  return merged;
}

// Cells of `grid` whose stored corner values straddle `iso`.
std::vector<Eigen::Vector3i> CrossingCells(const BlockGrid& grid, const std::vector<float>& corner_values, float iso) {
  std::vector<Eigen::Vector3i> cells;
  const int last = grid.nodes_per_axis() - 1;
  alignas(64) float tile[poisson::kTileNodes];
  for (int32_t block = 0; block < static_cast<int32_t>(grid.num_blocks()); ++block) {
    grid.GatherTile(block, corner_values.data(), std::numeric_limits<float>::quiet_NaN(), tile);
    for (int local = 0; local < kBlockNodes; ++local) {
      const Eigen::Vector3i node = grid.NodeCoords(block, local);
      if ((node.array() >= last).any()) continue;
      const int lx = local & 7, ly = (local >> 3) & 7, lz = local >> 6;
      bool below = false, above = false, complete = true;
      for (int c = 0; c < 8; ++c) {
        const float v = tile[poisson::TileIndex(lx + 1 + (c & 1), ly + 1 + ((c >> 1) & 1), lz + 1 + ((c >> 2) & 1))];
        if (std::isnan(v)) complete = false;
        (v < iso ? below : above) = true;
      }
      if (complete && below && above) cells.push_back(node);
    }
  }
  return cells;
}

// Stores the band of `level`: unknowns within kBandRadius cells of a seed cell are active (degree
// 1: the nodes of the cells, degree 2: the cells); the ring the stencil reaches beyond them (one
// node, or two cells) is stored as fixed (Dirichlet) values.
void BuildBand(const std::vector<Eigen::Vector3i>& seeds, FemLevel* level) {
  BlockGrid& grid = level->grid;
  const int extra = level->degree == 1 ? 1 : 0;  // a cell's upper corner nodes
  const int ring = level->degree == 1 ? 1 : 2;
  for (const Eigen::Vector3i& c : seeds) {
    grid.AddBlocksCoveringNodes(c.array() - (kBandRadius + ring), c.array() + (kBandRadius + extra + ring));
  }
  level->active.assign(grid.num_node_slots(), 0);
  const int last = poisson::UnknownsPerAxis(grid, level->degree) - 1;
  for (const Eigen::Vector3i& c : seeds) {
    const Eigen::Vector3i lo = (c.array() - kBandRadius).max(0).matrix();
    const Eigen::Vector3i hi = (c.array() + extra + kBandRadius).min(last).matrix();
    for (int z = lo.z(); z <= hi.z(); ++z) {
      for (int y = lo.y(); y <= hi.y(); ++y) {
        for (int x = lo.x(); x <= hi.x();) {
          const int run_end = std::min(hi.x(), (x | (kBlockSize - 1)));
          const int64_t index = grid.NodeIndex(x, y, z);
          std::memset(level->active.data() + index, 1, static_cast<size_t>(run_end - x + 1));
          x = run_end + 1;
        }
      }
    }
  }
}

void ActivateAll(FemLevel* level) {
  BlockGrid& grid = level->grid;
  for (int bz = 0; bz < grid.blocks_per_axis(); ++bz) {
    for (int by = 0; by < grid.blocks_per_axis(); ++by) {
      for (int bx = 0; bx < grid.blocks_per_axis(); ++bx) grid.AddBlock(bx, by, bz);
    }
  }
  level->active.assign(grid.num_node_slots(), 0);
  for (int32_t block = 0; block < static_cast<int32_t>(grid.num_blocks()); ++block) {
    for (int local = 0; local < kBlockNodes; ++local) {
      if (poisson::IsUnknown(grid, level->degree, grid.NodeCoords(block, local))) {
        level->active[static_cast<size_t>(block) * kBlockNodes + local] = 1;
      }
    }
  }
}

void CollectActiveBlocks(FemLevel* level) {
  level->active_blocks.clear();
  for (int32_t block = 0; block < static_cast<int32_t>(level->grid.num_blocks()); ++block) {
    const uint8_t* a = level->active.data() + static_cast<size_t>(block) * kBlockNodes;
    if (std::any_of(a, a + kBlockNodes, [](uint8_t v) { return v != 0; })) level->active_blocks.push_back(block);
  }
}

// chi (or its derivative along derivative_axis, per cell of the level) at a unit-cube point from
// one level; nullopt when a coefficient it needs is not stored.
std::optional<float> EvaluateLevel(const FemLevel& level, const Eigen::Vector3f& unit, int derivative_axis = -1) {
  Eigen::Vector3i indices[poisson::kMaxSupport];
  float weights[poisson::kMaxSupport];
  const int count = poisson::BasisAt(level.degree, level.grid.depth(), unit, indices, weights, derivative_axis);
  float sum = 0.0f;
  for (int k = 0; k < count; ++k) {
    const int64_t index = level.grid.NodeIndex(indices[k].x(), indices[k].y(), indices[k].z());
    if (index < 0) return std::nullopt;
    sum += weights[k] * level.solution[index];
  }
  return sum;
}

// chi at a unit-cube point from the finest level (up to `finest`) that stores the point's support.
float EvaluateSolution(const std::vector<std::unique_ptr<FemLevel>>& levels, size_t finest, const Eigen::Vector3f& unit) {
  for (size_t l = finest + 1; l-- > 0;) {
    if (const std::optional<float> v = EvaluateLevel(*levels[l], unit)) return *v;
  }
  return 0.0f;
}

// Degree 2: the value at every grid node (cell corner) of the level, the mean of the 8 cells
// around it (the quadratic B-splines are 1/2 at the faces of their centre cell); NaN where one
// is not stored.
std::vector<float> CornerValues(const FemLevel& level) {
  const BlockGrid& grid = level.grid;
  const int cells = grid.cells_per_axis();
  std::vector<float> corners(grid.num_node_slots(), std::numeric_limits<float>::quiet_NaN());
  for (int32_t block = 0; block < static_cast<int32_t>(grid.num_blocks()); ++block) {
    for (int local = 0; local < kBlockNodes; ++local) {
      const Eigen::Vector3i node = grid.NodeCoords(block, local);
      if (!grid.IsValidNode(node)) continue;
      float sum = 0.0f;
      bool complete = true;
      for (int k = 0; k < 8 && complete; ++k) {
        int c[3];
        for (int a = 0; a < 3; ++a) c[a] = std::min(cells - 1, std::max(0, node[a] - 1 + ((k >> a) & 1)));
        const int64_t index = grid.NodeIndex(c[0], c[1], c[2]);
        if (index < 0) {
          complete = false;
        } else {
          sum += level.solution[index];
        }
      }
      if (complete) corners[static_cast<size_t>(block) * kBlockNodes + local] = 0.125f * sum;
    }
  }
  return corners;
}

// Degree 2: the iso-crossing on the edge from `node` along `axis` (values v0, v1 at its ends).
// Along a grid edge chi is a C1 piecewise quadratic with its knot at the edge's midpoint (a cell
// centre), so each half is the quadratic through the end value and the midpoint's value and
// slope; the root is taken in the half whose ends straddle `iso`. Falls back to linear
// interpolation where the midpoint's coefficients are not stored.
float QuadraticEdgeCrossing(const FemLevel& level, float iso, const Eigen::Vector3i& node, int axis, float v0, float v1) {
  const float linear = (iso - v0) / (v1 - v0);
  Eigen::Vector3f mid = node.cast<float>();
  mid[axis] += 0.5f;
  mid /= static_cast<float>(level.grid.cells_per_axis());
  const std::optional<float> value = EvaluateLevel(level, mid);
  const std::optional<float> slope = EvaluateLevel(level, mid, axis);
  if (!value || !slope) return linear;
  const float fm = *value - iso, dm = *slope;
  // Half [lo, hi] in s = t - 0.5: f(s) = fm + dm s + a s^2 with f(end) = end value - iso.
  const bool left = (v0 < iso) != (*value < iso);
  const float end = left ? -0.5f : 0.5f;
  const float fe = (left ? v0 : v1) - iso;
  const float a = (fe - fm - dm * end) / (end * end);
  const float lo = std::min(0.0f, end), hi = std::max(0.0f, end);
  float root = std::numeric_limits<float>::quiet_NaN();
  if (std::abs(a) < 1e-12f * (std::abs(dm) + std::abs(fm) + std::abs(fe))) {
    if (dm != 0.0f) root = -fm / dm;
  } else {
    const float discriminant = dm * dm - 4.0f * a * fm;
    if (discriminant >= 0.0f) {
      // Numerically stable pair of roots.
      const float q = -0.5f * (dm + std::copysign(std::sqrt(discriminant), dm));
      const float r1 = q / a;
      const float r2 = q != 0.0f ? fm / q : r1;
      const float slack = 1e-4f;
      if (r1 >= lo - slack && r1 <= hi + slack) {
        root = r1;
      } else if (r2 >= lo - slack && r2 <= hi + slack) {
        root = r2;
      }
    }
  }
  if (std::isnan(root)) return linear;
  return 0.5f + std::min(hi, std::max(lo, root));
}

// Degree 2: initialises every stored cell of the last of `levels` with the prolongation of the
// level above it (the [1,3,3,1]/4 refinement of the quadratic B-splines); cells whose coarse
// parents are not stored take the coarser function's value at their centre.
void ProlongQuadratic(const std::vector<std::unique_ptr<FemLevel>>& levels, FemLevel* fine) {
  const FemLevel& coarse = *levels[levels.size() - 2];
  const BlockGrid& grid = fine->grid;
  const int coarse_n = coarse.grid.cells_per_axis();
  const float inv_cells = 1.0f / static_cast<float>(grid.cells_per_axis());
  for (int32_t block = 0; block < static_cast<int32_t>(grid.num_blocks()); ++block) {
    float* out = fine->solution.data() + static_cast<size_t>(block) * kBlockNodes;
    for (int local = 0; local < kBlockNodes; ++local) {
      const Eigen::Vector3i cell = grid.NodeCoords(block, local);
      if (!poisson::IsUnknown(grid, 2, cell)) {
        out[local] = 0.0f;
        continue;
      }
      int parent[3][2];
      for (int a = 0; a < 3; ++a) poisson::QuadraticParents(cell[a], coarse_n, parent[a]);
      float sum = 0.0f;
      bool complete = true;
      for (int k = 0; k < 8 && complete; ++k) {
        const int sx = k & 1, sy = (k >> 1) & 1, sz = (k >> 2) & 1;
        const int64_t index = coarse.grid.NodeIndex(parent[0][sx], parent[1][sy], parent[2][sz]);
        if (index < 0) {
          complete = false;
        } else {
          sum += poisson::kQuadraticChildWeights[sx] * poisson::kQuadraticChildWeights[sy] *
                 poisson::kQuadraticChildWeights[sz] * coarse.solution[index];
        }
      }
      out[local] = complete ? sum
                            : EvaluateSolution(levels, levels.size() - 2,
                                               (cell.cast<float>().array() + 0.5f).matrix() * inv_cells);
    }
  }
}

// Initialises every stored node of the last of `levels` with the trilinear prolongation of the
// level above it (each fine block reads the 5^3 coarse nodes it spans); nodes whose coarse corners
// are not stored fall back to the finest coarser level that stores them. Degree 2: see above.
void Prolong(const std::vector<std::unique_ptr<FemLevel>>& levels, FemLevel* fine) {
  if (fine->degree == 2) {
    ProlongQuadratic(levels, fine);
    return;
  }
  const FemLevel& coarse = *levels[levels.size() - 2];
  const BlockGrid& grid = fine->grid;
  const float nan = std::numeric_limits<float>::quiet_NaN();
  const float inv_cells = 1.0f / static_cast<float>(grid.cells_per_axis());
  constexpr int kSpan = kBlockSize / 2 + 1;
  for (int32_t block = 0; block < static_cast<int32_t>(grid.num_blocks()); ++block) {
    const Eigen::Vector3i base = grid.block_coords(block) * (kBlockSize / 2);
    float c[kSpan][kSpan][kSpan];
    for (int z = 0; z < kSpan; ++z) {
      for (int y = 0; y < kSpan; ++y) {
        for (int x = 0; x < kSpan; ++x) {
          const int64_t index = coarse.grid.NodeIndex(base.x() + x, base.y() + y, base.z() + z);
          c[z][y][x] = index < 0 ? nan : coarse.solution[index];
        }
      }
    }
    // Separable: x, then y, then z.
    float along_x[kSpan][kSpan][kBlockSize];
    for (int z = 0; z < kSpan; ++z) {
      for (int y = 0; y < kSpan; ++y) {
        for (int x = 0; x < kBlockSize; ++x) {
          along_x[z][y][x] = (x & 1) ? 0.5f * (c[z][y][x >> 1] + c[z][y][(x >> 1) + 1]) : c[z][y][x >> 1];
        }
      }
    }
    float along_y[kSpan][kBlockSize][kBlockSize];
    for (int z = 0; z < kSpan; ++z) {
      for (int y = 0; y < kBlockSize; ++y) {
        for (int x = 0; x < kBlockSize; ++x) {
          along_y[z][y][x] =
              (y & 1) ? 0.5f * (along_x[z][y >> 1][x] + along_x[z][(y >> 1) + 1][x]) : along_x[z][y >> 1][x];
        }
      }
    }
    float* out = fine->solution.data() + static_cast<size_t>(block) * kBlockNodes;
    for (int z = 0; z < kBlockSize; ++z) {
      for (int y = 0; y < kBlockSize; ++y) {
        for (int x = 0; x < kBlockSize; ++x) {
          float v = (z & 1) ? 0.5f * (along_y[z >> 1][y][x] + along_y[(z >> 1) + 1][y][x]) : along_y[z >> 1][y][x];
          const int local = BlockGrid::LocalIndex(x, y, z);
          if (std::isnan(v)) {
            const Eigen::Vector3i node = grid.NodeCoords(block, local);
            v = grid.IsValidNode(node) ? EvaluateSolution(levels, levels.size() - 2, node.cast<float>() * inv_cells)
                                       : 0.0f;
          }
          out[local] = v;
        }
      }
    }
  }
}

Status CheckInput(const Mesh& points) {
  if (points.positions.size() < 3) {
    return InvalidArgument("Poisson reconstruction needs at least 3 oriented points, got " +
                           std::to_string(points.positions.size()));
  }
  if (points.normals.size() != points.positions.size()) {
    return InvalidArgument("Poisson reconstruction needs one normal per point: " + std::to_string(points.normals.size()) +
                           " normals for " + std::to_string(points.positions.size()) + " points");
  }
  for (size_t i = 0; i < points.positions.size(); ++i) {
    if (!points.positions[i].allFinite()) return InvalidArgument("point " + std::to_string(i) + " has a non-finite position");
    if (!points.normals[i].allFinite()) return InvalidArgument("point " + std::to_string(i) + " has a non-finite normal");
  }
  if (!points.colors.empty() && points.colors.size() != points.positions.size()) {
    return InvalidArgument("Poisson reconstruction: " + std::to_string(points.colors.size()) + " colours for " +
                           std::to_string(points.positions.size()) + " points");
  }
  return Status::Ok();
}

}  // namespace

Status PoissonOptions::Check() const {
  if (depth < 2 || depth > poisson::kMaxBlockGridDepth) {
    return InvalidArgument("PoissonOptions.depth must be in [2, " + std::to_string(poisson::kMaxBlockGridDepth) +
                           "], got " + std::to_string(depth));
  }
  if (!(point_weight >= 0.0) || !std::isfinite(point_weight)) return InvalidArgument("PoissonOptions.point_weight must be >= 0");
  if (!(samples_per_node > 0.0) || !std::isfinite(samples_per_node)) return InvalidArgument("PoissonOptions.samples_per_node must be > 0");
  if (!(scale >= 1.0) || !std::isfinite(scale)) return InvalidArgument("PoissonOptions.scale must be >= 1");
  if (!(trim >= 0.0) || !std::isfinite(trim)) return InvalidArgument("PoissonOptions.trim must be >= 0");
  if (num_threads < 1) return InvalidArgument("PoissonOptions.num_threads must be >= 1");
  if (degree != 1 && degree != 2) return InvalidArgument("PoissonOptions.degree must be 1 or 2, got " + std::to_string(degree));
  return Status::Ok();
}

Result<Mesh> ReconstructPoissonSurface(const Mesh& oriented_points, const PoissonOptions& options,
                                       PoissonReport* report) {
  RECONAR_RETURN_IF_ERROR(options.Check());
  RECONAR_RETURN_IF_ERROR(CheckInput(oriented_points));
  PoissonReport local_report;
  PoissonReport& rep = report ? *report : local_report;
  rep = PoissonReport();
  std::unique_ptr<Progress> progress;
  const int depth = options.depth;
  const int degree = options.degree;
  const int coarsest = std::min(depth, kCoarsestBandDepth);
  if (options.show_progress) progress = std::make_unique<Progress>("poisson", static_cast<size_t>(depth - coarsest + 4));
  auto advance = [&] {
    if (progress) progress->Advance();
  };

  // --- Octree phase: unit cube, density, areas, merged samples, right-hand sides. ---
  auto start = std::chrono::steady_clock::now();
  const size_t n = oriented_points.positions.size();
  Eigen::Vector3f lo = oriented_points.positions[0], hi = lo;
  for (const Eigen::Vector3f& p : oriented_points.positions) {
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  const float extent = (hi - lo).maxCoeff();
  if (!(extent > 0.0f)) return InvalidArgument("Poisson reconstruction: all points coincide");
  const float cube_edge = static_cast<float>(options.scale) * extent;
  const Eigen::Vector3f origin = 0.5f * (lo + hi) - Eigen::Vector3f::Constant(0.5f * cube_edge);
  std::vector<Eigen::Vector3f> unit(n);
  for (size_t i = 0; i < n; ++i) unit[i] = (oriented_points.positions[i] - origin) / cube_edge;

  const int kernel_depth = std::max(1, depth - 2);
  const SampleDensity density(unit, kernel_depth);
  const float kernel_h = 1.0f / static_cast<float>(1 << kernel_depth);
  std::vector<CellSample> samples(n);
  for (size_t i = 0; i < n; ++i) {
    const float rho = density.SamplesPerNode(kernel_depth, unit[i]);
    samples[i] = {Eigen::Vector3i::Zero(), unit[i], kernel_h * kernel_h / std::max(rho, 1e-6f)};
  }

  // Merged samples per level, finest first.
  const int num_levels = depth - coarsest + 1;
  std::vector<std::vector<CellSample>> merged(num_levels);
  merged[num_levels - 1] = MergeByCell(samples, depth);
  for (int l = num_levels - 2; l >= 0; --l) merged[l] = MergeByCell(merged[l + 1], coarsest + l);

  // Right-hand side b = integral V . grad phi at the finest depth, restricted to coarser ones.
  std::vector<std::unique_ptr<BlockGrid>> rhs_grids(num_levels);
  std::vector<std::vector<float>> rhs(num_levels);
  for (int l = 0; l < num_levels; ++l) {
    rhs_grids[l] = std::make_unique<BlockGrid>(coarsest + l);
    for (const CellSample& s : merged[l]) rhs_grids[l]->AddBlocksCoveringNodes(s.cell.array() - 3, s.cell.array() + 4);
  }
  {
    const BlockGrid& finest = *rhs_grids[num_levels - 1];
    std::vector<float> vx(finest.num_node_slots(), 0.0f), vy(vx), vz(vx);
    for (size_t i = 0; i < n; ++i) {
      const Eigen::Vector3f& normal = oriented_points.normals[i];
      const float norm = normal.norm();
      if (!(norm > 0.0f)) continue;
      const Eigen::Vector3f weighted = normal * (samples[i].area / norm);
      if (degree == 2) {
        SplatCellCentred(finest, unit[i], weighted, &vx, &vy, &vz);
      } else {
        SplatQuadratic(finest, unit[i], weighted, &vx, &vy, &vz);
      }
    }
    poisson::ComputeDivergenceRhs(degree, finest, vx, vy, vz, &rhs[num_levels - 1]);
  }
  for (int l = num_levels - 2; l >= 0; --l) {
    rhs[l].assign(rhs_grids[l]->num_node_slots(), 0.0f);
    poisson::RestrictAdd(degree, *rhs_grids[l + 1], rhs[l + 1], *rhs_grids[l], &rhs[l]);
  }
  // Colours: area-weighted RGBA sums and weights splatted at the finest depth, summed to coarser ones.
  const bool with_colors = !oriented_points.colors.empty();
  std::vector<std::array<std::vector<float>, 5>> color_sums(with_colors ? num_levels : 0);
  if (with_colors) {
    for (auto& channel : color_sums[num_levels - 1]) channel.assign(rhs_grids[num_levels - 1]->num_node_slots(), 0.0f);
    for (size_t i = 0; i < n; ++i) {
      for (int k = 0; k < 4; ++k) {
        Splat(*rhs_grids[num_levels - 1], unit[i], samples[i].area * oriented_points.colors[i][k],
              &color_sums[num_levels - 1][k]);
      }
      Splat(*rhs_grids[num_levels - 1], unit[i], samples[i].area, &color_sums[num_levels - 1][4]);
    }
    for (int l = num_levels - 2; l >= 0; --l) {
      for (int k = 0; k < 5; ++k) {
        color_sums[l][k].assign(rhs_grids[l]->num_node_slots(), 0.0f);
        poisson::RestrictAdd(1, *rhs_grids[l + 1], color_sums[l + 1][k], *rhs_grids[l], &color_sums[l][k]);
      }
    }
  }
  rep.seconds_octree = Seconds(start);
  advance();

  // --- Cascadic solve, coarse to fine. ---
  start = std::chrono::steady_clock::now();
  const double lambda = options.point_weight * static_cast<double>(1 << depth);
  ThreadPool pool(options.num_threads);
  std::vector<std::unique_ptr<FemLevel>> levels;
  std::vector<Eigen::Vector3i> crossing;
  float iso = 0.0f;
  for (int l = 0; l < num_levels; ++l) {
    const int d = coarsest + l;
    levels.push_back(std::make_unique<FemLevel>(d, degree));
    FemLevel& level = *levels.back();
    if (l == 0) {
      ActivateAll(&level);
    } else {
      std::vector<Eigen::Vector3i> seeds;
      seeds.reserve(merged[l].size() + crossing.size() * 8);
      for (const CellSample& s : merged[l]) seeds.push_back(s.cell);
      for (const Eigen::Vector3i& c : crossing) {
        for (int k = 0; k < 8; ++k) seeds.push_back(2 * c + Eigen::Vector3i(k & 1, (k >> 1) & 1, (k >> 2) & 1));
      }
      BuildBand(seeds, &level);
    }
    CollectActiveBlocks(&level);
    const BlockGrid& grid = level.grid;
    level.solution.assign(grid.num_node_slots(), 0.0f);
    level.rhs.assign(grid.num_node_slots(), 0.0f);
    if (l > 0) Prolong(levels, &level);
    const BlockGrid& rhs_grid = *rhs_grids[l];
    for (int32_t block = 0; block < static_cast<int32_t>(rhs_grid.num_blocks()); ++block) {
      const Eigen::Vector3i& b = rhs_grid.block_coords(block);
      const int32_t target = grid.BlockId(b.x(), b.y(), b.z());
      if (target < 0) continue;
      std::memcpy(level.rhs.data() + static_cast<size_t>(target) * kBlockNodes,
                  rhs[l].data() + static_cast<size_t>(block) * kBlockNodes, kBlockNodes * sizeof(float));
    }
    level.points.resize(merged[l].size());
    for (size_t i = 0; i < merged[l].size(); ++i) {
      poisson::ScreeningPoint& point = level.points[i];
      Eigen::Vector3i indices[poisson::kMaxSupport];
      const int count = poisson::BasisAt(degree, d, merged[l][i].centroid, indices, point.weights);
      for (int k = 0; k < count; ++k) {
        point.nodes[k] = static_cast<int32_t>(grid.NodeIndex(indices[k].x(), indices[k].y(), indices[k].z()));
      }
      point.area = merged[l][i].area;
    }
    const poisson::CgReport cg = l == 0 ? poisson::SolveLevel(&level, lambda, kCoarseIterations, kCoarseTolerance, &pool)
                                        : poisson::SolveLevel(&level, lambda, kBandIterations, kBandTolerance, &pool);
    rep.solver_iterations += cg.iterations;
    rep.octree_nodes += static_cast<int>(grid.num_node_slots());
    rep.unknowns += static_cast<int>(std::count(level.active.begin(), level.active.end(), uint8_t{1}));
    // Iso-value: area-weighted mean of chi at the merged samples.
    double weighted = 0.0, area = 0.0;
    for (const poisson::ScreeningPoint& point : level.points) {
      float v = 0.0f;
      for (int k = 0; k < level.support; ++k) {
        if (point.nodes[k] >= 0) v += point.weights[k] * level.solution[point.nodes[k]];
      }
      weighted += static_cast<double>(point.area) * v;
      area += point.area;
    }
    iso = area > 0.0 ? static_cast<float>(weighted / area) : 0.0f;
    if (l + 1 < num_levels) {
      crossing = degree == 2 ? CrossingCells(grid, CornerValues(level), iso) : CrossingCells(grid, level.solution, iso);
    }
    advance();
  }
  rep.iso_value = iso;
  rep.seconds_solve = Seconds(start);

  // --- Extraction. ---
  start = std::chrono::steady_clock::now();
  const FemLevel& finest = *levels.back();
  poisson::IsoSurface surface =
      degree == 2 ? poisson::ExtractIsoSurface(finest.grid, CornerValues(finest), iso,
                                               [&](const Eigen::Vector3i& node, int axis, float v0, float v1) {
                                                 return QuadraticEdgeCrossing(finest, iso, node, axis, v0, v1);
                                               })
                  : poisson::ExtractIsoSurface(finest.grid, finest.solution, iso);
  rep.cells_skipped = surface.cells_skipped;
  const float node_size = cube_edge / static_cast<float>(finest.grid.cells_per_axis());
  Mesh mesh;
  mesh.positions.resize(surface.positions.size());
  for (size_t i = 0; i < surface.positions.size(); ++i) mesh.positions[i] = origin + surface.positions[i] * node_size;
  mesh.triangles = std::move(surface.triangles);
  if (with_colors) {
    // From the finest depth whose splats reach the vertex with at least a tenth of a sample's area.
    double mean_area = 0.0;
    for (const CellSample& s : samples) mean_area += s.area;
    const float enough = 0.1f * static_cast<float>(mean_area / static_cast<double>(n));
    mesh.colors.resize(mesh.positions.size(), {128, 128, 128, 255});
    for (size_t i = 0; i < mesh.positions.size(); ++i) {
      const Eigen::Vector3f u = surface.positions[i] / static_cast<float>(finest.grid.cells_per_axis());
      for (int l = num_levels - 1; l >= 0; --l) {
        const float w = Interpolate(*rhs_grids[l], color_sums[l][4], u).value_or(0.0f);
        if (!(w >= enough)) continue;
        for (int k = 0; k < 4; ++k) {
          const float c = Interpolate(*rhs_grids[l], color_sums[l][k], u).value_or(0.0f) / w;
          mesh.colors[i][k] = static_cast<uint8_t>(std::lround(std::min(255.0f, std::max(0.0f, c))));
        }
        break;
      }
    }
  }
  rep.seconds_extract = Seconds(start);
  advance();

  // --- Trim. ---
  start = std::chrono::steady_clock::now();
  if (options.trim > 0.0) {
    std::vector<float> value(mesh.positions.size());
    for (size_t i = 0; i < mesh.positions.size(); ++i) {
      const Eigen::Vector3f u = surface.positions[i] / static_cast<float>(finest.grid.cells_per_axis());
      value[i] = density.SampleDepth(u, options.samples_per_node);
    }
    poisson::SurfaceTrimOptions trim;
    trim.trim = static_cast<float>(options.trim);
    poisson::TrimSurface(value, trim, &mesh);
  }
  ComputeVertexNormals(&mesh);
  rep.seconds_trim = Seconds(start);
  advance();
  rep.vertices = mesh.positions.size();
  rep.triangles = mesh.triangles.size();
  if (progress) progress->Finish();
  return mesh;
}

}  // namespace reconar
