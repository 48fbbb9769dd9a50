// The record that lets a stage be skipped: for each stage, a fingerprint of its inputs
// (file sizes and modification times, recursively for folders, plus its options) and the
// outputs it produced. A stage is up to date when its fingerprint is unchanged and all
// its outputs exist. Saved atomically after every stage, so a run killed at any point
// resumes with no finished stage redone.
#pragma once

#include <map>
#include <string>
#include <vector>

namespace fvs {

// "<path> <size> <mtime_ns>" lines for a file, or for every regular file below a folder
// (sorted); "<path> missing" for a path that does not exist. Files whose names contain
// ".tmp-" (our temporaries) are ignored.
std::string StampPaths(const std::vector<std::string>& paths);

class Manifest {
 public:
  // A missing file gives an empty manifest; an unreadable or corrupt one too (with a
  // warning on stderr): the worst that follows is that stages run again.
  static Manifest Load(const std::string& path);
  void Save() const;  // atomic

  // Fingerprint = options + StampPaths(inputs).
  static std::string Fingerprint(const std::vector<std::string>& inputs,
                                 const std::string& options);

  bool IsUpToDate(const std::string& stage, const std::string& fingerprint,
                  const std::vector<std::string>& outputs) const;
  void Record(const std::string& stage, const std::string& fingerprint,
              const std::vector<std::string>& outputs, double seconds);
  void Forget(const std::string& stage);

  const std::string& path() const { return path_; }

 private:
  struct Entry {
    std::string fingerprint;
    std::vector<std::string> outputs;
    double seconds = 0;
  };
  std::string path_;
  std::map<std::string, Entry> stages_;
};

}  // namespace fvs
