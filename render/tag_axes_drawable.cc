#include "render/tag_axes_drawable.h"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <string>
#include <utility>

#include "render/gl_error.h"

namespace reconar {
namespace {

constexpr const char* kVertexShader = R"(#version 300 es
layout(location = 0) in vec3 a_position;
layout(location = 1) in vec3 a_color;
uniform mat4 u_clip_from_tag;
uniform vec3 u_outline_color;
uniform bool u_use_outline_color;
out vec3 v_color;
void main() {
  v_color = u_use_outline_color ? u_outline_color : a_color;
  gl_Position = u_clip_from_tag * vec4(a_position, 1.0);
}
)";

constexpr const char* kFragmentShader = R"(#version 300 es
precision highp float;
in vec3 v_color;
out vec4 o_color;
void main() {
  o_color = vec4(v_color, 1.0);
}
)";

// Unit-size geometry (tag size 1): 3 axis lines (GL_LINES), then the outline (GL_LINE_LOOP).
struct Vertex {
  GLfloat position[3];
  GLfloat color[3];
};
constexpr Vertex kVertices[] = {
    {{0, 0, 0}, {1, 0, 0}},         {{1, 0, 0}, {1, 0, 0}},        {{0, 0, 0}, {0, 1, 0}},
    {{0, 1, 0}, {0, 1, 0}},         {{0, 0, 0}, {0, 0, 1}},        {{0, 0, 1}, {0, 0, 1}},
    {{-0.5f, -0.5f, 0}, {1, 1, 0}}, {{0.5f, -0.5f, 0}, {1, 1, 0}}, {{0.5f, 0.5f, 0}, {1, 1, 0}},
    {{-0.5f, 0.5f, 0}, {1, 1, 0}},
};
constexpr GLint kAxisVertices = 6;
constexpr GLint kOutlineVertices = 4;

}  // namespace

Result<TagAxesDrawable> TagAxesDrawable::Create() {
  TagAxesDrawable axes;
  RECONAR_ASSIGN_OR_RETURN(axes.program_, ShaderProgram::Build("tag axes", kVertexShader, kFragmentShader));
  axes.clip_from_tag_ = axes.program_.Uniform("u_clip_from_tag");
  axes.outline_color_ = axes.program_.Uniform("u_outline_color");
  axes.use_outline_color_ = axes.program_.Uniform("u_use_outline_color");
  axes.vertex_array_ = MakeGlVertexArray();
  glBindVertexArray(axes.vertex_array_.get());
  axes.vertices_ = MakeGlBuffer();
  glBindBuffer(GL_ARRAY_BUFFER, axes.vertices_.get());
  glBufferData(GL_ARRAY_BUFFER, sizeof(kVertices), kVertices, GL_STATIC_DRAW);
  glEnableVertexAttribArray(0);
  glVertexAttribPointer(0, 3, GL_FLOAT, GL_FALSE, sizeof(Vertex), nullptr);
  glEnableVertexAttribArray(1);
  glVertexAttribPointer(1, 3, GL_FLOAT, GL_FALSE, sizeof(Vertex),
                        reinterpret_cast<const void*>(offsetof(Vertex, color)));
  glBindVertexArray(0);
  glBindBuffer(GL_ARRAY_BUFFER, 0);
  glGetFloatv(GL_ALIASED_LINE_WIDTH_RANGE, axes.line_width_range_.data());
  RECONAR_RETURN_IF_ERROR(CheckGlError("TagAxesDrawable::Create"));
  return axes;
}

Status TagAxesDrawable::Draw(const Eigen::Matrix4d& clip_from_cam, const Rigid3& cam_from_tag, double tag_size_m,
                             const TagAxesStyle& style) const {
  if (!(tag_size_m > 0.0 && std::isfinite(tag_size_m))) {
    return InvalidArgument("TagAxesDrawable::Draw: tag size must be positive, got " + std::to_string(tag_size_m));
  }
  Eigen::Matrix4d tag_from_unit = Eigen::Matrix4d::Identity();
  tag_from_unit.topLeftCorner<3, 3>() *= tag_size_m;
  const Eigen::Matrix4f clip_from_unit = (clip_from_cam * cam_from_tag.Matrix() * tag_from_unit).cast<float>();

  if (style.depth_test) {
    glEnable(GL_DEPTH_TEST);
    glDepthFunc(GL_LEQUAL);
  } else {
    glDisable(GL_DEPTH_TEST);
  }
  glLineWidth(std::clamp(style.line_width_px, line_width_range_[0], line_width_range_[1]));
  glUseProgram(program_.id());
  glUniformMatrix4fv(clip_from_tag_, 1, GL_FALSE, clip_from_unit.data());
  glUniform3f(outline_color_, style.outline_color[0], style.outline_color[1], style.outline_color[2]);
  glBindVertexArray(vertex_array_.get());
  if (style.draw_outline) {
    glUniform1i(use_outline_color_, 1);
    glDrawArrays(GL_LINE_LOOP, kAxisVertices, kOutlineVertices);
  }
  if (style.draw_axes) {
    glUniform1i(use_outline_color_, 0);
    glDrawArrays(GL_LINES, 0, kAxisVertices);
  }
  glBindVertexArray(0);
  glLineWidth(1.0f);
  glDepthFunc(GL_LESS);
  return CheckGlError("TagAxesDrawable::Draw");
}

}  // namespace reconar
