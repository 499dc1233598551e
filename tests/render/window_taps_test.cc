// Clicks (taps) in the view's X11 window reach WindowEvents::taps in window pixels, and the
// letterbox maps them back to the picture's pixels (the view's tap-to-measure). The window part
// runs only with an X server (`xvfb-run -a ctest -L gl`); skipped otherwise.
#include <gtest/gtest.h>
#include <unistd.h>

#include <chrono>
#include <cstdlib>
#include <string>
#include <thread>

#include "platform/egl/egl_context.h"
#include "render/offscreen_target.h"

// After our headers: Xlib defines Status as a macro.
#include <X11/Xlib.h>

namespace reconar {
namespace {

::Window FindWindowNamed(Display* display, ::Window parent, const std::string& name) {
  char* window_name = nullptr;
  if (XFetchName(display, parent, &window_name) && window_name != nullptr) {
    const bool match = name == window_name;
    XFree(window_name);
    if (match) return parent;
  }
  ::Window root_return, parent_return, *children = nullptr;
  unsigned count = 0;
  if (!XQueryTree(display, parent, &root_return, &parent_return, &children, &count)) return 0;
  ::Window found = 0;
  for (unsigned i = 0; i < count && found == 0; ++i) found = FindWindowNamed(display, children[i], name);
  if (children != nullptr) XFree(children);
  return found;
}

TEST(WindowTaps, TheLetterboxMapsWindowPixelsToThePicture) {
  // 320 x 240 in a 400 x 400 window: 400 x 300, 50 rows of black above and below.
  const Letterbox box = LetterboxIn(320, 240, 400, 400);
  EXPECT_EQ(box.x0, 0);
  EXPECT_EQ(box.y0, 50);
  EXPECT_EQ(box.width, 400);
  EXPECT_EQ(box.height, 300);
  double x = 0, y = 0;
  ASSERT_TRUE(box.ImagePixel(320, 240, 0, 50, &x, &y));  // the box's top-left window pixel
  EXPECT_NEAR(x, -0.1, 1e-12);
  EXPECT_NEAR(y, -0.1, 1e-12);
  ASSERT_TRUE(box.ImagePixel(320, 240, 200, 200, &x, &y));
  EXPECT_NEAR(x, 159.9, 1e-12);
  EXPECT_NEAR(y, 119.9, 1e-12);
  EXPECT_FALSE(box.ImagePixel(320, 240, 200, 20, &x, &y)) << "in the black band";
  EXPECT_FALSE(LetterboxIn(0, 240, 400, 400).ImagePixel(0, 240, 1, 1, &x, &y));
}

TEST(WindowTaps, AClickReachesTheEventsInWindowPixels) {
  const char* display_name = std::getenv("DISPLAY");
  if (display_name == nullptr || display_name[0] == '\0') GTEST_SKIP() << "DISPLAY is not set";
  EglContextOptions options;
  options.width = 400;
  options.height = 300;
  options.title = "reconar taps test " + std::to_string(::getpid());
  auto context = EglContext::Create(options);
  ASSERT_TRUE(context.ok()) << context.status().ToString();
  ASSERT_EQ((*context)->kind(), EglContextKind::kX11Window);
  Display* display = XOpenDisplay(nullptr);
  ASSERT_NE(display, nullptr);
  ::Window target = 0;
  for (int attempt = 0; attempt < 40 && target == 0; ++attempt) {
    (*context)->PollEvents();
    target = FindWindowNamed(display, DefaultRootWindow(display), options.title);
    if (target == 0) std::this_thread::sleep_for(std::chrono::milliseconds(25));
  }
  ASSERT_NE(target, 0u) << "no window named '" << options.title << "'";
  for (unsigned button : {Button3, Button1}) {  // the right button is not a tap
    XButtonEvent press = {};
    press.type = ButtonPress;
    press.display = display;
    press.window = target;
    press.root = DefaultRootWindow(display);
    press.x = 123;
    press.y = 45;
    press.button = button;
    press.same_screen = True;
    XSendEvent(display, target, True, ButtonPressMask, reinterpret_cast<XEvent*>(&press));
  }
  XSync(display, False);
  std::vector<std::array<int, 2>> taps;
  for (int attempt = 0; attempt < 40 && taps.empty(); ++attempt) {
    const WindowEvents events = (*context)->PollEvents();
    taps.insert(taps.end(), events.taps.begin(), events.taps.end());
    if (taps.empty()) std::this_thread::sleep_for(std::chrono::milliseconds(25));
  }
  ASSERT_EQ(taps.size(), 1u);
  EXPECT_EQ(taps[0][0], 123);
  EXPECT_EQ(taps[0][1], 45);
  XCloseDisplay(display);
}

}  // namespace
}  // namespace reconar
