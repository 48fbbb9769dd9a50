// The safetensors container (https://github.com/huggingface/safetensors), read and
// written without any tensor library so that every stage (weights, the packed training
// set) can use it:
//
//   8 bytes   N, unsigned little-endian: length of the header
//   N bytes   JSON: {"<name>": {"dtype": "F32", "shape": [2, 3],
//                               "data_offsets": [b, e]}, ...,
//                    "__metadata__": {"key": "string value", ...}}   (space-padded)
//   rest      the byte buffer; tensor data is raw little-endian, row-major, at [b, e)
//
// The reader checks everything against the file size before trusting it: offsets inside
// the buffer, byte counts equal to shape x dtype size, no overlap and no hole (as the
// reference implementation requires), known dtypes. Every problem is one fvs::Error
// naming the file.
#pragma once

#include <cstddef>
#include <cstdint>
#include <map>
#include <string>
#include <vector>

namespace fvs {

enum class SafeDtype { kF64, kF32, kF16, kBF16, kI64, kI32, kI16, kI8, kU8, kBool };

// "[2, 3]": a shape in error messages.
std::string ShapeString(const std::vector<int64_t>& shape);

// "F32", "BF16", ... as in the format.
std::string SafeDtypeName(SafeDtype dtype);
size_t SafeDtypeSize(SafeDtype dtype);
// Returns false for a name the format does not define (or that we do not read).
bool ParseSafeDtype(const std::string& name, SafeDtype* dtype);

struct SafeTensor {
  std::string name;
  SafeDtype dtype = SafeDtype::kF32;
  std::vector<int64_t> shape;  // empty: a scalar (one element)
  std::vector<uint8_t> data;   // raw little-endian bytes, row-major

  int64_t NumElements() const;
  // Convenience for fp32 data (copies the floats in/out; the dtype must be F32 to read).
  static SafeTensor FromFloats(const std::string& name, const std::vector<int64_t>& shape,
                               const float* values);
  // Any floating dtype (F64, F32, F16, BF16) converted to float; throws fvs::Error
  // otherwise.
  std::vector<float> ToFloats() const;
};

struct SafeTensorsFile {
  std::vector<SafeTensor> tensors;  // in the order of their data in the buffer
  std::map<std::string, std::string> metadata;  // "__metadata__": string -> string only

  const SafeTensor* Find(const std::string& name) const;
  // Adds or replaces a tensor of that name.
  void Add(SafeTensor tensor);
};

// Parses a whole file held in memory; `subject` names it in errors.
SafeTensorsFile ParseSafeTensors(const std::string& bytes, const std::string& subject);
SafeTensorsFile ReadSafeTensors(const std::string& path);

// The file's bytes: tensors sorted by name, header padded with spaces to a multiple of 8
// so that the data of every tensor starts 8-byte aligned (as the Python writer does).
// Throws fvs::Error for duplicate names, a name "__metadata__", or data whose size does
// not match.
std::string SerializeSafeTensors(const SafeTensorsFile& file);
// Atomic (temp file + rename).
void WriteSafeTensors(const std::string& path, const SafeTensorsFile& file);

// IEEE half and bfloat16 conversions (round to nearest even; overflow -> +/-inf for
// half).
uint16_t FloatToHalf(float value);
float HalfToFloat(uint16_t bits);
uint16_t FloatToBFloat16(float value);
float BFloat16ToFloat(uint16_t bits);

}  // namespace fvs
