// What every fuzz target shares. Most of our readers take a path, so the input goes to a
// file in a folder of this process (removed at exit); formats made of several files
// (cameras + images + points3D) take one input cut at kSeparator lines. The contract
// checked (doc/reliability.md): a reader returns, or throws fvs::Error with a one-line,
// non-empty message. Any other exception escapes to libFuzzer and is reported as a
// crash, as are aborts and sanitizer reports.
#pragma once

#include <stdlib.h>
#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "fvs/util/error.h"

namespace fvs::fuzz {

// Between the files of a multi-file input (seeds are written with it by make_seeds).
inline const std::string kSeparator = "\n=FVS-NEXT-FILE=\n";

// This process's scratch folder (libFuzzer runs one input at a time per process). Never
// destroyed: the atexit handler that removes the folder runs after static destructors
// of objects constructed later, so it must not read a destroyed string.
inline const std::string& ScratchDir() {
  static const std::string* const dir = [] {
    // Memory-backed when possible: on a disk the write and read of each input cost
    // five times the parsing (250 instead of 1300 executions per second measured).
    std::error_code ec;
    const std::filesystem::path base =
        getenv("TMPDIR") == nullptr && std::filesystem::is_directory("/dev/shm", ec) &&
                access("/dev/shm", W_OK) == 0
            ? std::filesystem::path("/dev/shm")
            : std::filesystem::temp_directory_path();
    std::string pattern = (base / "fvs_fuzz_XXXXXX").string();
    if (mkdtemp(pattern.data()) == nullptr) {
      std::perror("mkdtemp");
      std::abort();
    }
    std::atexit([] {
      std::error_code ec;
      std::filesystem::remove_all(ScratchDir(), ec);
    });
    return new std::string(pattern);
  }();
  return *dir;
}

// Writes `bytes` to ScratchDir()/name and returns the path.
inline std::string WriteScratch(const std::string& name, const std::string& bytes) {
  const std::string path = ScratchDir() + "/" + name;
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  out.close();
  if (!out) std::abort();  // the harness, not the reader, failed
  return path;
}

// The input cut at kSeparator into `count` parts; missing parts are empty, the last
// part keeps any further separators.
inline std::vector<std::string> SplitInput(const uint8_t* data, size_t size, int count) {
  const std::string input(reinterpret_cast<const char*>(data), size);
  std::vector<std::string> parts;
  size_t begin = 0;
  for (int i = 0; i + 1 < count; ++i) {
    const size_t end = input.find(kSeparator, begin);
    if (end == std::string::npos) break;
    parts.push_back(input.substr(begin, end - begin));
    begin = end + kSeparator.size();
  }
  parts.push_back(begin <= input.size() ? input.substr(begin) : "");
  parts.resize(count);
  return parts;
}

// Runs a reader: success and fvs::Error are both fine; an error must be one non-empty
// line (what the commands print after "ERROR: ").
template <typename Read>
void ExpectCleanResult(Read&& read) {
  try {
    read();
  } catch (const fvs::Error& e) {
    const std::string message = e.what();
    if (message.empty() || message.find('\n') != std::string::npos) {
      std::fprintf(stderr, "fvs::Error with a bad message: '%s'\n", message.c_str());
      std::abort();
    }
  }
}

}  // namespace fvs::fuzz
