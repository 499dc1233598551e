#include "core/texture/seam_levelling.h"

#include <Eigen/IterativeLinearSolvers>
#include <Eigen/SparseCore>
#include <algorithm>
#include <cmath>
#include <deque>
#include <tuple>

#include "core/base/image_sampling.h"

namespace reconar {
namespace {

constexpr double kConsensusWeight = 0.1;  // per face, against one seam sample's unit weight
constexpr double kHuberColour = 10.0; // RGB levels
constexpr float kMaxVertexMove = 64.0f;

// Colours of mesh points in the photos, sampled once.
class ColourSampler {
 public:
  ColourSampler(const std::vector<PhotoProjector>& projectors, const std::vector<ReducedPhoto>& reduced,
                const std::vector<Eigen::Vector3f>& gains)
      : projectors_(projectors), reduced_(reduced), gains_(gains) {}

  bool Sample(const Eigen::Vector3d& point, int photo, Eigen::Vector3f* colour) const {
    Eigen::Vector2d pixel;
    double depth;
    if (!projectors_[static_cast<size_t>(photo)].Project(point, &pixel, &depth)) return false;
    const ReducedPhoto& image = reduced_[static_cast<size_t>(photo)];
    const Eigen::Vector2d at = image.FromFull(pixel);
    float rgb[3];
    if (!SampleBilinear(image.rgb, at.x(), at.y(), rgb)) return false;
    *colour = Eigen::Vector3f(rgb[0], rgb[1], rgb[2]).cwiseProduct(gains_[static_cast<size_t>(photo)]);
    return true;
  }

