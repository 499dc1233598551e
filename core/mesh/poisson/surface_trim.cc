#include "core/mesh/poisson/surface_trim.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <unordered_map>

#include "core/base/union_find.h"

namespace reconar::poisson {
namespace {

// Component id (root vertex) of every triangle of `triangles`, by shared vertices.
std::vector<uint32_t> TriangleComponents(const std::vector<std::array<uint32_t, 3>>& triangles, size_t vertices) {
  UnionFind sets(vertices);
  for (const auto& t : triangles) {
    sets.Union(t[0], t[1]);
    sets.Union(t[0], t[2]);
  }
  std::vector<uint32_t> component(triangles.size());
  for (size_t i = 0; i < triangles.size(); ++i) component[i] = sets.Find(triangles[i][0]);
  return component;
}

double TriangleArea(const Mesh& mesh, const std::array<uint32_t, 3>& t) {
  const Eigen::Vector3d a = mesh.positions[t[0]].cast<double>();
  return 0.5 * (mesh.positions[t[1]].cast<double>() - a).cross(mesh.positions[t[2]].cast<double>() - a).norm();
}

// Triangles of `side` whose component is at least `min_area` (keep_large) or below it (!keep_large).
void KeepComponents(const Mesh& mesh, const std::vector<std::array<uint32_t, 3>>& side, double min_area,
                    bool keep_large, std::vector<std::array<uint32_t, 3>>* out) {
  const std::vector<uint32_t> component = TriangleComponents(side, mesh.positions.size());
  std::unordered_map<uint32_t, double> area;
  for (size_t i = 0; i < side.size(); ++i) area[component[i]] += TriangleArea(mesh, side[i]);
  for (size_t i = 0; i < side.size(); ++i) {
    if ((area[component[i]] >= min_area) == keep_large) out->push_back(side[i]);
  }
}

}  // namespace

void TrimSurface(const std::vector<float>& vertex_values, const SurfaceTrimOptions& options, Mesh* mesh) {
  const bool with_colors = !mesh->colors.empty();
  std::vector<float> values = vertex_values;
  std::unordered_map<uint64_t, uint32_t> cut_vertex;  // edge (low index << 32 | high index) -> new vertex
  auto cut = [&](uint32_t a, uint32_t b) {
    const uint64_t key = (static_cast<uint64_t>(std::min(a, b)) << 32) | std::max(a, b);
    const auto found = cut_vertex.find(key);
    if (found != cut_vertex.end()) return found->second;
    const uint32_t lo = std::min(a, b), hi = std::max(a, b);  // same interpolation from both sides
    float t = (options.trim - values[lo]) / (values[hi] - values[lo]);
    if (!std::isfinite(t)) t = 0.5f;
    t = std::min(1.0f, std::max(0.0f, t));
    const uint32_t v = static_cast<uint32_t>(mesh->positions.size());
    mesh->positions.push_back(mesh->positions[lo] + t * (mesh->positions[hi] - mesh->positions[lo]));
    if (with_colors) {
      std::array<uint8_t, 4> c;
      for (int k = 0; k < 4; ++k) {
        c[k] = static_cast<uint8_t>(std::lround(mesh->colors[lo][k] + t * (mesh->colors[hi][k] - mesh->colors[lo][k])));
      }
      mesh->colors.push_back(c);
    }
    values.push_back(options.trim);
    cut_vertex.emplace(key, v);
    return v;
  };
  std::vector<std::array<uint32_t, 3>> above, below;
  auto add_fan = [](const std::vector<uint32_t>& polygon, std::vector<std::array<uint32_t, 3>>* out) {
    for (size_t k = 1; k + 1 < polygon.size(); ++k) out->push_back({polygon[0], polygon[k], polygon[k + 1]});
  };
  std::vector<uint32_t> up, down;
  for (const auto& t : mesh->triangles) {
    const bool high[3] = {values[t[0]] >= options.trim, values[t[1]] >= options.trim, values[t[2]] >= options.trim};
    if (high[0] == high[1] && high[1] == high[2]) {
      (high[0] ? above : below).push_back(t);
      continue;
    }
    // Walk the triangle's boundary, inserting the cut vertex on every edge that changes side.
    up.clear();
    down.clear();
    for (int k = 0; k < 3; ++k) {
      const uint32_t a = t[k], b = t[(k + 1) % 3];
      (high[k] ? up : down).push_back(a);
      if (high[k] != high[(k + 1) % 3]) {
        const uint32_t v = cut(a, b);
        up.push_back(v);
        down.push_back(v);
      }
    }
    add_fan(up, &above);
    add_fan(down, &below);
  }
  double total = 0.0;
  for (const auto& t : above) total += TriangleArea(*mesh, t);
  for (const auto& t : below) total += TriangleArea(*mesh, t);
  const double island = options.island_area_ratio * total;
  std::vector<std::array<uint32_t, 3>> kept;
  KeepComponents(*mesh, above, island, /*keep_large=*/true, &kept);
  KeepComponents(*mesh, below, island, /*keep_large=*/false, &kept);

  // Drop unused vertices, keeping the order of first use.
  std::vector<int64_t> remap(mesh->positions.size(), -1);
  std::vector<Eigen::Vector3f> positions;
  std::vector<std::array<uint8_t, 4>> colors;
  for (auto& t : kept) {
    for (uint32_t& v : t) {
      if (remap[v] < 0) {
        remap[v] = static_cast<int64_t>(positions.size());
        positions.push_back(mesh->positions[v]);
        if (with_colors) colors.push_back(mesh->colors[v]);
      }
      v = static_cast<uint32_t>(remap[v]);
    }
  }
  mesh->positions = std::move(positions);
  mesh->colors = std::move(colors);
  mesh->normals.clear();
  mesh->triangles = std::move(kept);
}

}  // namespace reconar::poisson
