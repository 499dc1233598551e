#pragma once
// MeshDrawable: a Mesh uploaded once to GL buffers (positions, optional normals and RGBA colours,
// triangle indices, 16-bit when the mesh has at most 65536 vertices), and with a base colour
// texture its texcoords and the texture's pages (each mipmapped once at upload, and drawn with its
// triangles; the colour is the vertex colour, or white, times the texture, as glTF has it).
// MeshPipeline: the program that draws it with a headlight Lambert shade (light at the camera,
// two-sided): vertex normals when the mesh has them, otherwise the flat normal of each triangle
// from screen-space derivatives of the camera-frame position. A mesh without triangles is drawn as
// GL_POINTS of MeshStyle::point_size_px (unlit without normals).
#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <vector>

#include "core/base/image.h"
#include "core/base/status.h"
#include "core/mesh/mesh.h"
#include "render/gl_handles.h"
#include "render/shader_program.h"

namespace reconar {

class MeshDrawable {
 public:
  // Needs a current GLES 3 context. InvalidArgument for an empty mesh, normals or colours whose
  // count differs from the positions', a triangle index out of range, non-finite positions, a
  // texture (RGB pages) for a mesh without texcoords, with pages out of order or larger than the
  // GPU takes.
  static Result<MeshDrawable> Upload(const Mesh& mesh, const std::vector<TexturePage>* texture = nullptr);

  bool is_point_cloud() const { return index_count_ == 0; }
  bool has_normals() const { return has_normals_; }
  bool has_colors() const { return has_colors_; }
  bool has_texture() const { return !pages_.empty(); }
  int vertex_count() const { return vertex_count_; }
  int64_t triangle_count() const { return index_count_ / 3; }

 private:
  friend class MeshPipeline;
  GlVertexArray vertex_array_;
  GlBuffer positions_;
  GlBuffer normals_;
  GlBuffer colors_;
  GlBuffer indices_;
  GlBuffer texcoords_;
  struct Page {
    GlTexture texture;
    int64_t first_index, index_count;
  };
  std::vector<Page> pages_;
  int vertex_count_ = 0;
  int64_t index_count_ = 0;
  GLenum index_type_ = GL_UNSIGNED_INT;  // GL_UNSIGNED_SHORT for meshes of <= 65536 vertices
  bool has_normals_ = false;
  bool has_colors_ = false;
};

struct MeshStyle {
  std::array<float, 3> color = {0.85f, 0.75f, 0.6f};  // RGB 0..1 when the mesh has no vertex colours
  float point_size_px = 3.0f;                         // point clouds
  bool shading = true;                                // headlight Lambert; false = flat colour
  // Below 1: blended over what is drawn (a design over the as-built), without hiding what is drawn
  // after it (the depth buffer is not written).
  float opacity = 1.0f;
  // Multiplies the colour drawn, per channel: e.g. a texture brought to the video's exposure
  // (render/ar/exposure_match.h).
  std::array<float, 3> gain = {1.0f, 1.0f, 1.0f};
};

class MeshPipeline {
 public:
  // Needs a current GLES 3 context.
  static Result<MeshPipeline> Create();

  // Draws into the bound framebuffer with depth test. clip_from_cam: render/camera_projection.h;
  // cam_from_model: a similarity (render/model_placement.h CamFromModel).
  Status Draw(const MeshDrawable& mesh, const Eigen::Matrix4d& clip_from_cam, const Eigen::Matrix4d& cam_from_model,
              const MeshStyle& style) const;

 private:
  ShaderProgram program_;
  GLint clip_from_model_ = -1;
  GLint cam_from_model_ = -1;
  GLint cam_normal_from_model_ = -1;
  GLint point_size_ = -1;
  GLint shading_mode_ = -1;
  GLint opacity_ = -1;
  GLint gain_ = -1;
  GLint textured_ = -1;
  GLint base_color_ = -1;
};

}  // namespace reconar
