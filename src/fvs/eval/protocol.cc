#include "fvs/eval/protocol.h"

#include <algorithm>
#include <cctype>
#include <filesystem>
#include <fstream>

#include "fvs/util/error.h"
#include "fvs/util/string_util.h"

namespace fvs::eval {
namespace {

const char kWho[] = "colmap view_synthesis_eval";

bool IsNonNegativeInteger(const std::string& s) {
  if (s.empty() || s.size() > 9) return false;
  return std::all_of(s.begin(), s.end(),
                     [](char c) { return std::isdigit(static_cast<unsigned char>(c)); });
}

std::vector<std::string> SplitList(const std::string& list) {
  std::vector<std::string> items;
  for (const std::string& item : SplitString(list, ",")) {
    const std::string trimmed = TrimString(item);
    if (!trimmed.empty()) items.push_back(trimmed);
  }
  return items;
}

void ParseSubsequence(const std::string& spec, int* start, int* length) {
  const std::vector<std::string> parts = SplitString(spec, ":");
  Require(parts.size() == 2 && IsNonNegativeInteger(TrimString(parts[0])) &&
              IsNonNegativeInteger(TrimString(parts[1])) &&
              std::stoi(TrimString(parts[1])) > 0,
          "--subsequence", "'" + spec + "' is not START:LENGTH (e.g. 10:5)");
  *start = std::stoi(TrimString(parts[0]));
  *length = std::stoi(TrimString(parts[1]));
}

}  // namespace

void ProtocolOptions::Check() const {
  Require(
      protocol == "auto" || protocol == "holdout" || protocol == "leave_one_out" ||
          protocol == "subsequence" || protocol == "indices",
      kWho,
      "--protocol must be auto, holdout, leave_one_out, subsequence or indices, not '" +
          protocol + "'");
  Require(every >= 1, kWho, "--every must be at least 1");
  if (protocol == "subsequence") {
    int start = 0, length = 0;
    ParseSubsequence(subsequence, &start, &length);
  }
  if (protocol == "indices") {
    Require(!target_indices.empty() || !target_names.empty(), kWho,
            "--protocol indices needs --target_indices or --target_names");
    for (const std::string& item : SplitList(target_indices)) {
      Require(IsNonNegativeInteger(item), "--target_indices",
              "'" + item + "' is not a non-negative integer");
    }
  }
}

TargetSet SelectTargets(const std::vector<std::string>& unsorted_names,
                        const std::set<std::string>& holdout,
                        const ProtocolOptions& options) {
  options.Check();
  std::vector<std::string> names = unsorted_names;
  std::sort(names.begin(), names.end());
  auto position_of = [&](const std::string& name) {
    const auto it = std::lower_bound(names.begin(), names.end(), name);
    return (it != names.end() && *it == name) ? static_cast<int>(it - names.begin()) : -1;
  };

  TargetSet set;
  set.protocol = options.protocol;
  if (set.protocol == "auto")
    set.protocol = holdout.empty() ? "leave_one_out" : "holdout";

  auto add_name = [&](const std::string& name) {
    EvalTarget t;
    t.name = name;
    t.position = position_of(name);
    t.geometry_holdout = holdout.count(name) > 0;
    if (t.position < 0) t.error = "not a registered image of the model";
    set.targets.push_back(t);
  };
  auto add_position = [&](int position) {
    if (position < static_cast<int>(names.size())) {
      add_name(names[position]);
    } else {
      EvalTarget t;
      t.name = "#" + std::to_string(position);
      t.error = "position " + std::to_string(position) + " is past the " +
                std::to_string(names.size()) + " registered images";
      set.targets.push_back(t);
    }
  };

  if (set.protocol == "holdout") {
    Require(
        !holdout.empty(), kWho,
        "--protocol holdout: the workspace has no held-out images (W/fvs/holdout.txt; "
        "prepare with --holdout_images)");
    for (const std::string& name : holdout) {
      add_name(name);
      if (set.targets.back().position < 0) {
        set.targets.back().skipped = true;
        set.targets.back().error =
            "held out but not registered by SfM: no pose to render "
            "(W/fvs/registration.json)";
      }
    }
  } else if (set.protocol == "leave_one_out") {
    for (int i = 0; i < static_cast<int>(names.size()); i += options.every) {
      add_name(names[i]);
    }
  } else if (set.protocol == "subsequence") {
    int start = 0, length = 0;
    ParseSubsequence(options.subsequence, &start, &length);
    Require(start < static_cast<int>(names.size()), "--subsequence",
            "starts at " + std::to_string(start) + ", past the " +
                std::to_string(names.size()) + " registered images");
    for (int i = start; i < std::min<int>(start + length, names.size()); ++i) {
      add_name(names[i]);
    }
  } else {  // indices
    for (const std::string& item : SplitList(options.target_indices)) {
      add_position(std::stoi(item));
    }
    for (const std::string& name : SplitList(options.target_names)) add_name(name);
  }

  // Every protocol but leave-one-out withholds its whole target set from the sources.
  if (set.protocol != "leave_one_out") {
    for (const EvalTarget& t : set.targets) {
      if (t.error.empty()) set.excluded_sources.insert(t.name);
    }
  }
  Require(!set.targets.empty(), kWho, "the protocol selects no target views");
  return set;
}

std::set<std::string> ReadHoldoutNames(const std::string& workspace_path) {
  std::set<std::string> names;
  const std::string path = JoinPaths(workspace_path, "fvs/holdout.txt");
  if (!std::filesystem::exists(path)) return names;
  std::ifstream in(path);
  Require(in.good(), path, "cannot be read");
  std::string line;
  while (std::getline(in, line)) {
    line = TrimString(line);
    if (!line.empty() && line[0] != '#') names.insert(line);
  }
  return names;
}

}  // namespace fvs::eval
