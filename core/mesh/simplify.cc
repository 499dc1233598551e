#include "core/mesh/simplify.h"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <tuple>
#include <vector>

#include <Eigen/Dense>

namespace reconar {
namespace {

// The symmetric 4x4 matrix [A b; b^T c] of a sum of squared plane distances, upper triangle:
// a00 a01 a02 b0 a11 a12 b1 a22 b2 c.
struct Quadric {
  std::array<double, 10> q{};

  void AddPlane(const Eigen::Vector3d& n, double d, double weight) {
    q[0] += weight * n.x() * n.x();
    q[1] += weight * n.x() * n.y();
    q[2] += weight * n.x() * n.z();
    q[3] += weight * n.x() * d;
    q[4] += weight * n.y() * n.y();
    q[5] += weight * n.y() * n.z();
    q[6] += weight * n.y() * d;
    q[7] += weight * n.z() * n.z();
    q[8] += weight * n.z() * d;
    q[9] += weight * d * d;
  }
  Quadric operator+(const Quadric& other) const {
    Quadric sum;
    for (size_t i = 0; i < q.size(); ++i) sum.q[i] = q[i] + other.q[i];
    return sum;
  }
  double Error(const Eigen::Vector3d& p) const {
    const double x = p.x(), y = p.y(), z = p.z();
    const double error = q[0] * x * x + 2 * q[1] * x * y + 2 * q[2] * x * z + 2 * q[3] * x + q[4] * y * y +
                         2 * q[5] * y * z + 2 * q[6] * y + q[7] * z * z + 2 * q[8] * z + q[9];
    return std::max(error, 0.0);
  }
  // The point of least error when A is well conditioned (not a plane or a line of minima).
  bool Minimiser(Eigen::Vector3d* p) const {
    Eigen::Matrix3d a;
    a << q[0], q[1], q[2], q[1], q[4], q[5], q[2], q[5], q[7];
    const double trace = a.trace();
    if (!(trace > 0.0)) return false;
    const double mean_eigenvalue = trace / 3.0;
    if (a.determinant() <= 1e-6 * mean_eigenvalue * mean_eigenvalue * mean_eigenvalue) return false;
    *p = a.ldlt().solve(-Eigen::Vector3d(q[3], q[6], q[8]));
    return p->allFinite();
  }
};

// A heap entry: 16 bytes, so that the heap of millions of edges stays cache-friendly. The point
// the edge collapses to is computed again when it is popped (the quadrics are unchanged while
// both stamps are); stamps only grow, so an unchanged sum means both are unchanged.
struct Candidate {
  float cost;
  uint32_t removed, kept;  // the collapse moves `kept` to the best point and drops `removed`
  uint32_t stamp_sum;
};

// Min-heap order by cost; ties by vertex indices, so that the result is deterministic.
struct LaterThan {
  bool operator()(const Candidate& x, const Candidate& y) const {
    if (x.cost != y.cost) return x.cost > y.cost;
    if (x.kept != y.kept) return x.kept > y.kept;
    return x.removed > y.removed;
  }
};

class Simplifier {
 public:
  Simplifier(const SimplifyOptions& options, Mesh* mesh) : options_(options), mesh_(*mesh) {}

  SimplifyReport Run() {
    SimplifyReport report;
    report.vertices_before = mesh_.positions.size();
    report.faces_before = mesh_.triangles.size();
    Initialise();
    while (faces_alive_ > options_.target_faces && !heap_.empty()) {
      std::pop_heap(heap_.begin(), heap_.end(), LaterThan());
      const Candidate candidate = heap_.back();
      heap_.pop_back();
      if (Stale(candidate)) continue;
      Eigen::Vector3d point;
      const double cost = BestPoint(candidate.removed, candidate.kept, &point);
      if (cost > options_.max_error) break;
      if (!Collapse(candidate.removed, candidate.kept, point)) continue;
      ++report.collapses;
      report.max_collapse_error = std::max(report.max_collapse_error, cost);
    }
    Compact();
    report.vertices_after = mesh_.positions.size();
    report.faces_after = mesh_.triangles.size();
    return report;
  }

 private:
  Eigen::Vector3d Position(uint32_t v) const { return position_[v]; }

  Eigen::Vector3d FaceNormal(uint32_t f) const {
    const auto& t = mesh_.triangles[f];
    return (Position(t[1]) - Position(t[0])).cross(Position(t[2]) - Position(t[0]));
  }

