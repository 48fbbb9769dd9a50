#include "support/test_support.h"

#include <sys/wait.h>

#include <array>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>

namespace fvs::testing {

TempDir::TempDir() {
  const char* tmp = std::getenv("TMPDIR");
  std::string pattern = std::string(tmp ? tmp : "/tmp") + "/fvs_test_XXXXXX";
  if (::mkdtemp(pattern.data()) == nullptr) {
    throw std::runtime_error("cannot create temporary folder " + pattern);
  }
  path_ = pattern;
}

TempDir::~TempDir() {
  const char* keep = std::getenv("FVS_KEEP_TEST_DIRS");
  if (keep && keep[0] == '1') return;
  std::error_code ec;
  std::filesystem::remove_all(path_, ec);
}

std::string FrontDoorBinary() { return std::string(FVS_BINARY_DIR) + "/bin/colmap"; }

std::string RealColmapBinary() {
  if (const char* env = std::getenv("FVS_COLMAP_BIN")) return env;
  return "/usr/bin/colmap";
}

ScopedEnv::ScopedEnv(const char* name, const char* value) : name_(name) {
  const char* old = std::getenv(name);
  had_ = old != nullptr;
  if (had_) old_ = old;
  if (value) {
    ::setenv(name, value, 1);
  } else {
    ::unsetenv(name);
  }
}

ScopedEnv::~ScopedEnv() {
  if (had_) {
    ::setenv(name_.c_str(), old_.c_str(), 1);
  } else {
    ::unsetenv(name_.c_str());
  }
}

std::string SharedDir() {
  if (const char* env = std::getenv("FVS_SHARED_DIR")) return env;
  return FVS_SHARED_DIR;
}

std::string SharedFile(const std::string& relative, std::string* why_skip) {
  const std::string path = SharedDir() + "/" + relative;
  std::error_code ec;
  if (std::filesystem::is_regular_file(path, ec)) return path;
  *why_skip =
      path + " is absent (the shared data beside the checkout, or $FVS_SHARED_DIR)";
  return "";
}

int RunShell(const std::string& command, std::string* output) {
  FILE* pipe = ::popen((command + " 2>&1").c_str(), "r");
  if (!pipe) return -1;
  std::array<char, 4096> buffer;
  std::string text;
  size_t n;
  while ((n = std::fread(buffer.data(), 1, buffer.size(), pipe)) > 0) {
    text.append(buffer.data(), n);
  }
  const int status = ::pclose(pipe);
  if (output) *output = text;
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

void WriteTextFile(const std::string& path, const std::string& text) {
  std::ofstream out(path, std::ios::binary);
  out << text;
}

std::string ReadTextFile(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

}  // namespace fvs::testing
