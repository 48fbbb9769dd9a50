#include "fvs/util/option_manager.h"

#include <cctype>
#include <cerrno>
#include <charconv>
#include <climits>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <iostream>
#include <sstream>

#include "fvs/util/error.h"

namespace fvs {
namespace {

std::string StripDashes(const std::string& arg) {
  size_t i = 0;
  while (i < arg.size() && i < 2 && arg[i] == '-') ++i;
  return arg.substr(i);
}

bool ParseBool(std::string s, bool* value) {
  for (char& c : s) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  if (s == "1" || s == "true" || s == "on" || s == "yes") {
    *value = true;
    return true;
  }
  if (s == "0" || s == "false" || s == "off" || s == "no") {
    *value = false;
    return true;
  }
  return false;
}

}  // namespace

OptionManager::OptionManager(std::string command, std::string description)
    : command_(std::move(command)),
      program_("colmap " + command_),
      description_(std::move(description)) {}

void OptionManager::SetProgram(std::string program) { program_ = std::move(program); }

OptionManager::Option* OptionManager::Find(const std::string& name) {
  for (Option& o : options_) {
    if (o.name == name) return &o;
  }
  // The short form of --Section.name, when only one option ends in it.
  Option* found = nullptr;
  for (Option& o : options_) {
    const size_t dot = o.name.rfind('.');
    if (dot == std::string::npos || o.name.compare(dot + 1, std::string::npos, name) != 0)
      continue;
    if (found) {
      throw Error(program_, "option --" + name + " is ambiguous: --" + found->name +
                                " or --" + o.name);
    }
    found = &o;
  }
  return found;
}

void OptionManager::Add(const std::string& name, Option::Kind kind, void* target,
                        bool required, const std::string& help) {
  for (const Option& o : options_) {
    if (o.name == name) throw Error("option --" + name + " registered twice");
  }
  Option option;
  option.name = name;
  option.kind = kind;
  option.target = target;
  option.required = required;
  option.help = help;
  options_.push_back(option);
}

void OptionManager::AddRequired(const std::string& name, std::string* value,
                                const std::string& help) {
  Add(name, Option::Kind::kString, value, true, help);
}
void OptionManager::AddDefault(const std::string& name, std::string* value,
                               const std::string& help) {
  Add(name, Option::Kind::kString, value, false, help);
}
void OptionManager::AddDefault(const std::string& name, int* value,
                               const std::string& help) {
  Add(name, Option::Kind::kInt, value, false, help);
}
void OptionManager::AddDefault(const std::string& name, double* value,
                               const std::string& help) {
  Add(name, Option::Kind::kDouble, value, false, help);
}
void OptionManager::AddDefault(const std::string& name, bool* value,
                               const std::string& help) {
  Add(name, Option::Kind::kBool, value, false, help);
}

std::string OptionManager::ValueString(const Option& option) const {
  std::ostringstream s;
  switch (option.kind) {
    case Option::Kind::kString:
      s << *static_cast<std::string*>(option.target);
      break;
    case Option::Kind::kInt:
      s << *static_cast<int*>(option.target);
      break;
    case Option::Kind::kDouble: {
      // Shortest text that reads back as the same double ("0.05", not
      // 0.05000000000000001).
      char buffer[64];
      const auto r = std::to_chars(buffer, buffer + sizeof(buffer),
                                   *static_cast<double*>(option.target));
      s << std::string(buffer, r.ptr);
      break;
    }
    case Option::Kind::kBool:
      s << (*static_cast<bool*>(option.target) ? 1 : 0);
      break;
  }
  return s.str();
}

std::string OptionManager::Usage() const {
  std::ostringstream s;
  s << "Usage: " << program_ << " [options]\n\n" << description_ << "\n\nOptions:\n";
  s << "  -h [ --help ]\n";
  for (const Option& o : options_) {
    s << "  --" << o.name;
    if (o.required) {
      s << " arg (required)";
    } else {
      s << " arg (=" << ValueString(o) << ")";
    }
    if (!o.help.empty()) s << "\n      " << o.help;
    s << "\n";
  }
  return s.str();
}

std::string OptionManager::Describe() const {
  std::ostringstream s;
  for (size_t i = 0; i < options_.size(); ++i) {
    if (i) s << " ";
    s << "--" << options_[i].name << " " << ValueString(options_[i]);
  }
  return s.str();
}

bool OptionManager::Parse(int argc, char** argv, int first) {
  for (int i = first; i < argc; ++i) {
    const std::string arg = argv[i];
    if (arg == "-h" || arg == "--help") {
      std::cout << Usage();
      return false;
    }
  }
  for (int i = first; i < argc; ++i) {
    const std::string arg = argv[i];
    if (arg.size() < 2 || arg[0] != '-') {
      throw Error(program_,
                  "unexpected argument '" + arg + "' (options are --name value; see -h)");
    }
    std::string name = StripDashes(arg);
    std::string value;
    bool has_value = false;
    const size_t eq = name.find('=');
    if (eq != std::string::npos) {
      value = name.substr(eq + 1);
      name = name.substr(0, eq);
      has_value = true;
    }
    Option* option = Find(name);
    if (option == nullptr) {
      throw Error(program_, "unknown option --" + name + " (see -h)");
    }
    if (!has_value) {
      if (i + 1 >= argc) throw Error(program_, "option --" + name + " needs a value");
      value = argv[++i];
    }
    const std::string& where = program_;
    switch (option->kind) {
      case Option::Kind::kString:
        *static_cast<std::string*>(option->target) = value;
        break;
      case Option::Kind::kInt: {
        char* end = nullptr;
        errno = 0;
        const long v = std::strtol(value.c_str(), &end, 10);
        if (value.empty() || *end != '\0' || errno != 0 || v < INT32_MIN ||
            v > INT32_MAX) {
          throw Error(where,
                      "option --" + name + " expects an integer, got '" + value + "'");
        }
        *static_cast<int*>(option->target) = static_cast<int>(v);
        break;
      }
      case Option::Kind::kDouble: {
        char* end = nullptr;
        const double v = std::strtod(value.c_str(), &end);
        if (value.empty() || *end != '\0' || !std::isfinite(v)) {
          throw Error(where, "option --" + name + " expects a finite number, got '" +
                                 value + "'");
        }
        *static_cast<double*>(option->target) = v;
        break;
      }
      case Option::Kind::kBool: {
        bool v = false;
        if (!ParseBool(value, &v)) {
          throw Error(where, "option --" + name +
                                 " expects 1/0, true/false, on/off or yes/no, got '" +
                                 value + "'");
        }
        *static_cast<bool*>(option->target) = v;
        break;
      }
    }
    option->seen = true;
  }
  for (const Option& o : options_) {
    if (o.required && !o.seen) {
      throw Error(program_, "missing required option --" + o.name);
    }
  }
  return true;
}

}  // namespace fvs
