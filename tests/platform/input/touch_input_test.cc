// TouchTapDecoder on event streams as touch screens send them (the kernel's multi-touch protocol B
// with its single-touch emulation, Documentation/input/multi-touch-protocol.rst, and a plain
// single-touch panel): one tap per touch, where it began, in screen pixels.
#include "platform/input/touch_input.h"

#include <gtest/gtest.h>
#include <linux/input.h>

#include <vector>

namespace reconar {
namespace {

using Taps = std::vector<std::array<int, 2>>;

struct Event {
  uint16_t type, code;
  int32_t value;
};

Taps Decode(TouchTapDecoder* decoder, const std::vector<Event>& events) {
  Taps taps;
  for (const Event& e : events) decoder->Feed(e.type, e.code, e.value, &taps);
  return taps;
}

TEST(TouchTapDecoder, AMultiTouchScreenGivesOneTapPerTouchWhereItBegan) {
  TouchTapDecoder decoder({0, 4095}, {0, 4095}, 800, 480);
  // First finger down at (2048, 1024), then sliding: one tap, at the start.
  const Taps first = Decode(&decoder, {{EV_ABS, ABS_MT_SLOT, 0},
                                       {EV_ABS, ABS_MT_TRACKING_ID, 45},
                                       {EV_ABS, ABS_MT_POSITION_X, 2048},
                                       {EV_ABS, ABS_MT_POSITION_Y, 1024},
                                       {EV_KEY, BTN_TOUCH, 1},
                                       {EV_ABS, ABS_X, 2048},
                                       {EV_ABS, ABS_Y, 1024},
                                       {EV_SYN, SYN_REPORT, 0},
                                       {EV_ABS, ABS_MT_POSITION_X, 2100},
                                       {EV_ABS, ABS_X, 2100},
                                       {EV_SYN, SYN_REPORT, 0}});
  ASSERT_EQ(first.size(), 1u);
  EXPECT_EQ(first[0][0], 400);  // 2048 / 4095 of 799
  EXPECT_EQ(first[0][1], 120);
  // A second finger while the first is down is not a tap; lifting both is not either.
  const Taps second = Decode(&decoder, {{EV_ABS, ABS_MT_SLOT, 1},
                                        {EV_ABS, ABS_MT_TRACKING_ID, 46},
                                        {EV_ABS, ABS_MT_POSITION_X, 300},
                                        {EV_ABS, ABS_MT_POSITION_Y, 300},
                                        {EV_SYN, SYN_REPORT, 0},
                                        {EV_ABS, ABS_MT_TRACKING_ID, -1},
                                        {EV_ABS, ABS_MT_SLOT, 0},
                                        {EV_ABS, ABS_MT_TRACKING_ID, -1},
                                        {EV_KEY, BTN_TOUCH, 0},
                                        {EV_SYN, SYN_REPORT, 0}});
  EXPECT_TRUE(second.empty());
  // The next touch, in the bottom-right corner: a tap there.
  const Taps third = Decode(&decoder, {{EV_ABS, ABS_MT_TRACKING_ID, 47},
                                       {EV_ABS, ABS_MT_POSITION_X, 4095},
                                       {EV_ABS, ABS_MT_POSITION_Y, 4095},
                                       {EV_KEY, BTN_TOUCH, 1},
                                       {EV_SYN, SYN_REPORT, 0}});
  ASSERT_EQ(third.size(), 1u);
  EXPECT_EQ(third[0][0], 799);
  EXPECT_EQ(third[0][1], 479);
}

TEST(TouchTapDecoder, ASingleTouchPanelGivesATapPerPress) {
  TouchTapDecoder decoder({100, 900}, {100, 700}, 640, 480);
  const Taps taps = Decode(&decoder, {{EV_ABS, ABS_X, 500},
                                      {EV_ABS, ABS_Y, 400},
                                      {EV_KEY, BTN_TOUCH, 1},
                                      {EV_SYN, SYN_REPORT, 0},
                                      {EV_KEY, BTN_TOUCH, 0},
                                      {EV_SYN, SYN_REPORT, 0},
                                      {EV_ABS, ABS_X, 100},
                                      {EV_ABS, ABS_Y, 100},
                                      {EV_KEY, BTN_TOUCH, 1},
                                      {EV_SYN, SYN_REPORT, 0}});
  ASSERT_EQ(taps.size(), 2u);
  EXPECT_EQ(taps[0][0], 320);  // (500 - 100) / 800 of 639, rounded
  EXPECT_EQ(taps[0][1], 240);  // (400 - 100) / 600 of 479
  EXPECT_EQ(taps[1][0], 0);
  EXPECT_EQ(taps[1][1], 0);
}

TEST(TouchInput, ADeviceThatIsNotATouchScreenIsRefused) {
  EXPECT_FALSE(TouchInput::Open(800, 480, "/dev/null").ok());
  EXPECT_FALSE(TouchInput::Open(800, 480, "/nonexistent/event0").ok());
}

}  // namespace
}  // namespace reconar
