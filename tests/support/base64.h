#pragma once
// Base64 (RFC 4648, with padding) for tests that write glTF buffers as data: URIs. Test support only.
#include <string>

namespace reconar::testing {

std::string Base64(const std::string& bytes);

// "data:application/octet-stream;base64,..." of the bytes.
inline std::string DataUri(const std::string& bytes) {
  return "data:application/octet-stream;base64," + Base64(bytes);
}

}  // namespace reconar::testing
