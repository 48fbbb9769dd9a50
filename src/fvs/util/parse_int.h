// Whole-text integer parsing for option lists ("3", not "3x" nor "" nor "9999999999").
#pragma once

#include <exception>
#include <string>

namespace fvs {

// True, with *value set, when all of `text` is one integer >= 1 that fits an int.
inline bool ParsePositiveInt(const std::string& text, int* value) {
  size_t used = 0;
  int v = 0;
  try {
    v = std::stoi(text, &used);
  } catch (const std::exception&) {
    return false;
  }
  if (used != text.size() || v < 1) return false;
  *value = v;
  return true;
}

}  // namespace fvs
