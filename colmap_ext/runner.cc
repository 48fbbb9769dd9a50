// Running the real COLMAP: fork + execve with one pipe for stdout and stderr (no shell,
// so arguments need no quoting), lines forwarded as progress, the tail kept for the error
// line.
#include "colmap_ext/runner.h"

#include <fcntl.h>
#include <sys/prctl.h>
#include <signal.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <climits>
#include <cstdlib>
#include <cstring>
#include <deque>
#include <filesystem>
#include <iostream>
#include <mutex>
#include <regex>

#include "fvs/util/error.h"
#include "fvs/util/progress.h"

extern char** environ;

namespace fvs::colmap {
namespace {

bool EnvIs(const char* name, const char* value) {
  const char* v = std::getenv(name);
  return v != nullptr && std::strcmp(v, value) == 0;
}

bool IsExecutableFile(const std::string& path) {
  struct stat st;
  return ::stat(path.c_str(), &st) == 0 && S_ISREG(st.st_mode) &&
         ::access(path.c_str(), X_OK) == 0;
}

std::string DirName(const std::string& path) {
  const size_t slash = path.find_last_of('/');
  if (slash == std::string::npos) return ".";
  return slash == 0 ? "/" : path.substr(0, slash);
}

// The folders of a PATH-style list; an empty entry means the current folder.
std::vector<std::string> SplitPath(const std::string& list) {
  std::vector<std::string> dirs;
  size_t begin = 0;
  while (begin <= list.size()) {
    size_t end = list.find(':', begin);
    if (end == std::string::npos) end = list.size();
    dirs.push_back(end > begin ? list.substr(begin, end - begin) : ".");
    begin = end + 1;
  }
  return dirs;
}

// Our own front door (build/bin/colmap, an installed <prefix>/bin/colmap) has a
// `.fvs_front_door` marker beside it; running it from here would recurse. Checked for the
// path as given and for its resolved target. A path that resolves to the running
// executable itself (e.g. a user's own `colmap` link to /usr/bin/colmap-fvs, which has no
// marker: /usr/bin also holds Debian's real colmap) counts too.
bool IsFrontDoor(const std::string& path) {
  struct stat st;
  if (::stat((DirName(path) + "/.fvs_front_door").c_str(), &st) == 0) return true;
  char resolved[PATH_MAX];
  if (::realpath(path.c_str(), resolved) != nullptr) {
    if (::stat((DirName(resolved) + "/.fvs_front_door").c_str(), &st) == 0) return true;
    char self[PATH_MAX];
    if (::realpath("/proc/self/exe", self) != nullptr &&
        std::strcmp(self, resolved) == 0) {
      return true;
    }
  }
  return false;
}

// Drops glog's "E1121 10:00:00.123456 12345 file.cc:12] " prefix, which says nothing to a
// user.
std::string StripGlogPrefix(const std::string& line) {
  static const std::regex kGlog(R"(^[IWEF]\d{4,8} \d\d:\d\d:\d\d\.\d+\s+\d+ [^\]]*\] )");
  return std::regex_replace(line, kGlog, "", std::regex_constants::format_first_only);
}

bool LooksLikeError(const std::string& line) {
  static const char* kWords[] = {"error",    "ERROR",  "Error",        "Check failed",
                                 "requires", "failed", "Failed",       "not exist",
                                 "cannot",   "Cannot", "unrecognised", "unrecognized",
                                 "invalid",  "Invalid"};
  for (const char* word : kWords) {
    if (line.find(word) != std::string::npos) return true;
  }
  return false;
}

struct ProcessResult {
  bool exited = false;
  int exit_code = -1;
  int signal = 0;
  std::deque<std::string> tail;  // the last lines printed
};

constexpr size_t kTailLines = 50;
constexpr size_t kMaxLineBytes = 64 * 1024;

ProcessResult RunProcess(const std::string& executable,
                         const std::vector<std::string>& args,
                         const std::function<void(const std::string&)>& on_line) {
  // Everything the child needs is prepared before fork: after it only exec and _exit.
  std::vector<std::string> argv_storage;
  argv_storage.push_back(executable);
  argv_storage.insert(argv_storage.end(), args.begin(), args.end());
  std::vector<char*> argv;
  for (std::string& a : argv_storage) argv.push_back(a.data());
  argv.push_back(nullptr);
  // COLMAP links Qt; without a display it needs the offscreen platform.
  std::vector<char*> envp;
  bool has_qt_platform = false;
  for (char** e = environ; *e != nullptr; ++e) {
    if (std::strncmp(*e, "QT_QPA_PLATFORM=", 16) == 0) has_qt_platform = true;
    envp.push_back(*e);
  }
  std::string qt_platform = "QT_QPA_PLATFORM=offscreen";
  if (!has_qt_platform) envp.push_back(qt_platform.data());
  envp.push_back(nullptr);
  const std::string exec_failed = "cannot execute " + executable + "\n";

  int fds[2];
  if (::pipe2(fds, O_CLOEXEC) != 0) {
    throw Error(executable,
                std::string("cannot create a pipe (") + std::strerror(errno) + ")");
  }
  const pid_t parent = ::getpid();
  const pid_t pid = ::fork();
  if (pid < 0) {
    ::close(fds[0]);
    ::close(fds[1]);
    throw Error(executable, std::string("cannot fork (") + std::strerror(errno) + ")");
  }
  if (pid == 0) {
    // COLMAP dies with us: a killed prepare leaves no COLMAP writing its workspace (and
    // holding its lock, util/folder_lock.h) after it. The check after covers a parent
    // that died before the request.
    ::prctl(PR_SET_PDEATHSIG, SIGKILL);
    if (::getppid() != parent) ::_exit(127);
    ::dup2(fds[1], STDOUT_FILENO);
    ::dup2(fds[1], STDERR_FILENO);
    const int devnull = ::open("/dev/null", O_RDONLY);
    if (devnull >= 0) ::dup2(devnull, STDIN_FILENO);
    ::execve(executable.c_str(), argv.data(), envp.data());
    ssize_t ignored = ::write(STDERR_FILENO, exec_failed.data(), exec_failed.size());
    (void)ignored;
    ::_exit(127);
  }
  ::close(fds[1]);

  ProcessResult result;
  std::string pending;
  auto emit = [&](const std::string& raw) {
    std::string line = raw;
    while (!line.empty() && (line.back() == '\r' || line.back() == ' ')) line.pop_back();
    if (line.empty()) return;
    result.tail.push_back(line);
    if (result.tail.size() > kTailLines) result.tail.pop_front();
    if (on_line) on_line(line);
  };
  char buffer[4096];
  while (true) {
    const ssize_t n = ::read(fds[0], buffer, sizeof(buffer));
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) break;
    for (ssize_t i = 0; i < n; ++i) {
      if (buffer[i] == '\n' || buffer[i] == '\r') {
        emit(pending);
        pending.clear();
      } else if (pending.size() < kMaxLineBytes) {  // a runaway line is cut, not stored
        pending.push_back(buffer[i]);
      }
    }
  }
  emit(pending);
  ::close(fds[0]);
  int status = 0;
  while (::waitpid(pid, &status, 0) < 0) {
    if (errno != EINTR) throw Error(executable, "waitpid failed");
  }
  if (WIFEXITED(status)) {
    result.exited = true;
    result.exit_code = WEXITSTATUS(status);
  } else if (WIFSIGNALED(status)) {
    result.signal = WTERMSIG(status);
  }
  return result;
}

// glog's fatal or error lines ("F1121 ...", "E20261121 ...").
bool IsGlogErrorLine(const std::string& line) {
  static const std::regex kGlogError(R"(^[EF]\d{4,8} \d\d:\d\d:\d\d)");
  return std::regex_search(line, kGlogError);
}

// Stack traces after a failed CHECK say nothing to a user.
bool IsStackTraceLine(const std::string& line) {
  const size_t first = line.find_first_not_of(' ');
  return first == std::string::npos || line.compare(first, 2, "@ ") == 0 ||
         line.compare(first, 3, "***") == 0;
}

// The line that best says why COLMAP failed: its last glog error, else the last line that
// reads like an error, else the last line.
std::string ErrorLine(const std::deque<std::string>& tail) {
  for (auto it = tail.rbegin(); it != tail.rend(); ++it) {
    if (IsGlogErrorLine(*it)) return StripGlogPrefix(*it);
  }
  for (auto it = tail.rbegin(); it != tail.rend(); ++it) {
    if (IsStackTraceLine(*it)) continue;
    const std::string line = StripGlogPrefix(*it);
    if (LooksLikeError(line)) return line;
  }
  for (auto it = tail.rbegin(); it != tail.rend(); ++it) {
    if (!IsStackTraceLine(*it)) return StripGlogPrefix(*it);
  }
  return "(no output)";
}

std::string MakeTempDir() {
  const char* tmp = std::getenv("TMPDIR");
  std::string pattern =
      std::string(tmp && *tmp ? tmp : "/tmp") + "/fvs_colmap_probe_XXXXXX";
  if (::mkdtemp(pattern.data()) == nullptr) {
    throw Error(pattern, "cannot create a temporary folder to probe COLMAP");
  }
  return pattern;
}

ColmapCapabilities Probe() {
  ColmapCapabilities caps;
  caps.executable = FindColmapExecutable();
  std::string help;
  RunProcess(caps.executable, {"-h"},
             [&](const std::string& line) { help += line + "\n"; });
  std::smatch match;
  static const std::regex kVersion(R"(COLMAP\s+([0-9]+(\.[0-9]+)*))");
  if (std::regex_search(help, match, kVersion)) {
    caps.version = match[1];
  } else {
    throw Error(caps.executable, "does not look like COLMAP (no version in `colmap -h`)");
  }
  caps.has_cuda = help.find("with CUDA") != std::string::npos &&
                  help.find("without CUDA") == std::string::npos;
  // COLMAP says at run time whether it was built with CGAL: delaunay_mesher on an empty
  // workspace stops at once, with "requires CGAL" when it lacks it.
  const std::string dir = MakeTempDir();
  std::string mesher_output;
  RunProcess(
      caps.executable,
      {"delaunay_mesher", "--input_path", dir, "--output_path", dir + "/probe.ply"},
      [&](const std::string& line) { mesher_output += line + "\n"; });
  std::error_code ec;
  std::filesystem::remove_all(dir, ec);
  caps.has_cgal = mesher_output.find("requires CGAL") == std::string::npos &&
                  mesher_output.find("not recognized") == std::string::npos;
  return caps;
}

}  // namespace

