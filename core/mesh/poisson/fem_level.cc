#include "core/mesh/poisson/fem_level.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <optional>

namespace reconar::poisson {
namespace {

// 1D integrals of hat functions on a grid of unit spacing, for node c and neighbour c+o
// (index o+1), with hats truncated at the ends 0 and `last`:
//   mass m = integral phi_{c+o} phi_c, stiffness k = integral phi_{c+o}' phi_c',
//   mixed d = integral phi_{c+o} phi_c'.
struct AxisFactors {
  float m[3];
  float k[3];
  float d[3];
};

AxisFactors FactorsAt(int c, int last) {
  const float left = c > 0 ? 1.0f : 0.0f;
  const float right = c < last ? 1.0f : 0.0f;
  AxisFactors f;
  f.m[0] = left / 6.0f;
  f.m[1] = (left + right) / 3.0f;
  f.m[2] = right / 6.0f;
  f.k[0] = -left;
  f.k[1] = left + right;
  f.k[2] = -right;
  f.d[0] = 0.5f * left;
  f.d[1] = 0.5f * (left - right);
  f.d[2] = -0.5f * right;
  return f;
}

// Dimensionless stiffness stencil weight of node with factors (fx, fy, fz) at offset (ox, oy, oz).
inline float StiffnessWeight(const AxisFactors& fx, const AxisFactors& fy, const AxisFactors& fz, int ox, int oy,
                             int oz) {
  return fx.k[ox] * fy.m[oy] * fz.m[oz] + fx.m[ox] * fy.k[oy] * fz.m[oz] + fx.m[ox] * fy.m[oy] * fz.k[oz];
}

// Second-order factors: the quadratic B-spline centred on cell 0 (unit cells) restricted to
// cell s (s = -1, 0, 1) in the cell's coordinate t in [0, 1], and its derivative.
double QuadraticPiece(int s, double t) {
  if (s < 0) return 0.5 * t * t;
  if (s > 0) return 0.5 * (1.0 - t) * (1.0 - t);
  return 0.75 - (t - 0.5) * (t - 0.5);
}
double QuadraticPieceDerivative(int s, double t) {
  if (s < 0) return t;
  if (s > 0) return t - 1.0;
  return 1.0 - 2.0 * t;
}

// Integrals over one cell of products of pieces a and b (index s + 1): mass a*b, stiffness a'*b',
// mixed a*b'. Three-point Gauss-Legendre is exact for these quartics.
struct PieceIntegrals {
  double m[3][3], k[3][3], d[3][3];
};

const PieceIntegrals& GetPieceIntegrals() {
  static const PieceIntegrals integrals = [] {
    PieceIntegrals p{};
    const double r = std::sqrt(0.6);
    const double nodes[3] = {0.5 * (1.0 - r), 0.5, 0.5 * (1.0 + r)};
    const double weights[3] = {5.0 / 18.0, 8.0 / 18.0, 5.0 / 18.0};
    for (int a = 0; a < 3; ++a) {
      for (int b = 0; b < 3; ++b) {
        for (int q = 0; q < 3; ++q) {
          const double t = nodes[q];
          p.m[a][b] += weights[q] * QuadraticPiece(a - 1, t) * QuadraticPiece(b - 1, t);
          p.k[a][b] += weights[q] * QuadraticPieceDerivative(a - 1, t) * QuadraticPieceDerivative(b - 1, t);
          p.d[a][b] += weights[q] * QuadraticPiece(a - 1, t) * QuadraticPieceDerivative(b - 1, t);
        }
      }
    }
    return p;
  }();
  return integrals;
}

// The pieces of the (reflected) basis function of cell i on cell `cell` of an n-cell axis; returns
// how many (0..2) were written to `pieces` (as s + 1).
int PiecesOn(int i, int cell, int n, int pieces[2]) {
  int count = 0;
  if (cell < 0 || cell >= n) return 0;
  if (std::abs(cell - i) <= 1) pieces[count++] = cell - i + 1;
  if (i == 0 && cell == 0) pieces[count++] = 2;              // B_{-1} folded onto cell 0
  if (i == n - 1 && cell == n - 1) pieces[count++] = 0;      // B_n folded onto cell n - 1
  return count;
}

// 1D integrals of the reflected quadratic B-splines of an n-cell axis (unit spacing) for cell c and
// neighbour c + o (index o + 2): m = integral b_{c+o} b_c, k = integral b_{c+o}' b_c',
// d = integral b_{c+o} b_c'.
struct QuadraticAxisFactors {
  float m[5];
  float k[5];
  float d[5];
};

QuadraticAxisFactors QuadraticFactorsAt(int c, int n) {
  const PieceIntegrals& p = GetPieceIntegrals();
  QuadraticAxisFactors f{};
  for (int o = -2; o <= 2; ++o) {
    const int j = c + o;
    if (j < 0 || j >= n) continue;
    double m = 0.0, k = 0.0, d = 0.0;
    for (int cell = c - 1; cell <= c + 1; ++cell) {
      int pc[2], pj[2];
      const int nc = PiecesOn(c, cell, n, pc), nj = PiecesOn(j, cell, n, pj);
      for (int a = 0; a < nj; ++a) {
        for (int b = 0; b < nc; ++b) {
          m += p.m[pj[a]][pc[b]];
          k += p.k[pj[a]][pc[b]];
          d += p.d[pj[a]][pc[b]];
        }
      }
    }
    f.m[o + 2] = static_cast<float>(m);
    f.k[o + 2] = static_cast<float>(k);
    f.d[o + 2] = static_cast<float>(d);
  }
  return f;
}

inline float QuadraticStiffnessWeight(const QuadraticAxisFactors& fx, const QuadraticAxisFactors& fy,
                                      const QuadraticAxisFactors& fz, int ox, int oy, int oz) {
  return fx.k[ox] * fy.m[oy] * fz.m[oz] + fx.m[ox] * fy.k[oy] * fz.m[oz] + fx.m[ox] * fy.m[oy] * fz.k[oz];
}

// Factors per axis position, cached per axis length (interior positions share one entry).
class QuadraticFactorTable {
 public:
  explicit QuadraticFactorTable(int n) : n_(n) {
    for (int c = 0; c < std::min(n, 3); ++c) low_.push_back(QuadraticFactorsAt(c, n));
    for (int c = std::max(3, n - 3); c < n; ++c) high_.push_back(QuadraticFactorsAt(c, n));
    interior_ = QuadraticFactorsAt(n / 2, n);
  }
  const QuadraticAxisFactors& At(int c) const {
    if (c < static_cast<int>(low_.size())) return low_[c];
    if (c >= n_ - static_cast<int>(high_.size())) return high_[c - (n_ - static_cast<int>(high_.size()))];
    return interior_;
  }

