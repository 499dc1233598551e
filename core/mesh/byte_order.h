#pragma once
// Internal to core/mesh: the little-endian values of binary PLY and glTF, on hosts of either order.
#include <algorithm>
#include <cstdint>
#include <cstring>
#include <string>

namespace reconar::mesh_internal {

inline bool HostIsLittleEndian() {
  const uint16_t one = 1;
  uint8_t first;
  std::memcpy(&first, &one, 1);
  return first == 1;
}

// sizeof(T) bytes at `data`, byte-reversed when `swap` is set.
template <typename T>
T LoadBytes(const char* data, bool swap) {
  uint8_t bytes[sizeof(T)];
  std::memcpy(bytes, data, sizeof(T));
  if (swap) std::reverse(bytes, bytes + sizeof(T));
  T value;
  std::memcpy(&value, bytes, sizeof(T));
  return value;
}

template <typename T>
T LoadLittleEndian(const char* data) {
  return LoadBytes<T>(data, !HostIsLittleEndian());
}

template <typename T>
void AppendLittleEndian(std::string* out, T value) {
  uint8_t bytes[sizeof(T)];
  std::memcpy(bytes, &value, sizeof(T));
  if (!HostIsLittleEndian()) std::reverse(bytes, bytes + sizeof(T));
  out->append(reinterpret_cast<const char*>(bytes), sizeof(T));
}

}  // namespace reconar::mesh_internal
