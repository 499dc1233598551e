#pragma once
// Taps from a touch screen through evdev (Linux input events), for the full-screen DRM/KMS output
// where no window system delivers them (under X11 a touch arrives as a click: x11_window.cc).
//
// TouchTapDecoder turns a device's event stream into taps: a touch's first contact (BTN_TOUCH going
// to 1, or a multi-touch slot taking a tracking id) at its position when the SYN_REPORT that closes
// the contact's packet arrives, scaled from the device's axis ranges to the screen's pixels. Later
// contacts of the same touch (a finger sliding) and other fingers while one is down are not taps.
// TouchInput finds the device and feeds the decoder without blocking.
#include <array>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "core/base/status.h"

namespace reconar {

struct TouchAxisRange {
  int minimum = 0;
  int maximum = 0;
};

class TouchTapDecoder {
 public:
  TouchTapDecoder(TouchAxisRange x, TouchAxisRange y, int screen_width, int screen_height);

  // One input_event (type, code, value); a tap the event completes is appended to *taps, in screen
  // pixels (row 0 at the top).
  void Feed(uint16_t type, uint16_t code, int32_t value, std::vector<std::array<int, 2>>* taps);

 private:
  int Scale(int value, const TouchAxisRange& range, int pixels) const;

  TouchAxisRange x_range_, y_range_;
  int screen_width_, screen_height_;
  int x_ = 0, y_ = 0;          // the latest position reported
  bool down_ = false;          // a touch is on the screen
  bool contact_started_ = false;  // it began in this packet: a tap at the next SYN_REPORT
  int contacts_ = 0;           // multi-touch slots with a tracking id
  int slot_ = 0;
  std::vector<int> tracking_;  // per slot: its tracking id, -1 free
};

class TouchInput {
 public:
  // The first /dev/input/event* (or `device` when not empty) that reports absolute x/y and
  // BTN_TOUCH, opened non-blocking. NotFound when there is none, naming where it looked;
  // FailedPrecondition for one that cannot be read (permissions: the input group).
  static Result<std::unique_ptr<TouchInput>> Open(int screen_width, int screen_height, const std::string& device = "");
  ~TouchInput();

  const std::string& device() const { return device_; }
  // Reads what has arrived; appends the taps it completes.
  void Poll(std::vector<std::array<int, 2>>* taps);

 private:
  TouchInput(int fd, std::string device, const TouchTapDecoder& decoder);
  int fd_;
  std::string device_;
  TouchTapDecoder decoder_;
};

}  // namespace reconar
