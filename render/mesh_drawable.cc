#include "render/mesh_drawable.h"

#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <string>
#include <utility>
#include <vector>

#include "render/gl_error.h"

namespace reconar {
namespace {

enum AttributeLocation : GLuint { kPosition = 0, kNormal = 1, kColor = 2, kTexcoord = 3 };

// Shading modes of the fragment shader.
enum ShadingMode : GLint { kVertexNormals = 0, kFlatNormals = 1, kUnlit = 2 };

constexpr const char* kVertexShader = R"(#version 300 es
layout(location = 0) in vec3 a_position;
layout(location = 1) in vec3 a_normal;
layout(location = 2) in vec4 a_color;
layout(location = 3) in vec2 a_texcoord;
uniform mat4 u_clip_from_model;
uniform mat4 u_cam_from_model;
uniform mat3 u_cam_normal_from_model;
uniform float u_point_size;
out vec3 v_cam_position;
out vec3 v_cam_normal;
out vec4 v_color;
out vec2 v_texcoord;
void main() {
  v_texcoord = a_texcoord;
  v_cam_position = (u_cam_from_model * vec4(a_position, 1.0)).xyz;
  v_cam_normal = u_cam_normal_from_model * a_normal;
  v_color = a_color;
  gl_PointSize = u_point_size;
  gl_Position = u_clip_from_model * vec4(a_position, 1.0);
}
)";

constexpr const char* kFragmentShader = R"(#version 300 es
precision highp float;
uniform int u_shading_mode;
uniform float u_opacity;
uniform vec3 u_gain;
uniform bool u_textured;
uniform sampler2D u_base_color;
in vec3 v_cam_position;
in vec3 v_cam_normal;
in vec4 v_color;
in vec2 v_texcoord;
out vec4 o_color;
void main() {
  vec3 color = u_textured ? v_color.rgb * texture(u_base_color, v_texcoord).rgb : v_color.rgb;
  float shade = 1.0;
  if (u_shading_mode != 2) {
    vec3 normal = u_shading_mode == 0 ? v_cam_normal
                                      : cross(dFdx(v_cam_position), dFdy(v_cam_position));
    float length_n = length(normal);
    vec3 to_eye = normalize(-v_cam_position);
    shade = length_n > 0.0 ? 0.2 + 0.8 * abs(dot(normal / length_n, to_eye)) : 1.0;
  }
  o_color = vec4(color * u_gain * shade, u_opacity);
}
)";

template <typename T>
GlBuffer MakeArrayBuffer(GLenum target, const T* data, size_t count) {
  GlBuffer buffer = MakeGlBuffer();
  glBindBuffer(target, buffer.get());
  glBufferData(target, static_cast<GLsizeiptr>(count * sizeof(T)), data, GL_STATIC_DRAW);
  return buffer;
}

void ToGl(const Eigen::Matrix4d& m, float out[16]) {
  const Eigen::Matrix4f f = m.cast<float>();
  std::copy(f.data(), f.data() + 16, out);  // column major, as GL wants
}

}  // namespace

