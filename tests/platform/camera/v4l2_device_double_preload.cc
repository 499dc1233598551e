// The V4L2 device double (v4l2_device_double.h) in a process it is LD_PRELOADed into, such as
// `reconar capture v4l2:DEVICE`. Configured by the environment, before main():
//   RECONAR_V4L2_DOUBLE="device=PATH;recording=PATH[;first=N][;frames=N][;disconnect_after=N][;fps=F]"
// A setting it cannot take ends the process with exit code 125 and the reason on stderr.
#include <cstdio>
#include <cstdlib>
#include <sstream>
#include <string>

#include "tests/platform/camera/v4l2_device_double.h"

namespace reconar::testing {
namespace {

[[noreturn]] void Refuse(const std::string& reason) {
  std::fprintf(stderr, "RECONAR_V4L2_DOUBLE: %s\n", reason.c_str());
  std::exit(125);
}

double Number(const std::string& key, const std::string& value) {
  char* end = nullptr;
  const double number = std::strtod(value.c_str(), &end);
  if (value.empty() || *end != '\0') Refuse(key + " expects a number, got '" + value + "'");
  return number;
}

__attribute__((constructor)) void InstallFromEnvironment() {
  const char* setting = std::getenv("RECONAR_V4L2_DOUBLE");
  if (setting == nullptr) return;
  V4L2DeviceDoubleOptions options;
  std::istringstream fields(setting);
  for (std::string field; std::getline(fields, field, ';');) {
    const size_t equals = field.find('=');
    if (equals == std::string::npos) Refuse("'" + field + "' is not KEY=VALUE");
    const std::string key = field.substr(0, equals);
    const std::string value = field.substr(equals + 1);
    if (key == "device") {
      options.device_path = value;
    } else if (key == "recording") {
      options.recording = value;
    } else if (key == "first") {
      options.first_frame = static_cast<int>(Number(key, value));
    } else if (key == "frames") {
      options.num_frames = static_cast<int>(Number(key, value));
    } else if (key == "disconnect_after") {
      options.disconnect_after = static_cast<int>(Number(key, value));
    } else if (key == "fps") {
      options.frames_per_second = Number(key, value);
    } else {
      Refuse("unknown key '" + key + "'");
    }
  }
  const Status installed = InstallV4L2DeviceDouble(options);
  if (!installed.ok()) Refuse(installed.ToString());
}

}  // namespace
}  // namespace reconar::testing
