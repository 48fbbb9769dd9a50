#include "fvs/exe/command_registry.h"

#include <algorithm>
#include <exception>
#include <iostream>
#include <map>
#include <new>

#include "fvs/util/error.h"

namespace fvs {
namespace {

std::map<std::string, CommandInfo>& Registry() {
  static std::map<std::string, CommandInfo> registry;
  return registry;
}

}  // namespace

CommandRegistrar::CommandRegistrar(const char* name, const char* description,
                                   CommandFunction function) {
  Registry()[name] = CommandInfo{name, description, function};
}

std::vector<CommandInfo> RegisteredCommands() {
  std::vector<CommandInfo> commands;
  for (const auto& [name, info] : Registry()) commands.push_back(info);
  return commands;
}

const CommandInfo* FindCommand(const std::string& name) {
  const auto it = Registry().find(name);
  return it == Registry().end() ? nullptr : &it->second;
}

int RunCommand(int argc, char** argv) {
  if (argc < 2) {
    std::cerr << "ERROR: no command given\n";
    return 1;
  }
  const CommandInfo* command = FindCommand(argv[1]);
  if (command == nullptr) {
    std::cerr << "ERROR: unknown command " << argv[1] << "\n";
    return 1;
  }
  // One line on stderr for every failure: the brief forbids aborting on user input.
  try {
    return command->function(argc, argv);
  } catch (const Error& e) {
    std::cerr << "ERROR: " << e.what() << std::endl;
  } catch (const std::bad_alloc&) {
    std::cerr << "ERROR: colmap " << argv[1] << ": out of memory" << std::endl;
  } catch (const std::exception& e) {
    std::cerr << "ERROR: colmap " << argv[1] << ": " << e.what() << std::endl;
  }
  return 1;
}

}  // namespace fvs
