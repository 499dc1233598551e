#include "core/texture/view_labelling.h"

#include <algorithm>
#include <cmath>

#include "core/base/median.h"

namespace reconar {
namespace {

double DataCost(const FaceCandidateTable& table, size_t face, int photo, float best_quality) {
  for (size_t k = table.begin[face]; k < table.begin[face + 1]; ++k) {
    if (table.candidates[k].photo == photo) return 1.0 - table.candidates[k].quality / best_quality;
  }
  return 1.0;
}

double Energy(const FaceCandidateTable& table, const std::vector<std::array<int, 3>>& neighbours,
              const std::vector<int>& labels, const std::vector<float>& best_quality, double smoothness) {
  double energy = 0.0;
  for (size_t f = 0; f < labels.size(); ++f) {
    if (labels[f] >= 0) energy += DataCost(table, f, labels[f], best_quality[f]);
    for (const int g : neighbours[f]) {
      if (g > static_cast<int>(f) && labels[static_cast<size_t>(g)] != labels[f]) energy += smoothness;
    }
  }
  return energy;
}

}  // namespace

FaceCandidateTable GroupByFace(size_t num_faces, const std::vector<std::vector<FaceCandidate>>& per_photo) {
  FaceCandidateTable table;
  table.begin.assign(num_faces + 1, 0);
  for (const auto& photo : per_photo) {
    for (const FaceCandidate& candidate : photo) ++table.begin[static_cast<size_t>(candidate.face) + 1];
  }
  for (size_t f = 0; f < num_faces; ++f) table.begin[f + 1] += table.begin[f];
  table.candidates.resize(table.begin[num_faces]);
  std::vector<size_t> next(table.begin.begin(), table.begin.end() - 1);
  for (const auto& photo : per_photo) {  // photos in order: each face's candidates in photo order
    for (const FaceCandidate& candidate : photo) table.candidates[next[static_cast<size_t>(candidate.face)]++] = candidate;
  }
  return table;
}

void WeighCandidates(FaceCandidateTable* table) {
  std::vector<float> sharpness;
  for (size_t f = 0; f + 1 < table->begin.size(); ++f) {
    sharpness.clear();
    for (size_t k = table->begin[f]; k < table->begin[f + 1]; ++k) sharpness.push_back(table->candidates[k].sharpness);
    if (sharpness.empty()) continue;
    const float median = MedianInPlace(sharpness.data(), sharpness.size());
    for (size_t k = table->begin[f]; k < table->begin[f + 1]; ++k) {
      FaceCandidate& candidate = table->candidates[k];
      const float ratio = median > 0.0f ? std::min(1.0f, candidate.sharpness / median) : 1.0f;
      const float off_consensus = candidate.colour_distance / kMinColourDistance;
      candidate.quality = candidate.area * ratio / (1.0f + off_consensus * off_consensus);
    }
  }
}

size_t DropInconsistentCandidates(FaceCandidateTable* table) {
  const size_t num_faces = table->begin.size() - 1;
  size_t kept = 0, dropped = 0;
  std::vector<float> channel, distances;
  size_t begin = 0;
  for (size_t f = 0; f < num_faces; ++f) {
    const size_t end = table->begin[f + 1];
    const size_t count = end - begin;
    table->begin[f] = kept;
    std::array<float, 3> median = {0.0f, 0.0f, 0.0f};
    float limit = INFINITY;
    if (count >= 3) {
      for (size_t c = 0; c < 3; ++c) {
        channel.clear();
        for (size_t k = begin; k < end; ++k) channel.push_back(table->candidates[k].colour[c]);
        median[c] = MedianInPlace(channel.data(), channel.size());
      }
      distances.clear();
      for (size_t k = begin; k < end; ++k) {
        const auto& colour = table->candidates[k].colour;
        distances.push_back(std::sqrt((colour[0] - median[0]) * (colour[0] - median[0]) +
                                      (colour[1] - median[1]) * (colour[1] - median[1]) +
                                      (colour[2] - median[2]) * (colour[2] - median[2])));
      }
      const float spread = 1.4826f * MedianInPlace(distances.data(), distances.size());
      limit = std::max(kMinColourDistance, 3.0f * spread);
    }
    for (size_t k = begin; k < end; ++k) {
      FaceCandidate candidate = table->candidates[k];
      const auto& colour = candidate.colour;
      const float distance = count >= 3 ? std::sqrt((colour[0] - median[0]) * (colour[0] - median[0]) +
                                                    (colour[1] - median[1]) * (colour[1] - median[1]) +
                                                    (colour[2] - median[2]) * (colour[2] - median[2]))
                                        : 0.0f;
      if (distance <= limit) {
        candidate.colour_distance = distance;
        table->candidates[kept++] = candidate;
      } else {
        ++dropped;
      }
    }
    begin = end;
  }
  table->begin[num_faces] = kept;
  table->candidates.resize(kept);
  return dropped;
}

std::vector<int> LabelFaces(const FaceCandidateTable& table, const std::vector<std::array<int, 3>>& neighbours,
                            double smoothness, int max_sweeps, LabellingReport* report) {
  const size_t num_faces = table.begin.size() - 1;
  std::vector<int> labels(num_faces, -1);
  std::vector<float> best_quality(num_faces, 0.0f);
  for (size_t f = 0; f < num_faces; ++f) {
    for (size_t k = table.begin[f]; k < table.begin[f + 1]; ++k) {
      if (table.candidates[k].quality > best_quality[f]) {
        best_quality[f] = table.candidates[k].quality;
        labels[f] = table.candidates[k].photo;
      }
    }
  }
  report->energy_start = Energy(table, neighbours, labels, best_quality, smoothness);
  report->sweeps = 0;
  for (int sweep = 0; sweep < max_sweeps; ++sweep) {
    size_t changed = 0;
    for (size_t f = 0; f < num_faces; ++f) {
      if (table.begin[f + 1] - table.begin[f] < 2) continue;
      int best_label = labels[f];
      double best_cost = INFINITY;
      for (size_t k = table.begin[f]; k < table.begin[f + 1]; ++k) {
        const int photo = table.candidates[k].photo;
        double cost = 1.0 - table.candidates[k].quality / best_quality[f];
        for (const int g : neighbours[f]) {
          if (g >= 0 && labels[static_cast<size_t>(g)] != photo) cost += smoothness;
        }
        if (cost < best_cost - 1e-12 || (photo == labels[f] && cost <= best_cost + 1e-12)) {
          best_cost = cost;
          best_label = photo;
        }
      }
      if (best_label != labels[f]) {
        labels[f] = best_label;
        ++changed;
      }
    }
    ++report->sweeps;
    if (changed == 0) break;
  }
  report->energy_end = Energy(table, neighbours, labels, best_quality, smoothness);
  return labels;
}

}  // namespace reconar

