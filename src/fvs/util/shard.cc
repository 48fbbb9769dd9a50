#include "fvs/util/shard.h"

#include <cctype>

#include "fvs/util/error.h"

namespace fvs {
namespace {

// A non-negative decimal integer, digits only (no sign, no spaces); -1 otherwise.
int ParseCount(const std::string& s) {
  if (s.empty() || s.size() > 9) return -1;
  for (char c : s) {
    if (!std::isdigit(static_cast<unsigned char>(c))) return -1;
  }
  return std::stoi(s);
}

}  // namespace

Shard Shard::Parse(const std::string& spec) {
  Shard shard;
  if (spec.empty()) return shard;
  const size_t slash = spec.find('/');
  const std::string what = "'" + spec + "' is not i/n with 0 <= i < n (e.g. 0/4)";
  Require(slash != std::string::npos, "--shard", what);
  shard.index = ParseCount(spec.substr(0, slash));
  shard.count = ParseCount(spec.substr(slash + 1));
  Require(shard.index >= 0 && shard.count >= 1 && shard.index < shard.count, "--shard",
          what);
  return shard;
}

std::string Shard::ToString() const {
  return std::to_string(index) + "/" + std::to_string(count);
}

std::vector<int> Shard::Items(int total) const {
  std::vector<int> items;
  for (int i = index; i < total; i += count) items.push_back(i);
  return items;
}

}  // namespace fvs
