// Integers from JSON files written by users or other tools. nlohmann's get<int>() casts
// a double such as 1e30 to int, which is undefined behaviour, and wraps an integer such
// as 4294967297 to 1 silently (both reproduced by tests/fuzz/camera_path_fuzzer).
#pragma once

#include <cmath>
#include <nlohmann/json.hpp>

namespace fvs {

// True, with *out set, when `value` is a number holding a whole value in [min, max]
// (5 and 5.0 both; not 5.5, "5", 1e30).
inline bool JsonToInt(const nlohmann::json& value, int min, int max, int* out) {
  if (!value.is_number()) return false;
  const double d = value.get<double>();
  if (!(d >= min && d <= max) || d != std::floor(d)) return false;
  *out = static_cast<int>(d);
  return true;
}

}  // namespace fvs
