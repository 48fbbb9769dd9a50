#include "fvs/util/safetensors.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>

#include "fvs/util/atomic_file.h"
#include "fvs/util/error.h"

namespace fvs {
namespace {

// The format is little-endian; so is every machine we build for. Refuse to build
// elsewhere rather than silently writing byte-swapped files.
static_assert(__BYTE_ORDER__ == __ORDER_LITTLE_ENDIAN__,
              "safetensors I/O assumes a little-endian host");

// The reference implementation refuses headers above 100 MB; so do we (a corrupt length
// must not make us allocate gigabytes).
constexpr uint64_t kMaxHeaderBytes = 100u * 1000u * 1000u;

struct DtypeInfo {
  SafeDtype dtype;
  const char* name;
  size_t size;
};

constexpr DtypeInfo kDtypes[] = {
    {SafeDtype::kF64, "F64", 8}, {SafeDtype::kF32, "F32", 4},
    {SafeDtype::kF16, "F16", 2}, {SafeDtype::kBF16, "BF16", 2},
    {SafeDtype::kI64, "I64", 8}, {SafeDtype::kI32, "I32", 4},
    {SafeDtype::kI16, "I16", 2}, {SafeDtype::kI8, "I8", 1},
    {SafeDtype::kU8, "U8", 1},   {SafeDtype::kBool, "BOOL", 1},
};

const DtypeInfo& Info(SafeDtype dtype) {
  for (const DtypeInfo& info : kDtypes) {
    if (info.dtype == dtype) return info;
  }
  return kDtypes[1];  // unreachable: every enumerator is listed
}

// Number of bytes of a tensor, or false when it would overflow (a hostile header).
bool ByteCount(const std::vector<int64_t>& shape, size_t element_size, uint64_t* bytes) {
  uint64_t n = element_size;
  for (int64_t d : shape) {
    if (d < 0) return false;
    if (d != 0 && n > std::numeric_limits<uint64_t>::max() / static_cast<uint64_t>(d)) {
      return false;
    }
    n *= static_cast<uint64_t>(d);
  }
  *bytes = n;
  return true;
}

struct Entry {
  SafeTensor tensor;
  uint64_t begin = 0;
  uint64_t end = 0;
};

Entry ParseEntry(const std::string& name, const nlohmann::json& value,
                 const std::string& subject) {
  const std::string where = "tensor '" + name + "'";
  if (!value.is_object()) throw Error(subject, where + " is not a JSON object");
  for (const char* key : {"dtype", "shape", "data_offsets"}) {
    if (!value.contains(key)) throw Error(subject, where + " has no \"" + key + "\"");
  }
  Entry entry;
  entry.tensor.name = name;
  const nlohmann::json& dtype = value["dtype"];
  if (!dtype.is_string() ||
      !ParseSafeDtype(dtype.get<std::string>(), &entry.tensor.dtype)) {
    throw Error(subject,
                where + " has unknown dtype " + dtype.dump() +
                    " (known: F64, F32, F16, BF16, I64, I32, I16, I8, U8, BOOL)");
  }
  const nlohmann::json& shape = value["shape"];
  if (!shape.is_array()) throw Error(subject, where + " has a shape that is not a list");
  for (const nlohmann::json& d : shape) {
    if (!d.is_number_unsigned()) {
      throw Error(
          subject,
          where + " has a shape entry that is not a non-negative integer: " + d.dump());
    }
    entry.tensor.shape.push_back(static_cast<int64_t>(d.get<uint64_t>()));
  }
  const nlohmann::json& offsets = value["data_offsets"];
  if (!offsets.is_array() || offsets.size() != 2 || !offsets[0].is_number_unsigned() ||
      !offsets[1].is_number_unsigned()) {
    throw Error(subject, where + " needs \"data_offsets\": [begin, end] (non-negative)");
  }
  entry.begin = offsets[0].get<uint64_t>();
  entry.end = offsets[1].get<uint64_t>();
  if (entry.end < entry.begin)
    throw Error(subject, where + " has data_offsets end < begin");
  uint64_t bytes = 0;
  if (!ByteCount(entry.tensor.shape, SafeDtypeSize(entry.tensor.dtype), &bytes)) {
    throw Error(subject,
                where + " has an impossible shape " + ShapeString(entry.tensor.shape));
  }
  if (entry.end - entry.begin != bytes) {
    throw Error(subject, where + " of shape " + ShapeString(entry.tensor.shape) +
                             " and dtype " + SafeDtypeName(entry.tensor.dtype) +
                             " needs " + std::to_string(bytes) +
                             " bytes but data_offsets give " +
                             std::to_string(entry.end - entry.begin));
  }
  return entry;
}

}  // namespace

std::string ShapeString(const std::vector<int64_t>& shape) {
  std::string s = "[";
  for (size_t i = 0; i < shape.size(); ++i) {
    s += (i ? ", " : "") + std::to_string(shape[i]);
  }
  return s + "]";
}

std::string SafeDtypeName(SafeDtype dtype) { return Info(dtype).name; }
size_t SafeDtypeSize(SafeDtype dtype) { return Info(dtype).size; }

bool ParseSafeDtype(const std::string& name, SafeDtype* dtype) {
  for (const DtypeInfo& info : kDtypes) {
    if (name == info.name) {
      *dtype = info.dtype;
      return true;
    }
  }
  return false;
}

int64_t SafeTensor::NumElements() const {
  int64_t n = 1;
  for (int64_t d : shape) n *= d;
  return n;
}

SafeTensor SafeTensor::FromFloats(const std::string& name,
                                  const std::vector<int64_t>& shape,
                                  const float* values) {
  SafeTensor t;
  t.name = name;
  t.dtype = SafeDtype::kF32;
  t.shape = shape;
  t.data.resize(static_cast<size_t>(t.NumElements()) * sizeof(float));
  if (!t.data.empty()) std::memcpy(t.data.data(), values, t.data.size());
  return t;
}

std::vector<float> SafeTensor::ToFloats() const {
  const size_t n = static_cast<size_t>(NumElements());
  if (data.size() != n * SafeDtypeSize(dtype)) {
    throw Error(name, "data size does not match shape and dtype");
  }
  std::vector<float> out(n);
  for (size_t i = 0; i < n; ++i) {
    const uint8_t* p = data.data() + i * SafeDtypeSize(dtype);
    switch (dtype) {
      case SafeDtype::kF32:
        std::memcpy(&out[i], p, 4);
        break;
      case SafeDtype::kF64: {
        double d;
        std::memcpy(&d, p, 8);
        out[i] = static_cast<float>(d);
        break;
      }
      case SafeDtype::kF16:
      case SafeDtype::kBF16: {
        uint16_t bits;
        std::memcpy(&bits, p, 2);
        out[i] = dtype == SafeDtype::kF16 ? HalfToFloat(bits) : BFloat16ToFloat(bits);
        break;
      }
      default:
        throw Error(name,
                    "dtype " + SafeDtypeName(dtype) + " is not a floating-point type");
    }
  }
  return out;
}

const SafeTensor* SafeTensorsFile::Find(const std::string& name) const {
  for (const SafeTensor& t : tensors) {
    if (t.name == name) return &t;
  }
  return nullptr;
}

void SafeTensorsFile::Add(SafeTensor tensor) {
  for (SafeTensor& t : tensors) {
    if (t.name == tensor.name) {
      t = std::move(tensor);
      return;
    }
  }
  tensors.push_back(std::move(tensor));
}

SafeTensorsFile ParseSafeTensors(const std::string& bytes, const std::string& subject) {
  if (bytes.size() < 8) {
    throw Error(subject, "not a safetensors file: " + std::to_string(bytes.size()) +
                             " bytes, shorter than the 8-byte header length");
  }
  uint64_t header_size = 0;
  std::memcpy(&header_size, bytes.data(), 8);
  if (header_size > kMaxHeaderBytes || header_size > bytes.size() - 8) {
    throw Error(subject, "header length " + std::to_string(header_size) +
                             " does not fit in the file of " +
                             std::to_string(bytes.size()) +
                             " bytes (truncated or not a safetensors file)");
  }
  const std::string header = bytes.substr(8, header_size);
  if (header.empty() || header[0] != '{') {
    throw Error(subject, "header does not start with '{' (not a safetensors file)");
  }
  nlohmann::json json;
  try {
    json = nlohmann::json::parse(header);
  } catch (const nlohmann::json::exception& e) {
    throw Error(subject, std::string("header is not valid JSON: ") + e.what());
  }
  if (!json.is_object()) throw Error(subject, "header is not a JSON object");

  SafeTensorsFile file;
  std::vector<Entry> entries;
  for (auto it = json.begin(); it != json.end(); ++it) {
    if (it.key() == "__metadata__") {
      if (!it.value().is_object())
        throw Error(subject, "__metadata__ is not a JSON object");
      for (auto m = it.value().begin(); m != it.value().end(); ++m) {
        if (!m.value().is_string()) {
          throw Error(subject, "__metadata__ value of '" + m.key() + "' is not a string");
        }
        file.metadata[m.key()] = m.value().get<std::string>();
      }
      continue;
    }
    entries.push_back(ParseEntry(it.key(), it.value(), subject));
  }

  // The buffer must be covered exactly: sorted by offset, each tensor starts where the
  // previous one ended, the last ends at the end of the file.
  const uint64_t buffer_size = bytes.size() - 8 - header_size;
  std::sort(entries.begin(), entries.end(), [](const Entry& a, const Entry& b) {
    return a.begin != b.begin ? a.begin < b.begin : a.end < b.end;
  });
  uint64_t expected = 0;
  std::string previous;
  for (const Entry& e : entries) {
    if (e.end > buffer_size) {
      throw Error(subject, "tensor '" + e.tensor.name + "' data_offsets [" +
                               std::to_string(e.begin) + ", " + std::to_string(e.end) +
                               "] run past the data of " + std::to_string(buffer_size) +
                               " bytes (truncated file?)");
    }
    if (e.begin < expected) {
      throw Error(subject,
                  "tensor '" + e.tensor.name + "' overlaps tensor '" + previous + "'");
    }
    if (e.begin > expected) {
      throw Error(subject, "unused bytes before tensor '" + e.tensor.name + "' (offset " +
                               std::to_string(expected) + " to " +
                               std::to_string(e.begin) + ")");
    }
    expected = e.end;
    previous = e.tensor.name;
  }
  if (expected != buffer_size) {
    throw Error(subject,
                std::to_string(buffer_size - expected) +
                    " bytes after the last tensor are not described by the header");
  }
  const char* data = bytes.data() + 8 + header_size;
  for (Entry& e : entries) {
    e.tensor.data.assign(data + e.begin, data + e.end);
    file.tensors.push_back(std::move(e.tensor));
  }
  return file;
}

SafeTensorsFile ReadSafeTensors(const std::string& path) {
  return ParseSafeTensors(ReadFileToString(path), path);
}

std::string SerializeSafeTensors(const SafeTensorsFile& file) {
  std::vector<const SafeTensor*> sorted;
  for (const SafeTensor& t : file.tensors) sorted.push_back(&t);
  std::sort(sorted.begin(), sorted.end(),
            [](const SafeTensor* a, const SafeTensor* b) { return a->name < b->name; });
  // ordered_json keeps our order (metadata first, then tensors by name) in the file.
  nlohmann::ordered_json header = nlohmann::ordered_json::object();
  if (!file.metadata.empty()) {
    nlohmann::ordered_json meta = nlohmann::ordered_json::object();
    for (const auto& [key, value] : file.metadata) meta[key] = value;
    header["__metadata__"] = meta;
  }
  uint64_t offset = 0;
  for (size_t i = 0; i < sorted.size(); ++i) {
    const SafeTensor& t = *sorted[i];
    if (t.name.empty() || t.name == "__metadata__") {
      throw Error("safetensors", "invalid tensor name '" + t.name + "'");
    }
    if (i > 0 && sorted[i - 1]->name == t.name) {
      throw Error("safetensors", "duplicate tensor name '" + t.name + "'");
    }
    uint64_t bytes = 0;
    if (!ByteCount(t.shape, SafeDtypeSize(t.dtype), &bytes) || bytes != t.data.size()) {
      throw Error("safetensors",
                  "tensor '" + t.name + "' holds " + std::to_string(t.data.size()) +
                      " bytes, which does not match shape " + ShapeString(t.shape) +
                      " and dtype " + SafeDtypeName(t.dtype));
    }
    nlohmann::ordered_json entry;
    entry["dtype"] = SafeDtypeName(t.dtype);
    entry["shape"] = t.shape;
    entry["data_offsets"] = {offset, offset + bytes};
    header[t.name] = entry;
    offset += bytes;
  }
  std::string header_text = header.dump();
  header_text.append((8 - header_text.size() % 8) % 8, ' ');
  std::string out;
  out.reserve(8 + header_text.size() + offset);
  const uint64_t n = header_text.size();
  out.append(reinterpret_cast<const char*>(&n), 8);
  out += header_text;
  for (const SafeTensor* t : sorted) {
    out.append(reinterpret_cast<const char*>(t->data.data()), t->data.size());
  }
  return out;
}

void WriteSafeTensors(const std::string& path, const SafeTensorsFile& file) {
  const std::string bytes = SerializeSafeTensors(file);
  WriteFileAtomic(path,
                  [&](std::ostream& out) { out.write(bytes.data(), bytes.size()); });
}

uint16_t FloatToHalf(float value) {
  uint32_t x;
  std::memcpy(&x, &value, 4);
  const uint32_t sign = (x >> 16) & 0x8000u;
  uint32_t mantissa = x & 0x007fffffu;
  const int32_t exponent = static_cast<int32_t>((x >> 23) & 0xffu);
  if (exponent == 0xff) {  // inf stays inf, NaN stays a (quiet) NaN
    return static_cast<uint16_t>(sign | 0x7c00u | (mantissa ? 0x200u : 0u));
  }
  const int32_t e = exponent - 127 + 15;
  if (e >= 31) return static_cast<uint16_t>(sign | 0x7c00u);
  if (e <= 0) {  // half subnormal (or zero): value = m * 2^-24
    const int32_t shift = 14 - e;
    if (shift > 24) return static_cast<uint16_t>(sign);
    mantissa |= 0x00800000u;
    uint32_t m = mantissa >> shift;
    const uint32_t rest = mantissa & ((1u << shift) - 1u);
    const uint32_t half = 1u << (shift - 1);
    if (rest > half || (rest == half && (m & 1u))) ++m;
    return static_cast<uint16_t>(sign | m);
  }
  uint32_t h = sign | (static_cast<uint32_t>(e) << 10) | (mantissa >> 13);
  const uint32_t rest = mantissa & 0x1fffu;
  // Round to nearest even; a carry into the exponent is the correct result (up to inf).
  if (rest > 0x1000u || (rest == 0x1000u && (h & 1u))) ++h;
  return static_cast<uint16_t>(h);
}

float HalfToFloat(uint16_t bits) {
  const uint32_t sign = (static_cast<uint32_t>(bits) & 0x8000u) << 16;
  const uint32_t exponent = (bits >> 10) & 0x1fu;
  const uint32_t mantissa = bits & 0x3ffu;
  uint32_t x;
  if (exponent == 0) {
    const float magnitude = std::ldexp(static_cast<float>(mantissa), -24);
    return sign ? -magnitude : magnitude;
  } else if (exponent == 31) {
    x = sign | 0x7f800000u | (mantissa << 13);
  } else {
    x = sign | ((exponent + 112u) << 23) | (mantissa << 13);
  }
  float out;
  std::memcpy(&out, &x, 4);
  return out;
}

uint16_t FloatToBFloat16(float value) {
  uint32_t x;
  std::memcpy(&x, &value, 4);
  if ((x & 0x7fffffffu) > 0x7f800000u) return static_cast<uint16_t>((x >> 16) | 0x40u);
  x += 0x7fffu + ((x >> 16) & 1u);
  return static_cast<uint16_t>(x >> 16);
}

float BFloat16ToFloat(uint16_t bits) {
  const uint32_t x = static_cast<uint32_t>(bits) << 16;
  float out;
  std::memcpy(&out, &x, 4);
  return out;
}

}  // namespace fvs
