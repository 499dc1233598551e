// The capture's window (render/ar/capture_window.h) on a real X server: the picture shown upright
// on the screen, a picture of another size shown too, 'q' in the window asks to stop, and no
// display refused with a clear message. Runs only with an X server (scripts/test.sh runs the
// tests under xvfb-run when it is installed); skipped otherwise.
#include "render/ar/capture_window.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <chrono>
#include <cstdlib>
#include <string>
#include <thread>

// Last: X11's macros (Status, None) clash with names in the headers above.
#include <X11/Xlib.h>
#include <X11/Xutil.h>
#include <X11/keysym.h>
#undef Status

namespace reconar {
namespace {

bool HaveDisplay() {
  const char* display = std::getenv("DISPLAY");
  return display != nullptr && display[0] != '\0';
}

// A picture whose top half is red and bottom half blue.
Image<uint8_t> RedOverBlue(int width, int height) {
  Image<uint8_t> image(width, height, 3);
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      uint8_t* pixel = image.row(y) + 3 * x;
      pixel[0] = y < height / 2 ? 255 : 0;
      pixel[1] = 0;
      pixel[2] = y < height / 2 ? 0 : 255;
    }
  }
  return image;
}

struct ScreenColours {
  long red = 0, blue = 0;
  double red_mean_y = 0.0, blue_mean_y = 0.0;
};

// Pure red and pure blue pixels on the whole screen, read back from the X server.
ScreenColours ReadScreen(Display* display) {
  XSync(display, False);
  const Window root = DefaultRootWindow(display);
  XWindowAttributes attributes;
  XGetWindowAttributes(display, root, &attributes);
  XImage* image = XGetImage(display, root, 0, 0, static_cast<unsigned>(attributes.width),
                            static_cast<unsigned>(attributes.height), AllPlanes, ZPixmap);
  ScreenColours colours;
  if (image == nullptr) return colours;
  if (image->red_mask == 0 || image->green_mask == 0 || image->blue_mask == 0) {  // not a true-colour screen
    XDestroyImage(image);
    return colours;
  }
  for (int y = 0; y < attributes.height; ++y) {
    for (int x = 0; x < attributes.width; ++x) {
      const unsigned long pixel = XGetPixel(image, x, y);
      const unsigned long r = (pixel & image->red_mask) >> __builtin_ctzl(image->red_mask);
      const unsigned long g = (pixel & image->green_mask) >> __builtin_ctzl(image->green_mask);
      const unsigned long b = (pixel & image->blue_mask) >> __builtin_ctzl(image->blue_mask);
      if (r == 255 && g == 0 && b == 0) {
        ++colours.red;
        colours.red_mean_y += y;
      } else if (r == 0 && g == 0 && b == 255) {
        ++colours.blue;
        colours.blue_mean_y += y;
      }
    }
  }
  XDestroyImage(image);
  if (colours.red > 0) colours.red_mean_y /= static_cast<double>(colours.red);
  if (colours.blue > 0) colours.blue_mean_y /= static_cast<double>(colours.blue);
  return colours;
}