 private:
  int n_;
  std::vector<QuadraticAxisFactors> low_, high_;
  QuadraticAxisFactors interior_;
};

struct InteriorStencil {
  std::array<int, 27> tile_offsets;
  std::array<float, 27> weights;
  int count = 0;
};

const InteriorStencil& GetInteriorStencil() {
  static const InteriorStencil stencil = [] {
    InteriorStencil s;
    const AxisFactors f = FactorsAt(1, 2);
    for (int oz = 0; oz < 3; ++oz) {
      for (int oy = 0; oy < 3; ++oy) {
        for (int ox = 0; ox < 3; ++ox) {
          const float w = StiffnessWeight(f, f, f, ox, oy, oz);
          if (std::abs(w) < 1e-7f) continue;  // face neighbours cancel exactly
          s.tile_offsets[s.count] = TileIndex(ox, oy, oz) - TileIndex(1, 1, 1);
          s.weights[s.count] = w;
          ++s.count;
        }
      }
    }
    return s;
  }();
  return stencil;
}

bool BlockTouchesBoundary(const BlockGrid& grid, int32_t block) {
  const Eigen::Vector3i lo = grid.block_coords(block) * kBlockSize;
  const int last = grid.nodes_per_axis() - 1;
  return lo.minCoeff() <= 0 || lo.maxCoeff() + kBlockSize - 1 >= last;
}

// Sets out = K in on the active nodes of one block (K: the stiffness part of A).
void ApplyStiffnessToBlock(const FemLevel& level, int32_t block, const float* in, float* out) {
  const BlockGrid& grid = level.grid;
  const float h = 1.0f / static_cast<float>(grid.cells_per_axis());
  const int last = grid.nodes_per_axis() - 1;
  const InteriorStencil& stencil = GetInteriorStencil();
  alignas(64) float tile[kTileNodes];
  grid.GatherTile(block, in, 0.0f, tile);
  const uint8_t* active = level.active.data() + static_cast<size_t>(block) * kBlockNodes;
  float* result = out + static_cast<size_t>(block) * kBlockNodes;
  const bool boundary = BlockTouchesBoundary(grid, block);
  for (int lz = 0; lz < kBlockSize; ++lz) {
    for (int ly = 0; ly < kBlockSize; ++ly) {
      const int centre = TileIndex(1, ly + 1, lz + 1);
      float acc[kBlockSize] = {};
      for (int k = 0; k < stencil.count; ++k) {
        const float w = stencil.weights[k];
        const float* src = tile + centre + stencil.tile_offsets[k];
        for (int lx = 0; lx < kBlockSize; ++lx) acc[lx] += w * src[lx];
      }
      const int row = BlockGrid::LocalIndex(0, ly, lz);
      for (int lx = 0; lx < kBlockSize; ++lx) {
        if (!active[row + lx]) continue;
        result[row + lx] = h * acc[lx];
      }
      if (!boundary) continue;
      const Eigen::Vector3i base = grid.NodeCoords(block, row);
      const bool yz_boundary = base.y() == 0 || base.y() == last || base.z() == 0 || base.z() == last;
      for (int lx = 0; lx < kBlockSize; ++lx) {
        const int x = base.x() + lx;
        if (!active[row + lx] || !(yz_boundary || x == 0 || x == last)) continue;
        const AxisFactors fx = FactorsAt(x, last), fy = FactorsAt(base.y(), last), fz = FactorsAt(base.z(), last);
        float sum = 0.0f;
        for (int oz = 0; oz < 3; ++oz) {
          for (int oy = 0; oy < 3; ++oy) {
            for (int ox = 0; ox < 3; ++ox) {
              const float w = StiffnessWeight(fx, fy, fz, ox, oy, oz);
              if (w != 0.0f) sum += w * tile[TileIndex(lx + ox, ly + oy, lz + oz)];
            }
          }
        }
        result[row + lx] = h * sum;
      }
    }
  }
}

// Separable 5-tap passes over a wide tile (kWideTileSize^3, x fastest) for the 8 output
// positions of a block along one axis; factors[i] holds the taps of output i.
constexpr int kW = kWideTileSize;
constexpr int kB = kBlockSize;

// out[z][y][x] (kW x kW x kB) = sum_o taps(x)[o] in[z][y][x + o].
void PassX(const float* in, const float* const taps[kB], float* out) {
  for (int zy = 0; zy < kW * kW; ++zy) {
    const float* row = in + zy * kW;
    float* o = out + zy * kB;
    for (int x = 0; x < kB; ++x) {
      const float* t = taps[x];
      o[x] = t[0] * row[x] + t[1] * row[x + 1] + t[2] * row[x + 2] + t[3] * row[x + 3] + t[4] * row[x + 4];
    }
  }
}

// out[z][y][x] (kW x kB x kB) = sum_o taps(y)[o] in[z][y + o][x], in: kW x kW x kB.
void PassY(const float* in, const float* const taps[kB], float* out) {
  for (int z = 0; z < kW; ++z) {
    for (int y = 0; y < kB; ++y) {
      const float* t = taps[y];
      const float* r = in + (z * kW + y) * kB;
      float* o = out + (z * kB + y) * kB;
      for (int x = 0; x < kB; ++x) {
        o[x] = t[0] * r[x] + t[1] * r[x + kB] + t[2] * r[x + 2 * kB] + t[3] * r[x + 3 * kB] + t[4] * r[x + 4 * kB];
      }
    }
  }
}

// out[z][y][x] (kB^3) += sum_o taps(z)[o] in[z + o][y][x], in: kW x kB x kB.
void PassZAdd(const float* in, const float* const taps[kB], float* out) {
  constexpr int kPlane = kB * kB;
  for (int z = 0; z < kB; ++z) {
    const float* t = taps[z];
    const float* r = in + z * kPlane;
    float* o = out + z * kPlane;
    for (int i = 0; i < kPlane; ++i) {
      o[i] += t[0] * r[i] + t[1] * r[i + kPlane] + t[2] * r[i + 2 * kPlane] + t[3] * r[i + 3 * kPlane] +
              t[4] * r[i + 4 * kPlane];
    }
  }
}

// The 1D factors of the block's 8 positions along each axis; positions outside the grid get zeros.
struct BlockTaps {
  const float* m[3][kB];
  const float* k[3][kB];
  const float* d[3][kB];
};

BlockTaps TapsOfBlock(const BlockGrid& grid, const QuadraticFactorTable& factors, int32_t block) {
  static const QuadraticAxisFactors zero{};
  BlockTaps taps;
  const Eigen::Vector3i lo = grid.block_coords(block) * kBlockSize;
  for (int a = 0; a < 3; ++a) {
    for (int i = 0; i < kB; ++i) {
      const int c = lo[a] + i;
      const QuadraticAxisFactors& f = c < grid.cells_per_axis() ? factors.At(c) : zero;
      taps.m[a][i] = f.m;
      taps.k[a][i] = f.k;
      taps.d[a][i] = f.d;
    }
  }
  return taps;
}

// Degree 2: out = K in on the active cells of one block, K = Kx My Mz + Mx Ky Mz + Mx My Kz
// applied as 1D passes (7 passes of 5 taps instead of a 125-point stencil).
void ApplyQuadraticStiffnessToBlock(const FemLevel& level, const QuadraticFactorTable& factors, int32_t block,
                                    const float* in, float* out) {
  const BlockGrid& grid = level.grid;
  const float h = 1.0f / static_cast<float>(grid.cells_per_axis());
  const BlockTaps taps = TapsOfBlock(grid, factors, block);
  alignas(64) float tile[kWideTileNodes];
  grid.GatherWideTile(block, in, 0.0f, tile);
  alignas(64) float xk[kW * kW * kB], xm[kW * kW * kB];
  PassX(tile, taps.k[0], xk);
  PassX(tile, taps.m[0], xm);
  alignas(64) float y1[kW * kB * kB], y2[kW * kB * kB], y3[kW * kB * kB];
  PassY(xk, taps.m[1], y1);
  PassY(xm, taps.k[1], y2);
  PassY(xm, taps.m[1], y3);
  for (int i = 0; i < kW * kB * kB; ++i) y1[i] += y2[i];
  alignas(64) float result[kBlockNodes] = {};
  PassZAdd(y1, taps.m[2], result);
  PassZAdd(y3, taps.k[2], result);
  const uint8_t* active = level.active.data() + static_cast<size_t>(block) * kBlockNodes;
  float* target = out + static_cast<size_t>(block) * kBlockNodes;
  for (int i = 0; i < kBlockNodes; ++i) {
    if (active[i]) target[i] = h * result[i];
  }
}

// Work items for the pool: this many blocks, or points, per item.
constexpr size_t kBlocksPerChunk = 16;
constexpr size_t kPointsPerChunk = 4096;

size_t ChunkCount(size_t items, size_t per_chunk) { return (items + per_chunk - 1) / per_chunk; }

// Calls fn(chunk) for chunk in [0, chunks) on the pool, or inline without one.
template <typename Fn>
void ForEachChunk(ThreadPool* pool, size_t chunks, Fn&& fn) {
  if (pool == nullptr || pool->num_threads() == 1 || chunks <= 1) {
    for (size_t c = 0; c < chunks; ++c) fn(c);
    return;
  }
  pool->ParallelFor(0, chunks, [&](size_t c, int) { fn(c); });
}

}  // namespace

void IndexScreeningPoints(FemLevel* level) {
  std::vector<int32_t> active_position(level->grid.num_blocks(), -1);
  for (size_t b = 0; b < level->active_blocks.size(); ++b) {
    active_position[level->active_blocks[b]] = static_cast<int32_t>(b);
  }
  level->screening_offsets.assign(level->active_blocks.size() + 1, 0);
  auto each_active_corner = [&](auto&& f) {
    for (size_t p = 0; p < level->points.size(); ++p) {
      for (int c = 0; c < level->support; ++c) {
        const int32_t node = level->points[p].nodes[c];
        if (node < 0 || !level->active[node]) continue;
        f(static_cast<size_t>(active_position[node / kBlockNodes]), static_cast<uint32_t>(p * kMaxSupport + c));
      }
    }
  };
  each_active_corner([&](size_t b, uint32_t) { ++level->screening_offsets[b + 1]; });
  for (size_t b = 0; b < level->active_blocks.size(); ++b) {
    level->screening_offsets[b + 1] += level->screening_offsets[b];
  }
  level->screening_entries.resize(level->screening_offsets.back());
  std::vector<uint32_t> fill(level->screening_offsets.begin(), level->screening_offsets.end() - 1);
  each_active_corner([&](size_t b, uint32_t entry) { level->screening_entries[fill[b]++] = entry; });
}

void ApplyScreenedPoisson(const FemLevel& level, double lambda, const float* in, float* out, ThreadPool* pool,
                          std::vector<float>* point_values) {
  const bool screened = lambda != 0.0 && !level.points.empty();
  if (screened) {
    point_values->resize(level.points.size());
    const float weight = static_cast<float>(lambda);
    ForEachChunk(pool, ChunkCount(level.points.size(), kPointsPerChunk), [&](size_t chunk) {
      const size_t end = std::min(level.points.size(), (chunk + 1) * kPointsPerChunk);
      for (size_t p = chunk * kPointsPerChunk; p < end; ++p) {
        const ScreeningPoint& point = level.points[p];
        float value = 0.0f;
        for (int c = 0; c < level.support; ++c) {
          if (point.nodes[c] >= 0) value += point.weights[c] * in[point.nodes[c]];
        }
        (*point_values)[p] = value * (weight * point.area);
      }
    });
  }
  const size_t blocks = level.active_blocks.size();
  std::optional<QuadraticFactorTable> factors;
  if (level.degree == 2) factors.emplace(level.grid.cells_per_axis());
  ForEachChunk(pool, ChunkCount(blocks, kBlocksPerChunk), [&](size_t chunk) {
    const size_t end = std::min(blocks, (chunk + 1) * kBlocksPerChunk);
    for (size_t b = chunk * kBlocksPerChunk; b < end; ++b) {
      if (level.degree == 2) {
        ApplyQuadraticStiffnessToBlock(level, *factors, level.active_blocks[b], in, out);
      } else {
        ApplyStiffnessToBlock(level, level.active_blocks[b], in, out);
      }
      if (!screened) continue;
      for (uint32_t e = level.screening_offsets[b]; e < level.screening_offsets[b + 1]; ++e) {
        const uint32_t entry = level.screening_entries[e];
        const uint32_t p = entry / kMaxSupport, c = entry % kMaxSupport;
        out[level.points[p].nodes[c]] += (*point_values)[p] * level.points[p].weights[c];
      }
    }
  });
}

std::vector<float> ScreenedPoissonDiagonal(const FemLevel& level, double lambda) {
  const BlockGrid& grid = level.grid;
  const float h = 1.0f / static_cast<float>(grid.cells_per_axis());
  const int last = grid.nodes_per_axis() - 1;
  std::vector<float> diagonal(grid.num_node_slots(), 0.0f);
  const QuadraticFactorTable quadratic(grid.cells_per_axis());
  for (const int32_t block : level.active_blocks) {
    for (int local = 0; local < kBlockNodes; ++local) {
      const size_t index = static_cast<size_t>(block) * kBlockNodes + local;
      if (!level.active[index]) continue;
      const Eigen::Vector3i node = grid.NodeCoords(block, local);
      diagonal[index] = h * (level.degree == 2 ? QuadraticStiffnessWeight(quadratic.At(node.x()), quadratic.At(node.y()),
                                                                          quadratic.At(node.z()), 2, 2, 2)
                                               : StiffnessWeight(FactorsAt(node.x(), last), FactorsAt(node.y(), last),
                                                                 FactorsAt(node.z(), last), 1, 1, 1));
    }
  }
  // Folded indices can repeat an unknown within one point: its diagonal term is the square of
  // the summed weight, so sum per point first.
  for (const ScreeningPoint& point : level.points) {
    for (int c = 0; c < level.support; ++c) {
      if (point.nodes[c] < 0) continue;
      bool seen = false;
      for (int e = 0; e < c; ++e) seen |= point.nodes[e] == point.nodes[c];
      if (seen) continue;
      float weight = point.weights[c];
      for (int e = c + 1; e < level.support; ++e) {
        if (point.nodes[e] == point.nodes[c]) weight += point.weights[e];
      }
      if (level.active[point.nodes[c]]) {
        diagonal[point.nodes[c]] += static_cast<float>(lambda) * point.area * weight * weight;
      }
    }
  }
  return diagonal;
}

namespace {

void ComputeQuadraticDivergenceRhs(const BlockGrid& grid, const std::vector<float>& area_normal_x,
                                   const std::vector<float>& area_normal_y, const std::vector<float>& area_normal_z,
                                   std::vector<float>* rhs) {
  // b = (Dx My Mz) Vx + (Mx Dy Mz) Vy + (Mx My Dz) Vz, as 1D passes.
  const float inv_h = static_cast<float>(grid.cells_per_axis());
  const QuadraticFactorTable factors(grid.cells_per_axis());
  rhs->assign(grid.num_node_slots(), 0.0f);
  std::vector<float> scratch(3 * kWideTileNodes + 3 * kW * kW * kB + 3 * kW * kB * kB + kBlockNodes);
  float* tile_x = scratch.data();
  float* tile_y = tile_x + kWideTileNodes;
  float* tile_z = tile_y + kWideTileNodes;
  float* x_dx = tile_z + kWideTileNodes;
  float* x_my = x_dx + kW * kW * kB;
  float* x_mz = x_my + kW * kW * kB;
  float* y_a = x_mz + kW * kW * kB;
  float* y_b = y_a + kW * kB * kB;
  float* y_c = y_b + kW * kB * kB;
  float* result = y_c + kW * kB * kB;
  for (int32_t block = 0; block < static_cast<int32_t>(grid.num_blocks()); ++block) {
    const BlockTaps taps = TapsOfBlock(grid, factors, block);
    grid.GatherWideTile(block, area_normal_x.data(), 0.0f, tile_x);
    grid.GatherWideTile(block, area_normal_y.data(), 0.0f, tile_y);
    grid.GatherWideTile(block, area_normal_z.data(), 0.0f, tile_z);
    PassX(tile_x, taps.d[0], x_dx);
    PassX(tile_y, taps.m[0], x_my);
    PassX(tile_z, taps.m[0], x_mz);
    PassY(x_dx, taps.m[1], y_a);
    PassY(x_my, taps.d[1], y_b);
    PassY(x_mz, taps.m[1], y_c);
    for (int i = 0; i < kW * kB * kB; ++i) y_a[i] += y_b[i];
    std::fill(result, result + kBlockNodes, 0.0f);
    PassZAdd(y_a, taps.m[2], result);
    PassZAdd(y_c, taps.d[2], result);
    float* target = rhs->data() + static_cast<size_t>(block) * kBlockNodes;
    for (int i = 0; i < kBlockNodes; ++i) target[i] = inv_h * result[i];
  }
}

// Degree 2: fine cell 2I gets 3/4 of coarse I and 1/4 of I - 1, fine 2I + 1 3/4 of I and 1/4 of
// I + 1 (per axis; coarse indices outside the grid fold onto their mirror, the boundary cell).
void QuadraticRestrictAdd(const BlockGrid& fine_grid, const std::vector<float>& fine, const BlockGrid& coarse_grid,
                          std::vector<float>* coarse) {
  const int coarse_n = coarse_grid.cells_per_axis();
  for (int32_t block = 0; block < static_cast<int32_t>(fine_grid.num_blocks()); ++block) {
    for (int local = 0; local < kBlockNodes; ++local) {
      const float value = fine[static_cast<size_t>(block) * kBlockNodes + local];
      if (value == 0.0f) continue;
      const Eigen::Vector3i cell = fine_grid.NodeCoords(block, local);
      if (!IsUnknown(fine_grid, 2, cell)) continue;
      int parent[3][2];
      for (int a = 0; a < 3; ++a) QuadraticParents(cell[a], coarse_n, parent[a]);
      for (int k = 0; k < 8; ++k) {
        const int sx = k & 1, sy = (k >> 1) & 1, sz = (k >> 2) & 1;
        const float w = kQuadraticChildWeights[sx] * kQuadraticChildWeights[sy] * kQuadraticChildWeights[sz];
        const int64_t index = coarse_grid.NodeIndex(parent[0][sx], parent[1][sy], parent[2][sz]);
        if (index >= 0) (*coarse)[index] += w * value;
      }
    }
  }
}

}  // namespace

int BasisAt(int degree, int depth, const Eigen::Vector3f& p, Eigen::Vector3i indices[kMaxSupport],
            float weights[kMaxSupport], int derivative_axis) {
  const int cells = 1 << depth;
  const Eigen::Vector3f q = p * static_cast<float>(cells);
  if (degree == 1) {
    int base[3];
    float w[3][2];
    for (int a = 0; a < 3; ++a) {
      base[a] = std::min(cells - 1, std::max(0, static_cast<int>(std::floor(q[a]))));
      const float t = std::min(1.0f, std::max(0.0f, q[a] - static_cast<float>(base[a])));
      w[a][0] = a == derivative_axis ? -1.0f : 1.0f - t;
      w[a][1] = a == derivative_axis ? 1.0f : t;
    }
    for (int c = 0; c < 8; ++c) {
      const int ix = c & 1, iy = (c >> 1) & 1, iz = (c >> 2) & 1;
      indices[c] = Eigen::Vector3i(base[0] + ix, base[1] + iy, base[2] + iz);
      weights[c] = w[0][ix] * w[1][iy] * w[2][iz];
    }
    return 8;
  }
  int base[3];
  float w[3][3];
  for (int a = 0; a < 3; ++a) {
    base[a] = std::min(cells - 1, std::max(0, static_cast<int>(std::floor(q[a]))));
    const float t = std::min(0.5f, std::max(-0.5f, q[a] - static_cast<float>(base[a]) - 0.5f));
    if (a == derivative_axis) {
      w[a][0] = t - 0.5f;
      w[a][1] = -2.0f * t;
      w[a][2] = t + 0.5f;
    } else {
      w[a][0] = 0.5f * (0.5f - t) * (0.5f - t);
      w[a][1] = 0.75f - t * t;
      w[a][2] = 0.5f * (0.5f + t) * (0.5f + t);
    }
  }
  auto fold = [cells](int i) { return i < 0 ? -1 - i : (i >= cells ? 2 * cells - 1 - i : i); };
  int count = 0;
  for (int k = 0; k < 3; ++k) {
    for (int j = 0; j < 3; ++j) {
      for (int i = 0; i < 3; ++i) {
        indices[count] = Eigen::Vector3i(fold(base[0] + i - 1), fold(base[1] + j - 1), fold(base[2] + k - 1));
        weights[count] = w[0][i] * w[1][j] * w[2][k];
        ++count;
      }
    }
  }
  return count;
}

void ComputeDivergenceRhs(int degree, const BlockGrid& grid, const std::vector<float>& area_normal_x,
                          const std::vector<float>& area_normal_y, const std::vector<float>& area_normal_z,
                          std::vector<float>* rhs) {
  if (degree == 2) {
    ComputeQuadraticDivergenceRhs(grid, area_normal_x, area_normal_y, area_normal_z, rhs);
    return;
  }
  const float inv_h = static_cast<float>(grid.cells_per_axis());
  const int last = grid.nodes_per_axis() - 1;
  rhs->assign(grid.num_node_slots(), 0.0f);
  alignas(64) float tile_x[kTileNodes];
  alignas(64) float tile_y[kTileNodes];
  alignas(64) float tile_z[kTileNodes];
  for (int32_t block = 0; block < static_cast<int32_t>(grid.num_blocks()); ++block) {
    grid.GatherTile(block, area_normal_x.data(), 0.0f, tile_x);
    grid.GatherTile(block, area_normal_y.data(), 0.0f, tile_y);
    grid.GatherTile(block, area_normal_z.data(), 0.0f, tile_z);
    for (int local = 0; local < kBlockNodes; ++local) {
      const Eigen::Vector3i node = grid.NodeCoords(block, local);
      if (!grid.IsValidNode(node)) continue;
      const AxisFactors fx = FactorsAt(node.x(), last), fy = FactorsAt(node.y(), last), fz = FactorsAt(node.z(), last);
      const int lx = local & (kBlockSize - 1), ly = (local >> kBlockBits) & (kBlockSize - 1),
                lz = local >> (2 * kBlockBits);
      float sum = 0.0f;
      for (int oz = 0; oz < 3; ++oz) {
        for (int oy = 0; oy < 3; ++oy) {
          for (int ox = 0; ox < 3; ++ox) {
            const int t = TileIndex(lx + ox, ly + oy, lz + oz);
            sum += fx.d[ox] * fy.m[oy] * fz.m[oz] * tile_x[t] + fx.m[ox] * fy.d[oy] * fz.m[oz] * tile_y[t] +
                   fx.m[ox] * fy.m[oy] * fz.d[oz] * tile_z[t];
          }
        }
      }
      (*rhs)[static_cast<size_t>(block) * kBlockNodes + local] = inv_h * sum;
    }
  }
}

void RestrictAdd(int degree, const BlockGrid& fine_grid, const std::vector<float>& fine, const BlockGrid& coarse_grid,
                 std::vector<float>* coarse) {
  if (degree == 2) {
    QuadraticRestrictAdd(fine_grid, fine, coarse_grid, coarse);
    return;
  }
  for (int32_t block = 0; block < static_cast<int32_t>(fine_grid.num_blocks()); ++block) {
    for (int local = 0; local < kBlockNodes; ++local) {
      const float value = fine[static_cast<size_t>(block) * kBlockNodes + local];
      if (value == 0.0f) continue;
      const Eigen::Vector3i node = fine_grid.NodeCoords(block, local);
      if (!fine_grid.IsValidNode(node)) continue;
      int lo[3], hi[3];
      for (int a = 0; a < 3; ++a) {
        lo[a] = node[a] >> 1;
        hi[a] = (node[a] + 1) >> 1;
      }
      for (int z = lo[2]; z <= hi[2]; ++z) {
        for (int y = lo[1]; y <= hi[1]; ++y) {
          for (int x = lo[0]; x <= hi[0]; ++x) {
            const float w = (lo[0] == hi[0] ? 1.0f : 0.5f) * (lo[1] == hi[1] ? 1.0f : 0.5f) *
                            (lo[2] == hi[2] ? 1.0f : 0.5f);
            const int64_t index = coarse_grid.NodeIndex(x, y, z);
            if (index >= 0) (*coarse)[index] += w * value;
          }
        }
      }
    }
  }
}

CgReport SolveLevel(FemLevel* level, double lambda, int max_iterations, double relative_tolerance, ThreadPool* pool) {
  CgReport report;
  IndexScreeningPoints(level);
  const size_t slots = level->grid.num_node_slots();
  const std::vector<float> diagonal = ScreenedPoissonDiagonal(*level, lambda);
  std::vector<float> residual(slots, 0.0f), direction(slots, 0.0f), product(slots, 0.0f), preconditioned(slots, 0.0f);
  std::vector<float> point_values;
  const std::vector<int32_t>& blocks = level->active_blocks;
  const uint8_t* active = level->active.data();
  const size_t chunks = ChunkCount(blocks.size(), kBlocksPerChunk);
  std::vector<std::array<double, 2>> partial(chunks);

  // Calls f(index) for every active node, chunk by chunk on the pool, and returns the sums of the
  // pairs f returns, added in chunk order.
  auto for_active = [&](auto&& f) {
    ForEachChunk(pool, chunks, [&](size_t chunk) {
      std::array<double, 2> sum = {0.0, 0.0};
      const size_t end = std::min(blocks.size(), (chunk + 1) * kBlocksPerChunk);
      for (size_t b = chunk * kBlocksPerChunk; b < end; ++b) {
        const size_t begin = static_cast<size_t>(blocks[b]) * kBlockNodes;
        for (size_t i = begin; i < begin + kBlockNodes; ++i) {
          if (!active[i]) continue;
          const std::array<double, 2> terms = f(i);
          sum[0] += terms[0];
          sum[1] += terms[1];
        }
      }
      partial[chunk] = sum;
    });
    std::array<double, 2> total = {0.0, 0.0};
    for (const auto& p : partial) {
      total[0] += p[0];
      total[1] += p[1];
    }
    return total;
  };

  ApplyScreenedPoisson(*level, lambda, level->solution.data(), product.data(), pool, &point_values);
  std::array<double, 2> sums = for_active([&](size_t i) {
    residual[i] = level->rhs[i] - product[i];
    preconditioned[i] = diagonal[i] > 0.0f ? residual[i] / diagonal[i] : 0.0f;
    direction[i] = preconditioned[i];
    return std::array<double, 2>{static_cast<double>(residual[i]) * preconditioned[i],
                                 static_cast<double>(residual[i]) * residual[i]};
  });
  double rz = sums[0];
  report.initial_residual = std::sqrt(sums[1]);
  report.final_residual = report.initial_residual;
  const double target = relative_tolerance * report.initial_residual;
  float* solution = level->solution.data();
  for (int iteration = 0; iteration < max_iterations && report.final_residual > target; ++iteration) {
    ApplyScreenedPoisson(*level, lambda, direction.data(), product.data(), pool, &point_values);
    const double pq = for_active([&](size_t i) {
      return std::array<double, 2>{static_cast<double>(direction[i]) * product[i], 0.0};
    })[0];
    if (!(pq > 0.0)) break;
    const float alpha = static_cast<float>(rz / pq);
    sums = for_active([&](size_t i) {
      solution[i] += alpha * direction[i];
      residual[i] -= alpha * product[i];
      preconditioned[i] = diagonal[i] > 0.0f ? residual[i] / diagonal[i] : 0.0f;
      return std::array<double, 2>{static_cast<double>(residual[i]) * preconditioned[i],
                                   static_cast<double>(residual[i]) * residual[i]};
    });
    const float beta = static_cast<float>(sums[0] / rz);
    rz = sums[0];
    for_active([&](size_t i) {
      direction[i] = preconditioned[i] + beta * direction[i];
      return std::array<double, 2>{0.0, 0.0};
    });
    report.final_residual = std::sqrt(sums[1]);
    report.iterations = iteration + 1;
  }
  return report;
}

}  // namespace reconar::poisson
