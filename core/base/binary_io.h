#pragma once
// Little-endian binary records for our own file formats (the map file, core/sfm/localization_map.h):
// ByteWriter appends plain values to a string; ByteReader walks a byte span and refuses, without
// reading past the end, any value or count the bytes cannot hold. Crc32 is the IEEE 802.3 CRC
// (zlib's crc32) that checksums a file's payload. Both targets (x86-64, aarch64) are little-endian,
// so values are copied as they lie in memory.

#include <cstddef>
#include <cstdint>
#include <cstring>
#include <string>
#include <string_view>
#include <type_traits>

namespace reconar {

static_assert(__BYTE_ORDER__ == __ORDER_LITTLE_ENDIAN__, "binary_io assumes a little-endian host");

// CRC-32 (IEEE, reflected, polynomial 0xEDB88320), continuing from `crc` (0 to start).
uint32_t Crc32(const void* data, size_t size, uint32_t crc = 0);

class ByteWriter {
 public:
  template <typename T>
  void Put(const T& value) {
    static_assert(std::is_trivially_copyable_v<T>, "Put takes plain values");
    PutBytes(&value, sizeof(T));
  }
  void PutBytes(const void* data, size_t size) { bytes_.append(static_cast<const char*>(data), size); }
  // uint32 length, then the characters.
  void PutString(std::string_view text) {
    Put(static_cast<uint32_t>(text.size()));
    PutBytes(text.data(), text.size());
  }
  const std::string& bytes() const { return bytes_; }
  std::string& bytes() { return bytes_; }

 private:
  std::string bytes_;
};

// Every Get returns false (and leaves the output unchanged) when the bytes left are too few; the
// reader then stays failed, so a parser may check ok() once after a group of reads.
class ByteReader {
 public:
  explicit ByteReader(std::string_view bytes) : bytes_(bytes) {}

  template <typename T>
  bool Get(T* value) {
    static_assert(std::is_trivially_copyable_v<T>, "Get takes plain values");
    return GetBytes(value, sizeof(T));
  }
  bool GetBytes(void* out, size_t size) {
    if (!ok_ || size > remaining()) return ok_ = false;
    if (size == 0) return true;  // `out` may be the null data() of an empty vector
    std::memcpy(out, bytes_.data() + position_, size);
    position_ += size;
    return true;
  }
  // A uint32 count whose `element_bytes` * count fits in what is left (and is at most max_count):
  // the guard that keeps a damaged count from allocating gigabytes.
  bool GetCount(size_t element_bytes, uint32_t max_count, uint32_t* count) {
    uint32_t n = 0;
    if (!Get(&n)) return false;
    if (n > max_count || (element_bytes > 0 && n > remaining() / element_bytes)) return ok_ = false;
    *count = n;
    return true;
  }
  bool GetString(uint32_t max_size, std::string* text) {
    uint32_t n = 0;
    if (!GetCount(1, max_size, &n)) return false;
    text->assign(bytes_.data() + position_, n);
    position_ += n;
    return true;
  }
  // Pointer to the next `size` bytes without copying them.
  bool Skip(size_t size, const char** data) {
    if (!ok_ || size > remaining()) return ok_ = false;
    *data = bytes_.data() + position_;
    position_ += size;
    return true;
  }

  bool ok() const { return ok_; }
  size_t position() const { return position_; }
  size_t remaining() const { return bytes_.size() - position_; }

 private:
  std::string_view bytes_;
  size_t position_ = 0;
  bool ok_ = true;
};

}  // namespace reconar
