// The `colmap` front door: runs our view_synthesis* commands itself and execs the real
// COLMAP for every other command with the same arguments, so one `colmap` on the PATH
// does both.
#include <unistd.h>

#include <cerrno>
#include <csignal>
#include <cstdio>
#include <cstring>
#include <iostream>
#include <string>
#include <vector>

#include "colmap_ext/runner.h"
#include "fvs/exe/command_registry.h"
#include "fvs/util/error.h"

namespace {

void PrintOurCommands() {
  std::cout << "\ncolmap-fvs (Free View Synthesis) commands:\n";
  for (const fvs::CommandInfo& c : fvs::RegisteredCommands()) {
    std::cout << "  " << c.name;
    for (size_t i = c.name.size(); i < 34; ++i) std::cout << ' ';
    std::cout << c.description << "\n";
  }
}

// `colmap help` / `colmap -h` / `colmap`: COLMAP's own help first, then ours.
int PrintHelp(const std::string& real_colmap, const std::string& help_arg) {
  if (!real_colmap.empty()) {
    const std::string cmd = "'" + real_colmap + "' " + help_arg + " 2>&1";
    if (FILE* pipe = ::popen(cmd.c_str(), "r")) {
      char buffer[4096];
      size_t n;
      while ((n = std::fread(buffer, 1, sizeof(buffer), pipe)) > 0) {
        std::fwrite(buffer, 1, n, stdout);
      }
      ::pclose(pipe);
    }
  } else {
    std::cout
        << "(no COLMAP executable found: only the colmap-fvs commands are available; "
           "install colmap or set FVS_COLMAP_BIN)\n";
  }
  PrintOurCommands();
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  // Past a file-size limit (ulimit -f) the kernel sends SIGXFSZ, whose default action
  // kills the process without a word and leaves the temporary file of the write behind.
  // Ignored, the write fails with EFBIG instead and the writer reports it as one error
  // line and removes its temporary file. The real COLMAP, exec'd below, gets the
  // default back.
  std::signal(SIGXFSZ, SIG_IGN);
  const std::string command = argc >= 2 ? argv[1] : "";
  if (fvs::FindCommand(command) != nullptr) return fvs::RunCommand(argc, argv);

  std::string real_colmap;
  try {
    real_colmap = fvs::colmap::FindColmapExecutable();
  } catch (const fvs::Error&) {
  }
  if (command.empty() || command == "help" || command == "-h" || command == "--help") {
    return PrintHelp(real_colmap, command.empty() ? "help" : command);
  }
  if (real_colmap.empty()) {
    std::cerr
        << "ERROR: colmap " << command
        << ": not a colmap-fvs command, and no COLMAP executable was found to run it "
           "(install colmap or set FVS_COLMAP_BIN)\n";
    return 1;
  }
  std::vector<char*> args(argv, argv + argc);
  args[0] = real_colmap.data();
  args.push_back(nullptr);
  std::signal(SIGXFSZ, SIG_DFL);
  ::execv(real_colmap.c_str(), args.data());
  std::cerr << "ERROR: cannot run " << real_colmap << ": " << std::strerror(errno)
            << "\n";
  return 1;
}
