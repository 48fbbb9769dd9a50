// Command line of the benchmarks: pairs of --key value. A typo must not run the default
// benchmark for minutes, so -h/--help prints the usage and exits 0, and an unknown key or
// a key without its value prints one line and the usage and exits 2.
#pragma once

#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

namespace fvs::benchmark {

inline void CheckArgs(int argc, char** argv, const char* usage,
                      const std::vector<std::string>& known) {
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    if (arg == "-h" || arg == "--help") {
      std::printf("%s\n", usage);
      std::exit(0);
    }
  }
  for (int i = 1; i < argc; i += 2) {
    const std::string key = argv[i];
    bool ok = false;
    for (const std::string& k : known) ok = ok || k == key;
    const char* why = !ok ? "unknown option" : i + 1 >= argc ? "needs a value" : nullptr;
    if (why) {
      std::fprintf(stderr, "ERROR: %s: %s\n%s\n", key.c_str(), why, usage);
      std::exit(2);
    }
  }
}

}  // namespace fvs::benchmark