std::string FindColmapExecutable() {
  const char* env = std::getenv("FVS_COLMAP_BIN");
  if (env != nullptr && *env != '\0') {
    std::string path = env;
    if (path.find('/') == std::string::npos) {
      // A bare name ("colmap-3.8") is looked up on the PATH, as a shell would.
      const char* path_env = std::getenv("PATH");
      for (const std::string& dir : SplitPath(path_env ? path_env : "")) {
        if (IsExecutableFile(dir + "/" + path)) {
          path = dir + "/" + path;
          break;
        }
      }
    }
    if (!IsExecutableFile(path)) {
      throw Error(path, "FVS_COLMAP_BIN does not name an executable file");
    }
    if (IsFrontDoor(path)) {
      throw Error(path,
                  "FVS_COLMAP_BIN names our own colmap front door; point it at the "
                  "real COLMAP executable");
    }
    return path;
  }
  const char* path_env = std::getenv("PATH");
  for (const std::string& dir :
       SplitPath(path_env ? path_env : "/usr/local/bin:/usr/bin:/bin")) {
    const std::string candidate = dir + "/colmap";
    if (IsExecutableFile(candidate) && !IsFrontDoor(candidate)) return candidate;
  }
  throw Error("colmap",
              "COLMAP executable not found: install COLMAP (apt install colmap) "
              "or set FVS_COLMAP_BIN to its path");
}