  void Initialise() {
    const size_t n = mesh_.positions.size();
    position_.resize(n);
    for (size_t v = 0; v < n; ++v) position_[v] = mesh_.positions[v].cast<double>();
    quadric_.assign(n, Quadric{});
    vertex_faces_.assign(n, {});
    vertex_alive_.assign(n, 0);
    stamp_.assign(n, 0);
    face_alive_.assign(mesh_.triangles.size(), 0);
    std::vector<std::array<uint32_t, 3>> edges;  // (low, high, face)
    edges.reserve(3 * mesh_.triangles.size());
    for (uint32_t f = 0; f < mesh_.triangles.size(); ++f) {
      const auto& t = mesh_.triangles[f];
      if (t[0] == t[1] || t[1] == t[2] || t[0] == t[2]) continue;
      face_alive_[f] = 1;
      ++faces_alive_;
      const Eigen::Vector3d normal = FaceNormal(f);
      const double twice_area = normal.norm();
      for (uint32_t v : t) {
        vertex_faces_[v].push_back(f);
        vertex_alive_[v] = 1;
      }
      for (int k = 0; k < 3; ++k) {
        edges.push_back({std::min(t[k], t[(k + 1) % 3]), std::max(t[k], t[(k + 1) % 3]), f});
      }
      if (!(twice_area > 0.0)) continue;
      const Eigen::Vector3d unit = normal / twice_area;
      const double d = -unit.dot(Position(t[0]));
      for (uint32_t v : t) quadric_[v].AddPlane(unit, d, 0.5 * twice_area);
    }
    std::sort(edges.begin(), edges.end());
    for (size_t i = 0; i < edges.size();) {
      size_t j = i;
      while (j < edges.size() && edges[j][0] == edges[i][0] && edges[j][1] == edges[i][1]) ++j;
      if (j - i == 1) AddBorderPlanes(edges[i][0], edges[i][1], edges[i][2]);
      i = j;
    }
    heap_limit_ = std::max<size_t>(heap_limit_, edges.size() / 2);
    for (size_t i = 0; i < edges.size(); ++i) {
      if (i == 0 || edges[i][0] != edges[i - 1][0] || edges[i][1] != edges[i - 1][1]) {
        Push(edges[i][0], edges[i][1]);
      }
    }
  }

  // A plane through the border edge (a, b), perpendicular to its face.
  void AddBorderPlanes(uint32_t a, uint32_t b, uint32_t f) {
    const Eigen::Vector3d normal = FaceNormal(f);
    const Eigen::Vector3d edge = Position(b) - Position(a);
    const Eigen::Vector3d across = edge.cross(normal);
    const double length = across.norm();
    if (!(length > 0.0)) return;
    const Eigen::Vector3d unit = across / length;
    const double d = -unit.dot(Position(a));
    const double weight = options_.border_weight * edge.squaredNorm();
    quadric_[a].AddPlane(unit, d, weight);
    quadric_[b].AddPlane(unit, d, weight);
  }

  // The point of least error on edge (a, b) and that error.
  double BestPoint(uint32_t a, uint32_t b, Eigen::Vector3d* best) const {
    const Quadric q = quadric_[a] + quadric_[b];
    const Eigen::Vector3d pa = Position(a), pb = Position(b), mid = 0.5 * (pa + pb);
    *best = pb;
    double best_cost = q.Error(pb);
    for (const Eigen::Vector3d& p : {pa, mid}) {
      const double cost = q.Error(p);
      if (cost < best_cost) *best = p, best_cost = cost;
    }
    Eigen::Vector3d optimal;
    // The minimiser only when it stays near the edge (a nearly flat quadric sends it far).
    if (q.Minimiser(&optimal) && (optimal - mid).norm() <= (pb - pa).norm()) {
      const double cost = q.Error(optimal);
      if (cost < best_cost) *best = optimal, best_cost = cost;
    }
    return best_cost;
  }

  void Push(uint32_t a, uint32_t b) {
    Eigen::Vector3d best;
    const double cost = BestPoint(a, b, &best);
    heap_.push_back(Candidate{static_cast<float>(cost), a, b, stamp_[a] + stamp_[b]});
    std::push_heap(heap_.begin(), heap_.end(), LaterThan());
    if (heap_.size() > 2 * heap_limit_) DropStaleCandidates();
  }

