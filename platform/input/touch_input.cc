#include "platform/input/touch_input.h"

#include <fcntl.h>
#include <linux/input.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <filesystem>

namespace reconar {

TouchTapDecoder::TouchTapDecoder(TouchAxisRange x, TouchAxisRange y, int screen_width, int screen_height)
    : x_range_(x), y_range_(y), screen_width_(screen_width), screen_height_(screen_height) {}

int TouchTapDecoder::Scale(int value, const TouchAxisRange& range, int pixels) const {
  if (range.maximum <= range.minimum || pixels <= 0) return value;
  const double share = static_cast<double>(value - range.minimum) / (range.maximum - range.minimum);
  return std::clamp(static_cast<int>(share * (pixels - 1) + 0.5), 0, pixels - 1);
}

void TouchTapDecoder::Feed(uint16_t type, uint16_t code, int32_t value, std::vector<std::array<int, 2>>* taps) {
  if (type == EV_ABS) {
    if (code == ABS_X || (code == ABS_MT_POSITION_X && (slot_ == 0 || contacts_ <= 1))) x_ = value;
    if (code == ABS_Y || (code == ABS_MT_POSITION_Y && (slot_ == 0 || contacts_ <= 1))) y_ = value;
    if (code == ABS_MT_SLOT) slot_ = std::max(0, value);
    if (code == ABS_MT_TRACKING_ID) {
      if (tracking_.size() <= static_cast<size_t>(slot_)) tracking_.resize(static_cast<size_t>(slot_) + 1, -1);
      int& id = tracking_[static_cast<size_t>(slot_)];
      if (value >= 0 && id < 0) {
        ++contacts_;
        if (contacts_ == 1 && !down_) {
          down_ = true;
          contact_started_ = true;
        }
      } else if (value < 0 && id >= 0) {
        contacts_ = std::max(0, contacts_ - 1);
        if (contacts_ == 0) down_ = false;
      }
      id = value;
    }
  } else if (type == EV_KEY && code == BTN_TOUCH) {
    if (value == 1 && !down_) {
      down_ = true;
      contact_started_ = true;
    } else if (value == 0) {
      down_ = false;
      contacts_ = 0;
      std::fill(tracking_.begin(), tracking_.end(), -1);
    }
  } else if (type == EV_SYN && code == SYN_REPORT && contact_started_) {
    contact_started_ = false;
    taps->push_back({Scale(x_, x_range_, screen_width_), Scale(y_, y_range_, screen_height_)});
  }
}

namespace {

bool HasBit(const unsigned long* bits, int bit) {
  constexpr int kBitsPerLong = 8 * sizeof(unsigned long);
  return (bits[bit / kBitsPerLong] >> (bit % kBitsPerLong)) & 1UL;
}

}  // namespace

Result<std::unique_ptr<TouchInput>> TouchInput::Open(int screen_width, int screen_height, const std::string& device) {
  std::vector<std::string> candidates;
  if (!device.empty()) {
    candidates.push_back(device);
  } else {
    std::error_code error;
    for (const auto& entry : std::filesystem::directory_iterator("/dev/input", error)) {
      if (entry.path().filename().string().rfind("event", 0) == 0) candidates.push_back(entry.path().string());
    }
    std::sort(candidates.begin(), candidates.end());
  }
  std::string refused;
  for (const std::string& path : candidates) {
    const int fd = ::open(path.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC);
    if (fd < 0) {
      if (errno == EACCES && refused.empty()) refused = path;
      continue;
    }
    unsigned long keys[KEY_MAX / (8 * sizeof(unsigned long)) + 1] = {};
    unsigned long axes[ABS_MAX / (8 * sizeof(unsigned long)) + 1] = {};
    const bool touch = ioctl(fd, EVIOCGBIT(EV_KEY, sizeof(keys)), keys) >= 0 &&
                       ioctl(fd, EVIOCGBIT(EV_ABS, sizeof(axes)), axes) >= 0 && HasBit(keys, BTN_TOUCH) &&
                       ((HasBit(axes, ABS_X) && HasBit(axes, ABS_Y)) ||
                        (HasBit(axes, ABS_MT_POSITION_X) && HasBit(axes, ABS_MT_POSITION_Y)));
    if (!touch) {
      ::close(fd);
      continue;
    }
    const bool multi = HasBit(axes, ABS_MT_POSITION_X);
    input_absinfo x{}, y{};
    ioctl(fd, EVIOCGABS(multi ? ABS_MT_POSITION_X : ABS_X), &x);
    ioctl(fd, EVIOCGABS(multi ? ABS_MT_POSITION_Y : ABS_Y), &y);
    const TouchTapDecoder decoder({x.minimum, x.maximum}, {y.minimum, y.maximum}, screen_width, screen_height);
    return std::unique_ptr<TouchInput>(new TouchInput(fd, path, decoder));
  }
  if (!refused.empty()) {
    return FailedPrecondition(refused + ": no permission to read input devices (join the input group)");
  }
  return NotFound(device.empty() ? "no touch screen under /dev/input" : device + " is not a touch screen");
}

TouchInput::TouchInput(int fd, std::string device, const TouchTapDecoder& decoder)
    : fd_(fd), device_(std::move(device)), decoder_(decoder) {}

TouchInput::~TouchInput() { ::close(fd_); }

void TouchInput::Poll(std::vector<std::array<int, 2>>* taps) {
  input_event events[64];
  for (;;) {
    const ssize_t got = ::read(fd_, events, sizeof(events));
    if (got <= 0) return;  // nothing more now (EAGAIN), or the device went away
    for (size_t k = 0; k < static_cast<size_t>(got) / sizeof(input_event); ++k) {
      decoder_.Feed(events[k].type, events[k].code, events[k].value, taps);
    }
  }
}

}  // namespace reconar