const ColmapCapabilities& ProbeColmap() {
  static std::mutex mutex;
  static bool probed = false;
  static ColmapCapabilities caps;
  std::lock_guard<std::mutex> lock(mutex);
  if (!probed) {
    caps = Probe();
    probed = true;
  }
  return caps;
}

void RunColmap(const std::vector<std::string>& args, const RunColmapOptions& options) {
  const std::string executable = FindColmapExecutable();
  const std::string command = args.empty() ? std::string("(no command)") : args[0];
  const std::string label = options.label.empty() ? "colmap " + command : options.label;
  const bool quiet = EnvIs("FVS_QUIET", "1");
  const bool verbose = EnvIs("FVS_VERBOSE", "1");
  const bool tty = ::isatty(STDERR_FILENO) == 1;
  Timer timer;
  std::function<void(const std::string&)> on_line = options.on_line;
  if (!on_line && !quiet) {
    if (verbose) {
      on_line = [](const std::string& line) { std::cerr << line << "\n"; };
    } else if (tty) {
      // One redrawn status line: the label and the latest thing COLMAP said.
      on_line = [&](const std::string& line) {
        std::string shown = label + ": " + StripGlogPrefix(line);
        if (shown.size() > 100) shown = shown.substr(0, 97) + "...";
        std::cerr << "\r\033[K" << shown << std::flush;
      };
    }
  }
  if (!quiet && !tty) std::cerr << label << " ...\n";
  const ProcessResult result = RunProcess(executable, args, on_line);
  if (!quiet && tty && !options.on_line && !verbose) std::cerr << "\r\033[K";
  if (result.exited && result.exit_code == 0) {
    if (!quiet) {
      char seconds[32];
      std::snprintf(seconds, sizeof(seconds), "%.1f", timer.Seconds());
      std::cerr << label << " done (" << seconds << " s)\n";
    }
    return;
  }
  std::string what;
  if (result.exited) {
    what = "failed (exit " + std::to_string(result.exit_code) + ")";
  } else {
    what = "crashed (signal " + std::to_string(result.signal) + ", " +
           strsignal(result.signal) + ")";
  }
  throw Error(label + " " + what + ": " + ErrorLine(result.tail));
}

}  // namespace fvs::colmap
