// Bounds-checked little-endian reading of a whole file held in memory, and the matching
// writer. Private to colmap_ext. Every read checks the bytes left first, and counts read
// from a header are checked against the bytes left before anything is allocated, so a
// corrupt count cannot ask for terabytes.
#pragma once

#include <cstdint>
#include <cstring>
#include <ostream>
#include <string>
#include <type_traits>

#include "fvs/util/error.h"

namespace fvs::colmap::internal {

static_assert(sizeof(double) == 8 && sizeof(float) == 4, "IEEE 754 types expected");

inline bool HostIsLittleEndian() {
  const uint16_t one = 1;
  uint8_t first;
  std::memcpy(&first, &one, 1);
  return first == 1;
}

template <typename T>
T ByteSwapped(T value) {
  uint8_t bytes[sizeof(T)];
  std::memcpy(bytes, &value, sizeof(T));
  for (size_t i = 0; i < sizeof(T) / 2; ++i)
    std::swap(bytes[i], bytes[sizeof(T) - 1 - i]);
  std::memcpy(&value, bytes, sizeof(T));
  return value;
}

class BinaryReader {
 public:
  BinaryReader(std::string path, std::string data)
      : path_(std::move(path)), data_(std::move(data)) {}

  size_t remaining() const { return data_.size() - pos_; }
  size_t position() const { return pos_; }
  const std::string& path() const { return path_; }

  template <typename T>
  T Read(const char* what) {
    static_assert(std::is_arithmetic<T>::value, "arithmetic types only");
    if (remaining() < sizeof(T)) Truncated(what);
    T value;
    std::memcpy(&value, data_.data() + pos_, sizeof(T));
    pos_ += sizeof(T);
    return HostIsLittleEndian() ? value : ByteSwapped(value);
  }

  // A count from the file, bounded by what the rest of the file can hold when each item
  // takes at least `min_item_bytes`.
  uint64_t ReadCount(const char* what, size_t min_item_bytes) {
    const uint64_t count = Read<uint64_t>(what);
    if (min_item_bytes > 0 && count > remaining() / min_item_bytes) {
      throw Error(path_, std::string("corrupt or truncated file: ") + what + " is " +
                             std::to_string(count) + " but only " +
                             std::to_string(remaining()) + " bytes follow (offset " +
                             std::to_string(pos_ - 8) + ")");
    }
    return count;
  }

  // A null-terminated string.
  std::string ReadCString(const char* what) {
    const size_t end = data_.find('\0', pos_);
    if (end == std::string::npos) Truncated(what);
    std::string s = data_.substr(pos_, end - pos_);
    pos_ = end + 1;
    return s;
  }

  const char* Take(size_t bytes, const char* what) {
    if (remaining() < bytes) Truncated(what);
    const char* p = data_.data() + pos_;
    pos_ += bytes;
    return p;
  }

  void ExpectEnd() const {
    if (remaining() != 0) {
      throw Error(path_, "corrupt file: " + std::to_string(remaining()) +
                             " unexpected trailing bytes at offset " +
                             std::to_string(pos_));
    }
  }

  [[noreturn]] void Fail(const std::string& what) const {
    throw Error(path_, what + " (offset " + std::to_string(pos_) + ")");
  }

 private:
  [[noreturn]] void Truncated(const char* what) const {
    throw Error(path_, std::string("truncated file: ends inside ") + what +
                           " at offset " + std::to_string(pos_));
  }

  std::string path_;
  std::string data_;
  size_t pos_ = 0;
};

template <typename T>
void WriteLE(std::ostream& out, T value) {
  static_assert(std::is_arithmetic<T>::value, "arithmetic types only");
  if (!HostIsLittleEndian()) value = ByteSwapped(value);
  out.write(reinterpret_cast<const char*>(&value), sizeof(T));
}

}  // namespace fvs::colmap::internal
