// Our `view_synthesis*` commands. Each lives in src/fvs/exe/<name>_command.cc and
// registers itself with FVS_REGISTER_COMMAND; the front door (main.cc) runs ours and
// execs the real COLMAP for everything else.
#pragma once

#include <string>
#include <vector>

namespace fvs {

// argv[0] is the program, argv[1] the command name, options start at argv[2].
// Returns the process exit code. May throw fvs::Error: the front door prints
// "ERROR: <message>" (one line) and exits 1.
using CommandFunction = int (*)(int argc, char** argv);

struct CommandInfo {
  std::string name;
  std::string description;
  CommandFunction function = nullptr;
};

// Sorted by name.
std::vector<CommandInfo> RegisteredCommands();
const CommandInfo* FindCommand(const std::string& name);

struct CommandRegistrar {
  CommandRegistrar(const char* name, const char* description, CommandFunction function);
};

// Runs a registered command as the front door would (exceptions turned into one error
// line on stderr and exit code 1). For tests and for the GUI.
int RunCommand(int argc, char** argv);

}  // namespace fvs

#define FVS_REGISTER_COMMAND_CONCAT_(a, b) a##b
#define FVS_REGISTER_COMMAND_NAME_(line) \
  FVS_REGISTER_COMMAND_CONCAT_(fvs_command_registrar_, line)
// Works with qualified function names too: the registrar is named after the line.
#define FVS_REGISTER_COMMAND(name, description, function)                                \
  static ::fvs::CommandRegistrar FVS_REGISTER_COMMAND_NAME_(__LINE__)(name, description, \
                                                                      function)
