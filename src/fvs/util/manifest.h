// The record that lets a stage be skipped: for each stage, a fingerprint of its inputs
// (file sizes and modification times, recursively for folders, plus its options) and the
// outputs it produced. A stage is up to date when its fingerprint is unchanged and all
// its outputs exist. Saved atomically after every stage, so a run killed at any point
// resumes with no finished stage redone.
//
// Paths inside the manifest's root (the workspace) are recorded relative to it, so a
// workspace moved or copied elsewhere keeps every stage up to date; paths outside it
// (the photo folder) stay absolute. Manifests of format 1 (absolute outputs) are still
// read: their outputs are taken relative to the folder that held them all.
#pragma once

#include <map>
#include <string>
#include <vector>

namespace fvs {

// "<path> <size> <mtime_ns>" lines for a file, or for every regular file below a folder
// (sorted); "<path> missing" for a path that does not exist. Files whose names contain
// ".tmp-" (our temporaries) are ignored. With a `root`, paths inside it are written
// relative to it.
std::string StampPaths(const std::vector<std::string>& paths,
                       const std::string& root = "");

// `path` relative to `root` when it lies inside it (both absolute), else `path`.
std::string PathInside(const std::string& path, const std::string& root);

class Manifest {
 public:
  // A missing file gives an empty manifest; an unreadable or corrupt one too (with a
  // warning on stderr): the worst that follows is that stages run again.
  // `root`: the folder recorded paths are relative to (absolute; empty: none).
  static Manifest Load(const std::string& path, const std::string& root = "");
  void Save() const;  // atomic

  // Fingerprint = options + StampPaths(inputs, root).
  static std::string Fingerprint(const std::vector<std::string>& inputs,
                                 const std::string& options,
                                 const std::string& root = "");

  bool IsUpToDate(const std::string& stage, const std::string& fingerprint,
                  const std::vector<std::string>& outputs) const;
  void Record(const std::string& stage, const std::string& fingerprint,
              const std::vector<std::string>& outputs, double seconds);
  void Forget(const std::string& stage);

  const std::string& path() const { return path_; }
  const std::string& root() const { return root_; }

 private:
  struct Entry {
    std::string fingerprint;
    std::vector<std::string> outputs;
    double seconds = 0;
  };
  // Recorded form of an output: relative to root_ when inside it.
  std::string Recorded(const std::string& output) const;
  // Back to a usable path: relative ones under root_.
  std::string Resolved(const std::string& recorded) const;

  std::string path_;
  std::string root_;
  std::map<std::string, Entry> stages_;
};

}  // namespace fvs