 private:
  const std::vector<PhotoProjector>& projectors_;
  const std::vector<ReducedPhoto>& reduced_;
  const std::vector<Eigen::Vector3f>& gains_;
};

struct SeamSample {
  uint32_t vertex;
  int patch_a, patch_b;
  Eigen::Vector3f colour_a, colour_b;
};

std::vector<Eigen::Vector3f> SolvePatchOffsets(size_t num_patches, const std::vector<SeamSample>& samples,
                                               const PatchConsensus& consensus) {
  std::vector<Eigen::Vector3f> offsets(num_patches, Eigen::Vector3f::Zero());
  std::vector<double> weights(samples.size(), 1.0);
  const int n = static_cast<int>(num_patches);
  for (int round = 0; round < 3; ++round) {
    std::vector<Eigen::Triplet<double>> triplets;
    triplets.reserve(4 * samples.size() + num_patches);
    Eigen::MatrixXd rhs = Eigen::MatrixXd::Zero(n, 3);
    for (int p = 0; p < n; ++p) {
      const size_t faces = std::max<size_t>(1, consensus.faces[static_cast<size_t>(p)]);
      const double weight = kConsensusWeight * static_cast<double>(faces);
      triplets.emplace_back(p, p, weight);
      rhs.row(p) += weight * consensus.offset[static_cast<size_t>(p)].cast<double>().transpose();
    }
    for (size_t k = 0; k < samples.size(); ++k) {
      const SeamSample& s = samples[k];
      const double w = weights[k];
      triplets.emplace_back(s.patch_a, s.patch_a, w);
      triplets.emplace_back(s.patch_b, s.patch_b, w);
      triplets.emplace_back(s.patch_a, s.patch_b, -w);
      triplets.emplace_back(s.patch_b, s.patch_a, -w);
      // offset_a - offset_b should be colour_b - colour_a.
      const Eigen::Vector3d target = (s.colour_b - s.colour_a).cast<double>();
      rhs.row(s.patch_a) += w * target.transpose();
      rhs.row(s.patch_b) -= w * target.transpose();
    }
    Eigen::SparseMatrix<double> normal(n, n);
    normal.setFromTriplets(triplets.begin(), triplets.end());
    Eigen::ConjugateGradient<Eigen::SparseMatrix<double>, Eigen::Lower | Eigen::Upper> solver;
    solver.setTolerance(1e-6);
    solver.setMaxIterations(1000);
    solver.compute(normal);
    const Eigen::MatrixXd solution = solver.solve(rhs);
    for (int p = 0; p < n; ++p) offsets[static_cast<size_t>(p)] = solution.row(p).transpose().cast<float>();
    for (size_t k = 0; k < samples.size(); ++k) {
      const SeamSample& s = samples[k];
      const double residual = ((s.colour_a + offsets[static_cast<size_t>(s.patch_a)]) -
                               (s.colour_b + offsets[static_cast<size_t>(s.patch_b)]))
                                  .cast<double>()
                                  .norm();
      weights[k] = residual <= kHuberColour ? 1.0 : kHuberColour / residual;
    }
  }
  return offsets;
}

}  // namespace

Eigen::Vector3f PatchColourCorrection::At(int patch, uint32_t vertex) const {
  Eigen::Vector3f offset = patch_offset[static_cast<size_t>(patch)];
  const auto& moves = vertex_move[static_cast<size_t>(patch)];
  const auto it = moves.find(vertex);
  if (it != moves.end()) offset += it->second;
  return offset;
}

PatchColourCorrection NoCorrection(size_t num_patches) {
  PatchColourCorrection correction;
  correction.patch_offset.assign(num_patches, Eigen::Vector3f::Zero());
  correction.vertex_move.resize(num_patches);
  return correction;
}

std::vector<SeamEdge> FindSeamEdges(const Mesh& mesh, const TexturePatches& patches,
                                    const std::vector<std::array<int, 3>>& neighbours) {
  std::vector<SeamEdge> edges;
  for (size_t f = 0; f < mesh.triangles.size(); ++f) {
    const int patch_f = patches.patch_of_face[f];
    if (patch_f < 0) continue;
    for (int e = 0; e < 3; ++e) {
      const int g = neighbours[f][static_cast<size_t>(e)];
      if (g <= static_cast<int>(f)) continue;
      const int patch_g = patches.patch_of_face[static_cast<size_t>(g)];
      if (patch_g < 0 || patch_g == patch_f) continue;
      SeamEdge edge;
      edge.a = mesh.triangles[f][static_cast<size_t>(e)];
      edge.b = mesh.triangles[f][static_cast<size_t>((e + 1) % 3)];
      edge.face_a = static_cast<int>(f);
      edge.face_b = g;
      edge.patch_a = patch_f;
      edge.patch_b = patch_g;
      edges.push_back(edge);
    }
  }
  return edges;
}

PatchColourCorrection LevelSeams(const Mesh& mesh, const TexturePatches& patches, const std::vector<SeamEdge>& edges,
                                 const std::vector<PhotoProjector>& projectors,
                                 const std::vector<ReducedPhoto>& reduced, const std::vector<Eigen::Vector3f>& gains,
                                 const PatchConsensus& consensus, int blend_rings) {
  const size_t num_patches = patches.photo.size();
  PatchColourCorrection correction = NoCorrection(num_patches);
  const ColourSampler sampler(projectors, reduced, gains);

  // One sample per (vertex, pair of patches), from the first seam edge that has it.
  std::vector<std::tuple<uint32_t, int, int, size_t>> keys;
  for (size_t k = 0; k < edges.size(); ++k) {
    for (const uint32_t v : {edges[k].a, edges[k].b}) {
      keys.emplace_back(v, std::min(edges[k].patch_a, edges[k].patch_b), std::max(edges[k].patch_a, edges[k].patch_b), k);
    }
  }
  std::sort(keys.begin(), keys.end());
  std::vector<SeamSample> samples;
  for (size_t i = 0; i < keys.size(); ++i) {
    const auto& [vertex, low, high, edge_index] = keys[i];
    if (i > 0 && std::get<0>(keys[i - 1]) == vertex && std::get<1>(keys[i - 1]) == low &&
        std::get<2>(keys[i - 1]) == high) {
      continue;
    }
    const SeamEdge& edge = edges[edge_index];
    SeamSample sample{vertex, edge.patch_a, edge.patch_b, {}, {}};
    const Eigen::Vector3d point = mesh.positions[vertex].cast<double>();
    if (sampler.Sample(point, patches.photo[static_cast<size_t>(edge.patch_a)], &sample.colour_a) &&
        sampler.Sample(point, patches.photo[static_cast<size_t>(edge.patch_b)], &sample.colour_b)) {
      samples.push_back(sample);
    }
  }

  {
    correction.patch_offset = SolvePatchOffsets(num_patches, samples, consensus);
    // Local: each seam vertex's patches meet at their mean corrected colour.
    std::unordered_map<uint32_t, std::vector<std::pair<int, Eigen::Vector3f>>> at_vertex;
    for (const SeamSample& s : samples) {
      for (const std::pair<int, Eigen::Vector3f>& side :
           {std::make_pair(s.patch_a, s.colour_a), std::make_pair(s.patch_b, s.colour_b)}) {
        const int patch = side.first;
        auto& entries = at_vertex[s.vertex];
        const bool present = std::any_of(entries.begin(), entries.end(), [&](const auto& e) { return e.first == patch; });
        if (!present) entries.emplace_back(patch, side.second + correction.patch_offset[static_cast<size_t>(patch)]);
      }
    }
    std::vector<std::vector<std::pair<uint32_t, Eigen::Vector3f>>> sources(num_patches);
    std::vector<uint32_t> seam_vertices;
    for (const auto& entry : at_vertex) seam_vertices.push_back(entry.first);
    std::sort(seam_vertices.begin(), seam_vertices.end());
    for (const uint32_t vertex : seam_vertices) {
      const auto& entries = at_vertex[vertex];
      Eigen::Vector3f mean = Eigen::Vector3f::Zero();
      for (const auto& entry : entries) mean += entry.second;
      mean /= static_cast<float>(entries.size());
      for (const auto& [patch, colour] : entries) {
        const Eigen::Vector3f move = (mean - colour).cwiseMax(-kMaxVertexMove).cwiseMin(kMaxVertexMove);
        sources[static_cast<size_t>(patch)].emplace_back(vertex, move);
      }
    }
    // Fade each patch's moves inward, breadth first over its vertices.
    std::unordered_map<uint32_t, std::vector<uint32_t>> adjacency;
    std::unordered_map<uint32_t, int> ring;
    std::unordered_map<uint32_t, Eigen::Vector3f> seed;
    std::deque<uint32_t> queue;
    for (size_t p = 0; p < num_patches; ++p) {
      if (sources[p].empty()) continue;
      adjacency.clear();
      for (const int f : patches.faces[p]) {
        const auto& t = mesh.triangles[static_cast<size_t>(f)];
        for (int e = 0; e < 3; ++e) {
          adjacency[t[static_cast<size_t>(e)]].push_back(t[static_cast<size_t>((e + 1) % 3)]);
          adjacency[t[static_cast<size_t>((e + 1) % 3)]].push_back(t[static_cast<size_t>(e)]);
        }
      }
      auto& moves = correction.vertex_move[p];
      seed.clear();
      ring.clear();
      queue.clear();
      for (const auto& [vertex, move] : sources[p]) {
        seed[vertex] = move;
        ring[vertex] = 0;
        queue.push_back(vertex);
      }
      while (!queue.empty()) {
        const uint32_t vertex = queue.front();
        queue.pop_front();
        const int vertex_ring = ring[vertex];
        moves[vertex] = seed[vertex] * (1.0f - static_cast<float>(vertex_ring) / static_cast<float>(blend_rings + 1));
        if (vertex_ring >= blend_rings) continue;
        for (const uint32_t other : adjacency[vertex]) {
          if (ring.count(other) != 0) continue;
          ring[other] = vertex_ring + 1;
          seed[other] = seed[vertex];
          queue.push_back(other);
        }
      }
    }
  }

  return correction;
}

}  // namespace reconar