namespace reconar {

TexturePatches FindPatches(const std::vector<int>& labels, const std::vector<std::array<int, 3>>& neighbours) {
  TexturePatches patches;
  patches.patch_of_face.assign(labels.size(), -1);
  std::vector<int> stack;
  for (size_t seed = 0; seed < labels.size(); ++seed) {
    if (labels[seed] < 0 || patches.patch_of_face[seed] >= 0) continue;
    const int patch = static_cast<int>(patches.photo.size());
    patches.photo.push_back(labels[seed]);
    patches.faces.emplace_back();
    patches.patch_of_face[seed] = patch;
    stack.assign(1, static_cast<int>(seed));
    while (!stack.empty()) {
      const int f = stack.back();
      stack.pop_back();
      patches.faces.back().push_back(f);
      for (const int g : neighbours[static_cast<size_t>(f)]) {
        if (g >= 0 && patches.patch_of_face[static_cast<size_t>(g)] < 0 && labels[static_cast<size_t>(g)] == labels[seed]) {
          patches.patch_of_face[static_cast<size_t>(g)] = patch;
          stack.push_back(g);
        }
      }
    }
    std::sort(patches.faces.back().begin(), patches.faces.back().end());
  }
  return patches;
}

}  // namespace reconar

namespace reconar {

size_t MergeSmallPatches(const FaceCandidateTable& table, const std::vector<std::array<int, 3>>& neighbours,
                         size_t min_faces, std::vector<int>* labels) {
  const TexturePatches patches = FindPatches(*labels, neighbours);
  size_t changed = 0;
  std::vector<std::pair<int, int>> votes;  // photo, count
  for (size_t p = 0; p < patches.photo.size(); ++p) {
    if (patches.faces[p].size() >= min_faces) continue;
    votes.clear();
    for (const int f : patches.faces[p]) {
      for (const int g : neighbours[static_cast<size_t>(f)]) {
        if (g < 0 || patches.patch_of_face[static_cast<size_t>(g)] == static_cast<int>(p)) continue;
        const int photo = (*labels)[static_cast<size_t>(g)];
        if (photo < 0) continue;
        auto it = std::find_if(votes.begin(), votes.end(), [&](const auto& v) { return v.first == photo; });
        if (it == votes.end()) {
          votes.emplace_back(photo, 1);
        } else {
          ++it->second;
        }
      }
    }
    std::sort(votes.begin(), votes.end(), [](const auto& a, const auto& b) {
      return a.second != b.second ? a.second > b.second : a.first < b.first;
    });
    for (const int f : patches.faces[p]) {
      for (const auto& vote : votes) {
        const int photo = vote.first;
        const auto begin = table.candidates.begin() + static_cast<ptrdiff_t>(table.begin[static_cast<size_t>(f)]);
        const auto end = table.candidates.begin() + static_cast<ptrdiff_t>(table.begin[static_cast<size_t>(f) + 1]);
        if (std::any_of(begin, end, [&](const FaceCandidate& c) { return c.photo == photo; })) {
          (*labels)[static_cast<size_t>(f)] = photo;
          ++changed;
          break;
        }
      }
    }
  }
  return changed;
}

PatchConsensus FindPatchConsensus(const FaceCandidateTable& table, const TexturePatches& patches) {
  PatchConsensus consensus;
  consensus.offset.assign(patches.photo.size(), Eigen::Vector3f::Zero());
  consensus.faces.assign(patches.photo.size(), 0);
  std::vector<float> channel;
  for (size_t p = 0; p < patches.photo.size(); ++p) {
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    for (const int face : patches.faces[p]) {
      const size_t begin = table.begin[static_cast<size_t>(face)], end = table.begin[static_cast<size_t>(face) + 1];
      if (end - begin < 3) continue;
      const FaceCandidate* chosen = nullptr;
      for (size_t k = begin; k < end; ++k) {
        if (table.candidates[k].photo == patches.photo[p]) chosen = &table.candidates[k];
      }
      if (chosen == nullptr) continue;
      for (size_t c = 0; c < 3; ++c) {
        channel.clear();
        for (size_t k = begin; k < end; ++k) channel.push_back(table.candidates[k].colour[c]);
        sum[static_cast<int>(c)] += MedianInPlace(channel.data(), channel.size()) - chosen->colour[c];
      }
      ++consensus.faces[p];
    }
    if (consensus.faces[p] > 0) consensus.offset[p] = (sum / static_cast<double>(consensus.faces[p])).cast<float>();
  }
  return consensus;
}

}  // namespace reconar
