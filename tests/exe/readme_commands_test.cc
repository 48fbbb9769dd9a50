// Every command registered in the front door (src/fvs/exe, FVS_REGISTER_COMMAND) is in
// README.md's command table and in the manual page doc/colmap-fvs.1, and neither lists a
// command that is not registered: a new command cannot ship undocumented.
#include <gtest/gtest.h>

#include <regex>
#include <set>
#include <sstream>
#include <string>

#include "fvs/exe/command_registry.h"
#include "support/test_support.h"

namespace fvs::testing {
namespace {

// Names in README's table rows: lines "| `colmap view_synthesis_x ...` | ... |".
std::set<std::string> ReadmeTableCommands() {
  std::set<std::string> names;
  std::istringstream in(ReadTextFile(std::string(FVS_SOURCE_DIR) + "/README.md"));
  static const std::regex kRow(R"(^\| `colmap (view_synthesis\w*)[ `])");
  std::string line;
  std::smatch match;
  while (std::getline(in, line)) {
    if (std::regex_search(line, match, kRow)) names.insert(match[1]);
  }
  return names;
}

// Names in the manual page's COMMANDS section: ".B view_synthesis_x" lines.
std::set<std::string> ManPageCommands() {
  std::set<std::string> names;
  std::istringstream in(ReadTextFile(std::string(FVS_SOURCE_DIR) + "/doc/colmap-fvs.1"));
  static const std::regex kEntry(R"(^\.B (view_synthesis\w*)\s*$)");
  std::string line;
  std::smatch match;
  while (std::getline(in, line)) {
    if (std::regex_search(line, match, kEntry)) names.insert(match[1]);
  }
  return names;
}

std::set<std::string> Registered() {
  std::set<std::string> names;
  for (const CommandInfo& c : RegisteredCommands()) names.insert(c.name);
  return names;
}

TEST(ReadmeCommands, EveryRegisteredCommandIsInTheReadmeTable) {
  const std::set<std::string> registered = Registered();
  ASSERT_GE(registered.size(), 10u);
  const std::set<std::string> readme = ReadmeTableCommands();
  for (const std::string& name : registered) {
    EXPECT_EQ(readme.count(name), 1u)
        << name << " is registered but missing from README.md's command table "
        << "(add a row \"| `colmap " << name << " ...` | ... |\")";
  }
  for (const std::string& name : readme) {
    EXPECT_EQ(registered.count(name), 1u)
        << name << " is in README.md's command table but not registered";
  }
}

TEST(ReadmeCommands, EveryRegisteredCommandIsInTheManPage) {
  const std::set<std::string> registered = Registered();
  const std::set<std::string> man = ManPageCommands();
  for (const std::string& name : registered) {
    EXPECT_EQ(man.count(name), 1u) << name << " is missing from doc/colmap-fvs.1";
  }
  for (const std::string& name : man) {
    EXPECT_EQ(registered.count(name), 1u) << name << " is in doc/colmap-fvs.1 but not registered";
  }
}

}  // namespace
}  // namespace fvs::testing
