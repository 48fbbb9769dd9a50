// Shared test helpers: temporary folders that clean up, paths of the build.
#pragma once

#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "fvs/util/error.h"

namespace fvs::testing {

// A fresh, empty folder under $TMPDIR (or /tmp), removed with its contents on destruction
// unless FVS_KEEP_TEST_DIRS=1.
class TempDir {
 public:
  TempDir();
  ~TempDir();
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;
  const std::string& path() const { return path_; }
  std::string operator/(const std::string& name) const { return path_ + "/" + name; }

 private:
  std::string path_;
};

// build/bin/colmap, our front door.
std::string FrontDoorBinary();
// The real COLMAP: $FVS_COLMAP_BIN or `colmap` on the PATH (not our front door).
std::string RealColmapBinary();

// The shared data beside the checkout (../shared: weights/, datasets/; never copied into
// the repository), or $FVS_SHARED_DIR when set. Tests that need a file from it skip,
// visibly, when it is absent (SharedFile).
std::string SharedDir();
// SharedDir()/relative when that file exists, else "" and *why_skip says what is missing.
std::string SharedFile(const std::string& relative, std::string* why_skip);

// Sets (value) or unsets (nullptr) an environment variable and restores it when the
// test ends.
class ScopedEnv {
 public:
  ScopedEnv(const char* name, const char* value);
  ~ScopedEnv();
  ScopedEnv(const ScopedEnv&) = delete;
  ScopedEnv& operator=(const ScopedEnv&) = delete;

 private:
  std::string name_, old_;
  bool had_ = false;
};

// Runs a shell command, returns its exit status; output goes to *output when given.
int RunShell(const std::string& command, std::string* output = nullptr);

void WriteTextFile(const std::string& path, const std::string& text);
std::string ReadTextFile(const std::string& path);

// Runs fn and expects an fvs::Error whose message is one line containing every one of
// `parts` (the bad-input rule: one clear line naming the file and the fault).
template <typename Fn>
void ExpectError(Fn fn, const std::vector<std::string>& parts) {
  try {
    fn();
    ADD_FAILURE() << "no error thrown";
  } catch (const Error& e) {
    const std::string message = e.what();
    EXPECT_EQ(message.find('\n'), std::string::npos) << "one line: " << message;
    for (const std::string& part : parts) {
      EXPECT_NE(message.find(part), std::string::npos) << message << " lacks " << part;
    }
  }
}

}  // namespace fvs::testing
