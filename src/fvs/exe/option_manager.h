// Command-line options in COLMAP's style: `--name value` or `--Section.name value`, `-h` /
// `--help`. Values bind to variables (usually fields of an options struct with Check()).
#pragma once

#include <memory>
#include <string>
#include <vector>

namespace fvs {

class OptionManager {
 public:
  OptionManager(std::string command, std::string description);

  // `name` without the leading dashes, e.g. "workspace_path" or "Stereo.backend".
  void AddRequired(const std::string& name, std::string* value, const std::string& help);
  void AddDefault(const std::string& name, std::string* value, const std::string& help);
  void AddDefault(const std::string& name, int* value, const std::string& help);
  void AddDefault(const std::string& name, double* value, const std::string& help);
  void AddDefault(const std::string& name, bool* value, const std::string& help);

  // Parses argv[first..argc). Returns false when help was asked for (printed to stdout):
  // the caller returns 0. Throws fvs::Error with one line for an unknown option, a missing
  // value, a value that does not parse, or a missing required option.
  bool Parse(int argc, char** argv, int first = 2);

  std::string Usage() const;

  // "--name value" pairs of every option as parsed (for manifests and reproducibility).
  std::string Describe() const;

 private:
  struct Option {
    std::string name;
    std::string help;
    bool required = false;
    bool seen = false;
    enum class Kind { kString, kInt, kDouble, kBool } kind;
    void* target = nullptr;
  };
  std::string ValueString(const Option& option) const;
  void Add(const std::string& name, Option::Kind kind, void* target, bool required,
           const std::string& help);

  std::string command_;
  std::string description_;
  std::vector<Option> options_;
};

}  // namespace fvs
