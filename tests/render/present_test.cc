// Presenting the overlay in an X11 window: letterboxed and upright. Runs only with an X server
// (e.g. `xvfb-run -a ctest -L gl`); skipped otherwise.
#include <GLES3/gl3.h>
#include <gtest/gtest.h>

#include <array>
#include <cstdlib>
#include <memory>
#include <vector>

#include "platform/egl/egl_context.h"
#include "render/overlay_renderer.h"

namespace reconar {
namespace {

using Rgba = std::array<uint8_t, 4>;

Rgba WindowPixel(int x, int y_from_bottom) {
  Rgba pixel = {0, 0, 0, 0};
  glReadPixels(x, y_from_bottom, 1, 1, GL_RGBA, GL_UNSIGNED_BYTE, pixel.data());
  return pixel;
}

TEST(PresentTest, FrameAppearsUprightAndLetterboxedInAWindow) {
  const char* display = std::getenv("DISPLAY");
  if (display == nullptr || display[0] == '\0') GTEST_SKIP() << "DISPLAY is not set";
  EglContextOptions window_options;  // kAuto: DISPLAY is set, so an X11 window
  window_options.width = 400;
  window_options.height = 400;
  auto context = EglContext::Create(window_options);
  ASSERT_TRUE(context.ok()) << context.status().ToString();
  ASSERT_EQ((*context)->kind(), EglContextKind::kX11Window);

  // A 320 x 240 frame: top half red, bottom half blue.
  const int width = 320;
  const int height = 240;
  std::vector<uint8_t> frame(static_cast<size_t>(width) * height * 3, 0);
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) frame[(static_cast<size_t>(y) * width + x) * 3 + (y < height / 2 ? 0 : 2)] = 255;
  }
  OverlayRendererOptions options;
  options.width = width;
  options.height = height;
  auto renderer = OverlayRenderer::Create(options);
  ASSERT_TRUE(renderer.ok()) << renderer.status().ToString();
  ASSERT_TRUE((*renderer)->BeginFrame().ok());
  ASSERT_TRUE(
      (*renderer)->DrawBackground(ImageView<const uint8_t>(3 * width, height, 3 * width, frame.data()), 3).ok());
  ASSERT_TRUE((*renderer)->PresentToDefaultFramebuffer((*context)->width(), (*context)->height()).ok());

  // 320 x 240 scaled by 1.25 fills 400 x 300, with 50-pixel bars above and below. The back buffer
  // is read bottom-up: the image's top (red) is near the window's top (high y).
  glBindFramebuffer(GL_READ_FRAMEBUFFER, 0);
  EXPECT_EQ(WindowPixel(200, 20), (Rgba{0, 0, 0, 255}));     // bottom bar
  EXPECT_EQ(WindowPixel(200, 80), (Rgba{0, 0, 255, 255}));   // image bottom half: blue
  EXPECT_EQ(WindowPixel(200, 320), (Rgba{255, 0, 0, 255}));  // image top half: red
  EXPECT_EQ(WindowPixel(200, 380), (Rgba{0, 0, 0, 255}));    // top bar
  EXPECT_TRUE((*context)->SwapBuffers().ok());
  EXPECT_FALSE((*context)->PollEvents().should_quit());
}

}  // namespace
}  // namespace reconar
