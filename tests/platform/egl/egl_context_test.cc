#include "platform/egl/egl_context.h"

#include <GLES3/gl3.h>
#include <gtest/gtest.h>
#include <sys/stat.h>

#include <cstdlib>
#include <string>

namespace reconar {
namespace {

bool PathExists(const char* path) {
  struct stat info;
  return ::stat(path, &info) == 0;
}

// Runs the body with DISPLAY unset, restoring it afterwards.
class ScopedUnsetDisplay {
 public:
  ScopedUnsetDisplay() {
    if (const char* display = std::getenv("DISPLAY")) {
      saved_ = display;
      had_ = true;
    }
    ::unsetenv("DISPLAY");
  }
  ~ScopedUnsetDisplay() {
    if (had_) ::setenv("DISPLAY", saved_.c_str(), 1);
  }

 private:
  std::string saved_;
  bool had_ = false;
};

TEST(EglContextTest, SurfacelessGivesAnEs3ContextThatRenders) {
  EglContextOptions options;
  options.kind = EglContextKind::kSurfaceless;
  options.width = 64;
  options.height = 32;
  auto context = EglContext::Create(options);
  ASSERT_TRUE(context.ok()) << context.status().ToString();
  EXPECT_EQ((*context)->kind(), EglContextKind::kSurfaceless);
  EXPECT_FALSE((*context)->has_surface());
  EXPECT_EQ((*context)->width(), 64);
  EXPECT_EQ((*context)->height(), 32);
  EXPECT_FALSE((*context)->renderer().empty());
  EXPECT_NE((*context)->gl_version().find("OpenGL ES 3"), std::string::npos) << (*context)->gl_version();
  std::printf("renderer: %s | %s | EGL vendor %s\n", (*context)->renderer().c_str(), (*context)->gl_version().c_str(),
              (*context)->egl_vendor().c_str());

  // Clear a 1x1 framebuffer and read it back: the context really draws.
  GLuint framebuffer = 0;
  GLuint color = 0;
  glGenFramebuffers(1, &framebuffer);
  glGenRenderbuffers(1, &color);
  glBindRenderbuffer(GL_RENDERBUFFER, color);
  glRenderbufferStorage(GL_RENDERBUFFER, GL_RGBA8, 1, 1);
  glBindFramebuffer(GL_FRAMEBUFFER, framebuffer);
  glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER, color);
  ASSERT_EQ(glCheckFramebufferStatus(GL_FRAMEBUFFER), static_cast<GLenum>(GL_FRAMEBUFFER_COMPLETE));
  glViewport(0, 0, 1, 1);
  glClearColor(0.2f, 0.4f, 0.6f, 1.0f);
  glClear(GL_COLOR_BUFFER_BIT);
  unsigned char pixel[4] = {0, 0, 0, 0};
  glReadPixels(0, 0, 1, 1, GL_RGBA, GL_UNSIGNED_BYTE, pixel);
  EXPECT_NEAR(pixel[0], 51, 1);
  EXPECT_NEAR(pixel[1], 102, 1);
  EXPECT_NEAR(pixel[2], 153, 1);
  glDeleteRenderbuffers(1, &color);
  glDeleteFramebuffers(1, &framebuffer);
  EXPECT_TRUE((*context)->SwapBuffers().ok());  // surfaceless: a flush, nothing to show
  EXPECT_FALSE((*context)->PollEvents().should_quit());
  EXPECT_TRUE((*context)->MakeCurrent().ok());
}

TEST(EglContextTest, Gles2ContextWorksToo) {
  EglContextOptions options;
  options.kind = EglContextKind::kSurfaceless;
  options.gles_version = 2;
  auto context = EglContext::Create(options);
  ASSERT_TRUE(context.ok()) << context.status().ToString();
  EXPECT_NE((*context)->gl_version().find("OpenGL ES"), std::string::npos);
}

TEST(EglContextTest, TwoContextsInSequence) {
  for (int i = 0; i < 2; ++i) {
    EglContextOptions options;
    options.kind = EglContextKind::kSurfaceless;
    auto context = EglContext::Create(options);
    ASSERT_TRUE(context.ok()) << context.status().ToString();
  }
}

TEST(EglContextTest, GbmWithoutDriDevicesFailsClearly) {
  if (PathExists("/dev/dri")) GTEST_SKIP() << "/dev/dri exists on this machine";
  EglContextOptions options;
  options.kind = EglContextKind::kGbm;
  auto context = EglContext::Create(options);
  ASSERT_FALSE(context.ok());
  EXPECT_EQ(context.status().code(), StatusCode::kFailedPrecondition);
  EXPECT_NE(context.status().message().find("no DRM device under /dev/dri"), std::string::npos)
      << context.status().ToString();
}

TEST(EglContextTest, GbmWithAMissingExplicitDeviceNamesIt) {
  EglContextOptions options;
  options.kind = EglContextKind::kGbm;
  options.drm_device = "/dev/dri/card97";
  auto context = EglContext::Create(options);
  ASSERT_FALSE(context.ok());
  EXPECT_NE(context.status().message().find("/dev/dri/card97: cannot open"), std::string::npos)
      << context.status().ToString();
}

TEST(EglContextTest, X11WithoutDisplayFailsClearly) {
  ScopedUnsetDisplay no_display;
  EglContextOptions options;
  options.kind = EglContextKind::kX11Window;
  auto context = EglContext::Create(options);
  ASSERT_FALSE(context.ok());
  EXPECT_EQ(context.status().code(), StatusCode::kFailedPrecondition);
  EXPECT_NE(context.status().message().find("cannot open X display"), std::string::npos) << context.status().ToString();
}

TEST(EglContextTest, AutoWithoutDisplayOrDriIsSurfaceless) {
  if (PathExists("/dev/dri")) GTEST_SKIP() << "/dev/dri exists on this machine";
  ScopedUnsetDisplay no_display;
  auto context = EglContext::Create(EglContextOptions());
  ASSERT_TRUE(context.ok()) << context.status().ToString();
  EXPECT_EQ((*context)->kind(), EglContextKind::kSurfaceless);
}

// Runs only with an X server (e.g. `xvfb-run -a ctest -L gl`); skipped otherwise.
TEST(EglContextTest, X11WindowClearsSwapsAndPolls) {
  const char* display = std::getenv("DISPLAY");
  if (display == nullptr || display[0] == '\0') GTEST_SKIP() << "DISPLAY is not set";
  EglContextOptions options;
  options.kind = EglContextKind::kX11Window;
  options.width = 160;
  options.height = 120;
  options.title = "reconar egl test";
  auto context = EglContext::Create(options);
  ASSERT_TRUE(context.ok()) << context.status().ToString();
  EXPECT_EQ((*context)->kind(), EglContextKind::kX11Window);
  EXPECT_TRUE((*context)->has_surface());
  EXPECT_EQ((*context)->width(), 160);
  EXPECT_EQ((*context)->height(), 120);
  for (int frame = 0; frame < 3; ++frame) {
    glViewport(0, 0, 160, 120);
    glClearColor(0.0f, 1.0f, 0.0f, 1.0f);
    glClear(GL_COLOR_BUFFER_BIT);
    unsigned char pixel[4] = {0, 0, 0, 0};
    glReadPixels(80, 60, 1, 1, GL_RGBA, GL_UNSIGNED_BYTE, pixel);
    EXPECT_EQ(pixel[1], 255);
    EXPECT_TRUE((*context)->SwapBuffers().ok());
    EXPECT_FALSE((*context)->PollEvents().should_quit());
  }
  EXPECT_EQ(glGetError(), static_cast<GLenum>(GL_NO_ERROR));
}

TEST(EglContextTest, BadOptionsAreRejected) {
  EglContextOptions options;
  options.kind = EglContextKind::kSurfaceless;
  options.gles_version = 4;
  auto context = EglContext::Create(options);
  ASSERT_FALSE(context.ok());
  EXPECT_EQ(context.status().code(), StatusCode::kInvalidArgument);
  EXPECT_NE(context.status().message().find("gles_version"), std::string::npos);
}

}  // namespace
}  // namespace reconar
