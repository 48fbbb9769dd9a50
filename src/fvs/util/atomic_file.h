// Writing files so that a killed run never leaves a half-written file that a later run
// trusts: everything is written to "<path>.tmp-<pid>" and renamed over <path> on
// Commit().
#pragma once

#include <fstream>
#include <functional>
#include <string>

namespace fvs {

class AtomicFile {
 public:
  // Opens the temporary file (binary mode). Throws fvs::Error if it cannot be created.
  explicit AtomicFile(const std::string& path);
  // Removes the temporary file if Commit() was not reached (an exception, say).
  ~AtomicFile();
  AtomicFile(const AtomicFile&) = delete;
  AtomicFile& operator=(const AtomicFile&) = delete;

  std::ofstream& stream() { return stream_; }
  const std::string& path() const { return path_; }
  const std::string& temp_path() const { return temp_path_; }

  // Flushes, checks the stream (disk full shows here), closes and renames. Throws
  // fvs::Error.
  void Commit();

 private:
  std::string path_;
  std::string temp_path_;
  std::ofstream stream_;
  bool committed_ = false;
};

// Convenience: writes through `write` and commits.
void WriteFileAtomic(const std::string& path,
                     const std::function<void(std::ostream&)>& write);

// Temporary path beside `path` for writers that need a file name rather than a stream (an
// external library, say); rename it with CommitTempFile. Removed by RemoveTempFile on
// failure.
std::string TempPathFor(const std::string& path);
void CommitTempFile(const std::string& temp_path, const std::string& path);

// Reads a whole file; throws fvs::Error naming the file if it cannot be read.
std::string ReadFileToString(const std::string& path);

}  // namespace fvs