  bool Stale(const Candidate& c) const {
    return !vertex_alive_[c.removed] || !vertex_alive_[c.kept] || stamp_[c.removed] + stamp_[c.kept] != c.stamp_sum;
  }

  // Every collapse pushes its new edges and leaves the old ones stale in the heap; dropping them
  // now and then keeps the heap near the number of live edges.
  void DropStaleCandidates() {
    heap_.erase(std::remove_if(heap_.begin(), heap_.end(), [&](const Candidate& c) { return Stale(c); }),
                heap_.end());
    std::make_heap(heap_.begin(), heap_.end(), LaterThan());
    heap_limit_ = std::max(heap_limit_, heap_.size());
  }

  // Neighbours of v over its live faces, each with how many live faces hold the edge.
  void Neighbours(uint32_t v, std::vector<std::pair<uint32_t, int>>* out) const {
    out->clear();
    for (uint32_t f : vertex_faces_[v]) {
      if (!face_alive_[f]) continue;
      for (uint32_t w : mesh_.triangles[f]) {
        if (w != v) out->push_back({w, 1});
      }
    }
    std::sort(out->begin(), out->end());
    size_t unique = 0;
    for (size_t i = 0; i < out->size(); ++i) {
      if (unique > 0 && (*out)[unique - 1].first == (*out)[i].first) {
        ++(*out)[unique - 1].second;
      } else {
        (*out)[unique++] = (*out)[i];
      }
    }
    out->resize(unique);
  }

  static bool OnBorder(const std::vector<std::pair<uint32_t, int>>& neighbours) {
    return std::any_of(neighbours.begin(), neighbours.end(), [](const auto& n) { return n.second == 1; });
  }

  bool Collapse(uint32_t u, uint32_t v, const Eigen::Vector3d& p) {
    Neighbours(u, &neighbours_u_);
    Neighbours(v, &neighbours_v_);
    const auto edge = std::lower_bound(neighbours_u_.begin(), neighbours_u_.end(), std::make_pair(v, 0));
    if (edge == neighbours_u_.end() || edge->first != v) return false;  // no longer an edge
    const int shared_faces = edge->second;
    // Link condition: the vertices adjacent to both are exactly the third corners of the shared
    // faces; and two border vertices joined by an inner edge would pinch the surface.
    int common = 0;
    for (size_t i = 0, j = 0; i < neighbours_u_.size() && j < neighbours_v_.size();) {
      if (neighbours_u_[i].first < neighbours_v_[j].first) {
        ++i;
      } else if (neighbours_v_[j].first < neighbours_u_[i].first) {
        ++j;
      } else {
        ++common, ++i, ++j;
      }
    }
    if (common != shared_faces || shared_faces > 2) return false;
    if (shared_faces == 2 && OnBorder(neighbours_u_) && OnBorder(neighbours_v_)) return false;
    if (faces_alive_ <= static_cast<size_t>(shared_faces) + 2) return false;

    // No surviving face may degenerate or turn over.
    for (uint32_t moved : {u, v}) {
      for (uint32_t f : vertex_faces_[moved]) {
        if (!face_alive_[f]) continue;
        const auto& t = mesh_.triangles[f];
        if ((t[0] == u || t[1] == u || t[2] == u) && (t[0] == v || t[1] == v || t[2] == v)) continue;
        std::array<Eigen::Vector3d, 3> corners;
        for (int k = 0; k < 3; ++k) corners[static_cast<size_t>(k)] = t[k] == moved ? p : Position(t[k]);
        const Eigen::Vector3d after = (corners[1] - corners[0]).cross(corners[2] - corners[0]);
        const Eigen::Vector3d before = FaceNormal(f);
        const double norms = after.norm() * before.norm();
        if (!(norms > 0.0) || after.dot(before) < options_.min_normal_cosine * norms) return false;
      }
    }

    // Colour along the edge, by where the new point projects on it.
    const Eigen::Vector3d pu = Position(u), pv = Position(v);
    const double length2 = (pv - pu).squaredNorm();
    const double t = length2 > 0.0 ? std::clamp((p - pu).dot(pv - pu) / length2, 0.0, 1.0) : 1.0;
    if (!mesh_.colors.empty()) {
      auto& cv = mesh_.colors[v];
      const auto& cu = mesh_.colors[u];
      for (size_t k = 0; k < 4; ++k) cv[k] = static_cast<uint8_t>(std::lround((1.0 - t) * cu[k] + t * cv[k]));
    }
    position_[v] = p;
    quadric_[v] = quadric_[u] + quadric_[v];
    std::vector<uint32_t> faces;
    for (uint32_t moved : {v, u}) {
      for (uint32_t f : vertex_faces_[moved]) {
        if (!face_alive_[f]) continue;
        auto& tri = mesh_.triangles[f];
        const bool has_u = tri[0] == u || tri[1] == u || tri[2] == u;
        const bool has_v = tri[0] == v || tri[1] == v || tri[2] == v;
        if (has_u && has_v) {
          face_alive_[f] = 0;
          --faces_alive_;
          continue;
        }
        for (uint32_t& w : tri) w = w == u ? v : w;
        faces.push_back(f);
      }
    }
    vertex_faces_[v] = std::move(faces);
    vertex_faces_[u].clear();
    vertex_faces_[u].shrink_to_fit();
    vertex_alive_[u] = 0;
    ++stamp_[u];
    ++stamp_[v];
    Neighbours(v, &neighbours_v_);
    for (const auto& neighbour : neighbours_v_) Push(std::min(v, neighbour.first), std::max(v, neighbour.first));
    return true;
  }

