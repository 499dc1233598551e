// X11 window output: one top-level window whose visual matches the EGL config, with
// WM_DELETE_WINDOW so that the close button becomes an event instead of killing the connection.
#include <EGL/egl.h>
#include <EGL/eglext.h>

#include <cstdlib>
#include <string>

#include "platform/egl/native_output.h"

// Xlib defines macros named Status, Bool, None...: include it last and drop the clashing one.
#include <X11/Xlib.h>
#include <X11/Xutil.h>
#include <X11/keysym.h>
#undef Status

namespace reconar {
namespace {

class X11Window final : public NativeOutput {
 public:
  X11Window(Display* display, int width, int height, std::string title)
      : display_(display), width_(width), height_(height), title_(std::move(title)) {}
  ~X11Window() override {
    if (window_ != 0) XDestroyWindow(display_, window_);
    if (colormap_ != 0) XFreeColormap(display_, colormap_);
    XCloseDisplay(display_);
  }

  EGLenum platform() const override { return EGL_PLATFORM_X11_KHR; }
  void* native_display() const override { return display_; }
  int width() const override { return width_; }
  int height() const override { return height_; }
  void* native_window() override { return &window_; }

  reconar::Status CreateWindow(EGLint visual_id) override {
    XVisualInfo wanted{};
    wanted.visualid = static_cast<VisualID>(visual_id);
    int count = 0;
    XVisualInfo* visual = XGetVisualInfo(display_, VisualIDMask, &wanted, &count);
    if (visual == nullptr || count == 0) {
      return FailedPrecondition("X11: no visual with id " + std::to_string(visual_id) + " for the EGL config");
    }
    const ::Window root = RootWindow(display_, visual->screen);
    colormap_ = XCreateColormap(display_, root, visual->visual, AllocNone);
    XSetWindowAttributes attributes{};
    attributes.colormap = colormap_;
    attributes.event_mask = KeyPressMask | ButtonPressMask | StructureNotifyMask | ExposureMask;
    window_ = XCreateWindow(display_, root, 0, 0, static_cast<unsigned>(width_), static_cast<unsigned>(height_), 0,
                            visual->depth, InputOutput, visual->visual, CWColormap | CWEventMask, &attributes);
    XFree(visual);
    if (window_ == 0) return FailedPrecondition("X11: XCreateWindow failed");
    XStoreName(display_, window_, title_.c_str());
    delete_atom_ = XInternAtom(display_, "WM_DELETE_WINDOW", False);
    XSetWMProtocols(display_, window_, &delete_atom_, 1);
    XMapWindow(display_, window_);
    XFlush(display_);
    return reconar::Status::Ok();
  }

  WindowEvents PollEvents() override {
    WindowEvents events;
    while (XPending(display_) > 0) {
      XEvent event;
      XNextEvent(display_, &event);
      if (event.type == ClientMessage && static_cast<Atom>(event.xclient.data.l[0]) == delete_atom_) {
        events.close_requested = true;
      } else if (event.type == KeyPress) {
        const KeySym key = XLookupKeysym(&event.xkey, 0);
        if (key == XK_q || key == XK_Escape) events.quit_key = true;
        if (key == XK_space || key == XK_l) ++events.next_layer_presses;
      } else if (event.type == ButtonPress && event.xbutton.button == Button1) {
        events.taps.push_back({event.xbutton.x, event.xbutton.y});
      } else if (event.type == ConfigureNotify) {
        if (event.xconfigure.width != width_ || event.xconfigure.height != height_) {
          width_ = event.xconfigure.width;
          height_ = event.xconfigure.height;
          events.resized = true;
        }
      } else if (event.type == DestroyNotify) {
        events.close_requested = true;
      }
    }
    return events;
  }

 private:
  Display* display_;
  int width_;
  int height_;
  std::string title_;
  ::Window window_ = 0;
  Colormap colormap_ = 0;
  Atom delete_atom_ = 0;
};

}  // namespace

Result<std::unique_ptr<NativeOutput>> OpenX11Window(int width, int height, const std::string& title) {
  const char* name = std::getenv("DISPLAY");
  Display* display = XOpenDisplay(nullptr);
  if (display == nullptr) {
    return FailedPrecondition(std::string("EGL x11: cannot open X display \"") + (name ? name : "") + "\"" +
                              (name == nullptr || name[0] == '\0' ? " (DISPLAY is not set)" : ""));
  }
  return std::unique_ptr<NativeOutput>(new X11Window(display, width, height, title));
}

}  // namespace reconar
