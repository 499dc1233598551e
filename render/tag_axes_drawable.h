#pragma once
// TagAxesDrawable: a tag's frame as three lines from its centre, x red, y green, z blue, each one
// tag size long, and the tag's outline (the edge of the black square, corners (+-s/2, +-s/2, 0)).
// Tag frame: origin at the tag centre, x right, y up, z out of the printed tag toward the viewer.
#include <Eigen/Core>
#include <array>

#include "core/base/status.h"
#include "core/math/rigid3.h"
#include "render/gl_handles.h"
#include "render/shader_program.h"

namespace reconar {

struct TagAxesStyle {
  float line_width_px = 3.0f;  // clamped to the driver's GL_ALIASED_LINE_WIDTH_RANGE
  bool draw_axes = true;
  bool draw_outline = true;
  std::array<float, 3> outline_color = {1.0f, 1.0f, 0.0f};
  bool depth_test = true;  // hidden behind a model drawn earlier
};

class TagAxesDrawable {
 public:
  // Needs a current GLES 3 context.
  static Result<TagAxesDrawable> Create();

  // InvalidArgument unless tag_size_m > 0 and finite.
  Status Draw(const Eigen::Matrix4d& clip_from_cam, const Rigid3& cam_from_tag, double tag_size_m,
              const TagAxesStyle& style) const;

 private:
  ShaderProgram program_;
  GLint clip_from_tag_ = -1;
  GLint outline_color_ = -1;
  GLint use_outline_color_ = -1;
  GlVertexArray vertex_array_;
  GlBuffer vertices_;
  std::array<GLfloat, 2> line_width_range_ = {1.0f, 1.0f};
};

}  // namespace reconar