// Shows the picture until the screen holds about `each` pixels of red and of blue (the server
// draws asynchronously, so the screen may still show the picture before), at most ~2 s.
ScreenColours ShowAndRead(CaptureWindow* window, const Image<uint8_t>& picture, Display* display, long each) {
  auto near = [each](long count) { return count >= each * 9 / 10 && count <= each * 11 / 10; };
  ScreenColours colours;
  for (int attempt = 0; attempt < 40; ++attempt) {
    const Result<bool> shown = window->Show(picture);
    EXPECT_TRUE(shown.ok()) << shown.status().ToString();
    colours = ReadScreen(display);
    if (near(colours.red) && near(colours.blue)) break;
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  return colours;
}

Window FindWindowNamed(Display* display, Window parent, const std::string& name) {
  char* window_name = nullptr;
  if (XFetchName(display, parent, &window_name) && window_name != nullptr) {
    const bool match = name == window_name;
    XFree(window_name);
    if (match) return parent;
  }
  Window root_return, parent_return, *children = nullptr;
  unsigned count = 0;
  if (!XQueryTree(display, parent, &root_return, &parent_return, &children, &count)) return 0;
  Window found = 0;
  for (unsigned i = 0; i < count && found == 0; ++i) found = FindWindowNamed(display, children[i], name);
  if (children != nullptr) XFree(children);
  return found;
}

TEST(CaptureWindow, ThePictureIsOnTheScreenUprightAndQStops) {
  if (!HaveDisplay()) GTEST_SKIP() << "DISPLAY is not set";
  Display* display = XOpenDisplay(nullptr);
  ASSERT_NE(display, nullptr);
  // A title of its own: 'q' must reach this window, not another test's on the same X server.
  const std::string title = "reconar capture test " + std::to_string(::getpid());
  auto window = CaptureWindow::Open(EglContextKind::kX11Window, 400, 300, title);
  ASSERT_TRUE(window.ok()) << window.status().ToString();
  EXPECT_NE((*window)->Describe().find("x11"), std::string::npos) << (*window)->Describe();

  // 320 x 240 fills the 400 x 300 window: 400 x 150 of each colour.
  ScreenColours colours = ShowAndRead(window->get(), RedOverBlue(320, 240), display, 400 * 150);
  EXPECT_GE(colours.red, 400 * 150 * 9 / 10);
  EXPECT_GE(colours.blue, 400 * 150 * 9 / 10);
  EXPECT_LT(colours.red_mean_y, colours.blue_mean_y) << "the picture's top (red) must be at the top";

  // A picture of another size (a camera that changed mode) is letterboxed into the same window:
  // 640 x 160 scaled to 400 x 100.
  colours = ShowAndRead(window->get(), RedOverBlue(640, 160), display, 400 * 50);
  EXPECT_GE(colours.red, 400 * 50 * 9 / 10);
  EXPECT_LE(colours.red, 400 * 50 * 11 / 10);
  EXPECT_LT(colours.red_mean_y, colours.blue_mean_y);

  // 'q' pressed in the window: the next Show says stop.
  const Window target = FindWindowNamed(display, DefaultRootWindow(display), title);
  ASSERT_NE(target, 0u) << "no window named '" << title << "'";
  XKeyEvent key = {};
  key.type = KeyPress;
  key.display = display;
  key.window = target;
  key.root = DefaultRootWindow(display);
  key.keycode = XKeysymToKeycode(display, XK_q);
  key.same_screen = True;
  XSendEvent(display, target, True, KeyPressMask, reinterpret_cast<XEvent*>(&key));
  XSync(display, False);
  bool stopped = false;
  for (int attempt = 0; attempt < 40 && !stopped; ++attempt) {
    const Result<bool> shown = (*window)->Show(RedOverBlue(320, 240));
    ASSERT_TRUE(shown.ok()) << shown.status().ToString();
    stopped = !*shown;
    if (!stopped) std::this_thread::sleep_for(std::chrono::milliseconds(25));
  }
  EXPECT_TRUE(stopped) << "'q' in the window did not ask to stop";
  XCloseDisplay(display);
}

TEST(CaptureWindow, NoDisplayIsRefusedClearly) {
  const char* saved = std::getenv("DISPLAY");
  const std::string display = saved != nullptr ? saved : "";
  unsetenv("DISPLAY");
  auto window = CaptureWindow::Open(EglContextKind::kX11Window);
  if (!display.empty()) setenv("DISPLAY", display.c_str(), 1);
  ASSERT_FALSE(window.ok());
  EXPECT_EQ(window.status().code(), StatusCode::kFailedPrecondition);
  EXPECT_NE(window.status().message().find("no display for the capture's window"), std::string::npos)
      << window.status().ToString();
  EXPECT_NE(window.status().message().find("--out-preview"), std::string::npos) << window.status().ToString();
}

}  // namespace
}  // namespace reconar
