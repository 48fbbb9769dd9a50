// One slice of a long job for batch schedulers (Slurm array jobs, Kubernetes indexed
// Jobs): `--shard i/n` keeps every n-th item starting at item i (0-based), so n machines
// given 0/n .. (n-1)/n together cover every item exactly once, each with a similar mix
// of easy and hard items (a path's frames, an evaluation's targets).
#pragma once

#include <string>
#include <vector>

namespace fvs {

struct Shard {
  int index = 0;  // i, 0 <= i < count
  int count = 1;  // n >= 1; 1 = everything

  // Parses "i/n" (an empty string = 0/1). Throws fvs::Error("--shard", ...) otherwise.
  static Shard Parse(const std::string& spec);
  bool Contains(int item) const { return item % count == index; }
  bool IsAll() const { return count == 1; }
  std::string ToString() const;  // "i/n"
  // The items of [0, total) that this shard renders, ascending.
  std::vector<int> Items(int total) const;
};

}  // namespace fvs