Result<MeshDrawable> MeshDrawable::Upload(const Mesh& mesh, const std::vector<TexturePage>* texture) {
  const size_t n = mesh.positions.size();
  if (n == 0) return InvalidArgument("MeshDrawable::Upload: the mesh has no vertices");
  if (n > static_cast<size_t>(INT32_MAX)) return InvalidArgument("MeshDrawable::Upload: too many vertices");
  RECONAR_RETURN_IF_ERROR(ValidateMesh(mesh).WithContext("MeshDrawable::Upload"));
  for (size_t i = 0; i < n; ++i) {
    if (!mesh.positions[i].allFinite()) {
      return InvalidArgument("MeshDrawable::Upload: vertex " + std::to_string(i) + " is not finite");
    }
  }

  const bool textured = texture != nullptr;
  if (textured) {
    if (mesh.texcoords.empty()) return InvalidArgument("MeshDrawable::Upload: a texture for a mesh without texcoords");
    RECONAR_RETURN_IF_ERROR(ValidateTexturePages(*texture, mesh.triangles.size()).WithContext("MeshDrawable::Upload"));
    GLint max_size = 0;
    glGetIntegerv(GL_MAX_TEXTURE_SIZE, &max_size);
    for (const TexturePage& page : *texture) {
      if (page.image.channels() != 3 || page.image.empty()) {
        return InvalidArgument("MeshDrawable::Upload: the texture must be RGB");
      }
      if (page.image.width() > max_size || page.image.height() > max_size) {
        return InvalidArgument("MeshDrawable::Upload: a " + std::to_string(page.image.width()) + " x " +
                               std::to_string(page.image.height()) + " texture exceeds the GPU's " +
                               std::to_string(max_size) + " texels");
      }
    }
  }

  MeshDrawable drawable;
  drawable.vertex_count_ = static_cast<int>(n);
  drawable.index_count_ = static_cast<int64_t>(mesh.triangles.size()) * 3;
  drawable.has_normals_ = !mesh.normals.empty();
  drawable.has_colors_ = !mesh.colors.empty();
  drawable.vertex_array_ = MakeGlVertexArray();
  glBindVertexArray(drawable.vertex_array_.get());

  static_assert(sizeof(Eigen::Vector3f) == 3 * sizeof(float), "packed positions");
  drawable.positions_ = MakeArrayBuffer(GL_ARRAY_BUFFER, mesh.positions.data(), n);
  glEnableVertexAttribArray(kPosition);
  glVertexAttribPointer(kPosition, 3, GL_FLOAT, GL_FALSE, 0, nullptr);
  if (drawable.has_normals_) {
    drawable.normals_ = MakeArrayBuffer(GL_ARRAY_BUFFER, mesh.normals.data(), n);
    glEnableVertexAttribArray(kNormal);
    glVertexAttribPointer(kNormal, 3, GL_FLOAT, GL_FALSE, 0, nullptr);
  }
  if (drawable.has_colors_) {
    static_assert(sizeof(std::array<uint8_t, 4>) == 4, "packed colours");
    drawable.colors_ = MakeArrayBuffer(GL_ARRAY_BUFFER, mesh.colors.data(), n);
    glEnableVertexAttribArray(kColor);
    glVertexAttribPointer(kColor, 4, GL_UNSIGNED_BYTE, GL_TRUE, 0, nullptr);
  }
  if (textured) {
    static_assert(sizeof(Eigen::Vector2f) == 2 * sizeof(float), "packed texcoords");
    drawable.texcoords_ = MakeArrayBuffer(GL_ARRAY_BUFFER, mesh.texcoords.data(), n);
    glEnableVertexAttribArray(kTexcoord);
    glVertexAttribPointer(kTexcoord, 2, GL_FLOAT, GL_FALSE, 0, nullptr);
    for (size_t k = 0; k < texture->size(); ++k) {
      const Image<uint8_t>& image = (*texture)[k].image;
      // Row 0 first: texcoord v = 0 is the image's top row, as glTF has it.
      const size_t first = (*texture)[k].first_triangle;
      const size_t end = PageTrianglesEnd(*texture, k, mesh.triangles.size());
      drawable.pages_.push_back({MakeGlTexture(), static_cast<int64_t>(first) * 3, static_cast<int64_t>(end - first) * 3});
      glBindTexture(GL_TEXTURE_2D, drawable.pages_.back().texture.get());
      glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
      glTexImage2D(GL_TEXTURE_2D, 0, GL_RGB8, image.width(), image.height(), 0, GL_RGB, GL_UNSIGNED_BYTE, image.data());
      glPixelStorei(GL_UNPACK_ALIGNMENT, 4);
      glGenerateMipmap(GL_TEXTURE_2D);
      glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_LINEAR_MIPMAP_LINEAR);
      glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
      glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
      glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
    }
    glBindTexture(GL_TEXTURE_2D, 0);
  }
  if (!mesh.triangles.empty()) {
    static_assert(sizeof(std::array<uint32_t, 3>) == 12, "packed triangles");
    if (n <= 65536) {  // 16-bit indices: half the index traffic
      std::vector<uint16_t> short_indices;
      short_indices.reserve(mesh.triangles.size() * 3);
      for (const auto& triangle : mesh.triangles) {
        for (uint32_t index : triangle) short_indices.push_back(static_cast<uint16_t>(index));
      }
      drawable.indices_ = MakeArrayBuffer(GL_ELEMENT_ARRAY_BUFFER, short_indices.data(), short_indices.size());
      drawable.index_type_ = GL_UNSIGNED_SHORT;
    } else {
      drawable.indices_ = MakeArrayBuffer(GL_ELEMENT_ARRAY_BUFFER, mesh.triangles.data(), mesh.triangles.size());
      drawable.index_type_ = GL_UNSIGNED_INT;
    }
  }
  glBindVertexArray(0);
  glBindBuffer(GL_ARRAY_BUFFER, 0);
  glBindBuffer(GL_ELEMENT_ARRAY_BUFFER, 0);
  RECONAR_RETURN_IF_ERROR(CheckGlError("MeshDrawable::Upload"));
  return drawable;
}

