// Command-line options in COLMAP's style: `--name value` or `--Section.name value`, `-h`
// /
// `--help`. Values bind to variables (usually fields of an options struct with Check()).
// The one parser of every command and of the standalone trainer (fvs_train_main, which
// builds without the front door): option groups are registered by functions shared
// between commands (AddTrainOptions, AddRenderFlags, ...), never written out twice.
//
// Why our own and not CLI11 or cxxopts (issue 19): COLMAP's `--Section.option value` with
// its help layout, `Describe()` for manifests, and no dependency in the trainer-only
// build on a GPU machine; 200 lines, tested (tests/util/option_manager_test.cc).
#pragma once

#include <memory>
#include <string>
#include <vector>

namespace fvs {

class OptionManager {
 public:
  OptionManager(std::string command, std::string description);

  // The program named by the usage line and the errors: "colmap <command>" unless set
  // (fvs_train_main sets its own name).
  void SetProgram(std::string program);

  // `name` without the leading dashes, e.g. "workspace_path" or "Stereo.backend".
  void AddRequired(const std::string& name, std::string* value, const std::string& help);
  void AddDefault(const std::string& name, std::string* value, const std::string& help);
  void AddDefault(const std::string& name, int* value, const std::string& help);
  void AddDefault(const std::string& name, double* value, const std::string& help);
  void AddDefault(const std::string& name, bool* value, const std::string& help);

  // Parses argv[first..argc). Returns false when help was asked for (printed to stdout):
  // the caller returns 0. Throws fvs::Error with one line for an unknown or ambiguous
  // option, a missing value, a value that does not parse, or a missing required option.
  // `--name` may leave out the section of `--Section.name` when no other option ends in
  // that name. Booleans read 1/0, true/false, on/off, yes/no (any case).
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
  Option* Find(const std::string& name);

  std::string command_;
  std::string program_;
  std::string description_;
  std::vector<Option> options_;
};

}  // namespace fvs
