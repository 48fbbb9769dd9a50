// Internal to the PLY reader and writer: the header model (elements, typed properties)
// and the scalar types. Not part of the public API; use fvs/geometry/ply.h.
#pragma once

#include <cstdint>
#include <cstring>
#include <string>
#include <vector>

namespace fvs::ply_internal {

enum class PlyType : uint8_t {
  kInt8,
  kUint8,
  kInt16,
  kUint16,
  kInt32,
  kUint32,
  kFloat32,
  kFloat64
};

enum class Encoding { kAscii, kBinaryLittleEndian, kBinaryBigEndian };

struct PlyProperty {
  std::string name;
  bool is_list = false;
  PlyType type = PlyType::kFloat32;      // the value (or list item) type
  PlyType count_type = PlyType::kUint8;  // lists only
};

struct PlyElement {
  std::string name;
  uint64_t count = 0;
  std::vector<PlyProperty> properties;
};

struct PlyHeader {
  Encoding encoding = Encoding::kAscii;
  std::vector<PlyElement> elements;
  size_t body_offset = 0;  // first byte after "end_header\n"
};

// Both spellings: char/uchar/short/ushort/int/uint/float/double and int8..float64.
bool ParsePlyType(const std::string& name, PlyType* type);
int TypeSize(PlyType type);

// Parses the header at the start of `data` (the whole file). Throws fvs::Error(path, ...)
// on a wrong magic number, an unknown format, a malformed line or a missing end_header.
PlyHeader ParsePlyHeader(const std::string& path, const std::string& data);

constexpr Encoding NativeBinaryEncoding() {
#if defined(__BYTE_ORDER__) && __BYTE_ORDER__ == __ORDER_BIG_ENDIAN__
  return Encoding::kBinaryBigEndian;
#else
  return Encoding::kBinaryLittleEndian;
#endif
}

// Value of a scalar stored in native byte order at `bytes`.
inline double DecodeNative(const unsigned char* bytes, PlyType type) {
  switch (type) {
    case PlyType::kInt8: {
      int8_t v;
      std::memcpy(&v, bytes, 1);
      return v;
    }
    case PlyType::kUint8:
      return bytes[0];
    case PlyType::kInt16: {
      int16_t v;
      std::memcpy(&v, bytes, 2);
      return v;
    }
    case PlyType::kUint16: {
      uint16_t v;
      std::memcpy(&v, bytes, 2);
      return v;
    }
    case PlyType::kInt32: {
      int32_t v;
      std::memcpy(&v, bytes, 4);
      return v;
    }
    case PlyType::kUint32: {
      uint32_t v;
      std::memcpy(&v, bytes, 4);
      return v;
    }
    case PlyType::kFloat32: {
      float v;
      std::memcpy(&v, bytes, 4);
      return v;
    }
    case PlyType::kFloat64: {
      double v;
      std::memcpy(&v, bytes, 8);
      return v;
    }
  }
  return 0;
}

}  // namespace fvs::ply_internal
