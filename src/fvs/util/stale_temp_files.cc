#include "fvs/util/stale_temp_files.h"

#include <signal.h>
#include <unistd.h>

#include <cerrno>
#include <filesystem>
#include <regex>

namespace fvs {

int RemoveStaleTempFiles(const std::string& dir) {
  namespace fs = std::filesystem;
  std::error_code ec;
  if (!fs::is_directory(dir, ec)) return 0;
  // Images keep their extension after the counter (OIIO picks the format from it).
  static const std::regex kTemp(R"(.+\.tmp-([0-9]+)-[0-9]+(\.[A-Za-z0-9]+)?)");
  int removed = 0;
  for (const auto& entry : fs::directory_iterator(dir, ec)) {
    std::smatch match;
    const std::string name = entry.path().filename().string();
    if (!entry.is_regular_file(ec) || !std::regex_match(name, match, kTemp)) continue;
    const long pid = std::stol(match[1].str().substr(0, 9));
    // ESRCH: no such process. Our own pid counts as live (a writer of this run).
    const bool alive =
        pid == ::getpid() || ::kill(static_cast<pid_t>(pid), 0) == 0 || errno != ESRCH;
    if (alive) continue;
    if (fs::remove(entry.path(), ec)) ++removed;
  }
  return removed;
}

}  // namespace fvs