Result<MeshPipeline> MeshPipeline::Create() {
  MeshPipeline pipeline;
  RECONAR_ASSIGN_OR_RETURN(pipeline.program_, ShaderProgram::Build("mesh", kVertexShader, kFragmentShader));
  pipeline.clip_from_model_ = pipeline.program_.Uniform("u_clip_from_model");
  pipeline.cam_from_model_ = pipeline.program_.Uniform("u_cam_from_model");
  pipeline.cam_normal_from_model_ = pipeline.program_.Uniform("u_cam_normal_from_model");
  pipeline.point_size_ = pipeline.program_.Uniform("u_point_size");
  pipeline.shading_mode_ = pipeline.program_.Uniform("u_shading_mode");
  pipeline.opacity_ = pipeline.program_.Uniform("u_opacity");
  pipeline.gain_ = pipeline.program_.Uniform("u_gain");
  pipeline.textured_ = pipeline.program_.Uniform("u_textured");
  pipeline.base_color_ = pipeline.program_.Uniform("u_base_color");
  return pipeline;
}

Status MeshPipeline::Draw(const MeshDrawable& mesh, const Eigen::Matrix4d& clip_from_cam,
                          const Eigen::Matrix4d& cam_from_model, const MeshStyle& style) const {
  float clip_from_model[16];
  float cam_from_model_gl[16];
  ToGl(clip_from_cam * cam_from_model, clip_from_model);
  ToGl(cam_from_model, cam_from_model_gl);
  // Normals transform by the inverse transpose; for a similarity that is the rotation up to scale,
  // and the shader normalises.
  const Eigen::Matrix3f normal_from_model = cam_from_model.topLeftCorner<3, 3>().inverse().transpose().cast<float>();
  GLint mode = kUnlit;
  if (style.shading) {
    if (mesh.has_normals_) {
      mode = kVertexNormals;
    } else if (!mesh.is_point_cloud()) {
      mode = kFlatNormals;
    }
  }

  glEnable(GL_DEPTH_TEST);
  glDepthFunc(GL_LESS);
  const bool blended = style.opacity < 1.0f;
  glDepthMask(blended ? GL_FALSE : GL_TRUE);
  if (blended) {
    glEnable(GL_BLEND);
    glBlendFunc(GL_SRC_ALPHA, GL_ONE_MINUS_SRC_ALPHA);
  } else {
    glDisable(GL_BLEND);
  }
  glUseProgram(program_.id());
  glUniformMatrix4fv(clip_from_model_, 1, GL_FALSE, clip_from_model);
  glUniformMatrix4fv(cam_from_model_, 1, GL_FALSE, cam_from_model_gl);
  glUniformMatrix3fv(cam_normal_from_model_, 1, GL_FALSE, normal_from_model.data());
  glUniform1f(point_size_, style.point_size_px);
  glUniform1i(shading_mode_, mode);
  glUniform1f(opacity_, std::clamp(style.opacity, 0.0f, 1.0f));
  glUniform3f(gain_, style.gain[0], style.gain[1], style.gain[2]);
  glUniform1i(textured_, mesh.has_texture() ? 1 : 0);
  glUniform1i(base_color_, 0);
  glActiveTexture(GL_TEXTURE0);
  glBindVertexArray(mesh.vertex_array_.get());
  // Attributes without an array take the current generic value (context state, not VAO state).
  if (!mesh.has_colors_) glVertexAttrib4f(kColor, style.color[0], style.color[1], style.color[2], 1.0f);
  if (!mesh.has_normals_) glVertexAttrib3f(kNormal, 0.0f, 0.0f, 0.0f);
  if (!mesh.has_texture()) glVertexAttrib2f(kTexcoord, 0.0f, 0.0f);
  if (mesh.is_point_cloud()) {
    glDrawArrays(GL_POINTS, 0, mesh.vertex_count_);
  } else if (!mesh.has_texture()) {
    glDrawElements(GL_TRIANGLES, static_cast<GLsizei>(mesh.index_count_), mesh.index_type_, nullptr);
  } else {
    const size_t index_bytes = mesh.index_type_ == GL_UNSIGNED_SHORT ? 2 : 4;
    for (const MeshDrawable::Page& page : mesh.pages_) {
      glBindTexture(GL_TEXTURE_2D, page.texture.get());
      glDrawElements(GL_TRIANGLES, static_cast<GLsizei>(page.index_count), mesh.index_type_,
                     reinterpret_cast<const void*>(static_cast<uintptr_t>(page.first_index) * index_bytes));
    }
    glBindTexture(GL_TEXTURE_2D, 0);
  }
  glBindVertexArray(0);
  if (blended) {
    glDisable(GL_BLEND);
    glDepthMask(GL_TRUE);
  }
  return CheckGlError("MeshPipeline::Draw");
}

}  // namespace reconar