  void Compact() {
    std::vector<uint32_t> new_index(mesh_.positions.size(), UINT32_MAX);
    Mesh out;
    for (size_t f = 0; f < mesh_.triangles.size(); ++f) {
      if (!face_alive_[f]) continue;
      std::array<uint32_t, 3> t = mesh_.triangles[f];
      for (uint32_t& v : t) {
        if (new_index[v] == UINT32_MAX) {
          new_index[v] = static_cast<uint32_t>(out.positions.size());
          out.positions.push_back(position_[v].cast<float>());
          if (!mesh_.colors.empty()) out.colors.push_back(mesh_.colors[v]);
        }
        v = new_index[v];
      }
      out.triangles.push_back(t);
    }
    const bool had_normals = !mesh_.normals.empty();
    mesh_ = std::move(out);
    if (had_normals) ComputeVertexNormals(&mesh_);
  }

  const SimplifyOptions& options_;
  Mesh& mesh_;
  std::vector<Eigen::Vector3d> position_;
  std::vector<Quadric> quadric_;
  std::vector<std::vector<uint32_t>> vertex_faces_;
  std::vector<char> vertex_alive_, face_alive_;
  std::vector<uint32_t> stamp_;
  std::vector<Candidate> heap_;
  size_t faces_alive_ = 0;
  size_t heap_limit_ = 1024;
  std::vector<std::pair<uint32_t, int>> neighbours_u_, neighbours_v_;
};

}  // namespace

Status SimplifyOptions::Check() const {
  if (target_faces == 0) return InvalidArgument("simplify: target_faces must be positive");
  if (!(max_error >= 0.0)) return InvalidArgument("simplify: max_error must be >= 0");
  if (!(border_weight >= 0.0) || !std::isfinite(border_weight)) {
    return InvalidArgument("simplify: border_weight must be a finite number >= 0");
  }
  if (!(min_normal_cosine >= -1.0 && min_normal_cosine <= 1.0)) {
    return InvalidArgument("simplify: min_normal_cosine must be in [-1, 1]");
  }
  return Status::Ok();
}

Result<SimplifyReport> SimplifyMesh(const SimplifyOptions& options, Mesh* mesh) {
  RECONAR_RETURN_IF_ERROR(options.Check());
  RECONAR_RETURN_IF_ERROR(ValidateMesh(*mesh));
  const auto start = std::chrono::steady_clock::now();
  SimplifyReport report;
  if (mesh->triangles.size() <= options.target_faces) {
    report.vertices_before = report.vertices_after = mesh->positions.size();
    report.faces_before = report.faces_after = mesh->triangles.size();
  } else {
    report = Simplifier(options, mesh).Run();
    report.simplified = true;
  }
  report.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return report;
}

Result<SimplifyReport> SimplifyToFaceBudget(size_t max_faces, Mesh* mesh) {
  if (max_faces == 0 || mesh->triangles.size() <= max_faces) return SimplifyReport();
  SimplifyOptions options;
  options.target_faces = max_faces;
  return SimplifyMesh(options, mesh);
}

}  // namespace reconar
