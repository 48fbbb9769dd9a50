#include "fvs/eval/sweep.h"

#include <cmath>
#include <map>

#include "fvs/net/model_config.h"
#include "fvs/render/method.h"
#include "fvs/util/error.h"
#include "fvs/util/safetensors.h"
#include "fvs/util/string_util.h"

namespace fvs::eval {
namespace {

std::vector<std::string> Items(const std::string& list) {
  std::vector<std::string> items;
  for (const std::string& item : SplitString(list, ",")) {
    const std::string trimmed = TrimString(item);
    if (!trimmed.empty()) items.push_back(trimmed);
  }
  return items;
}

}  // namespace

std::vector<double> ParseDoubleList(const std::string& list, const std::string& option) {
  std::vector<double> values;
  for (const std::string& item : Items(list)) {
    size_t used = 0;
    double v = 0;
    try {
      v = std::stod(item, &used);
    } catch (const std::exception&) {
      used = 0;
    }
    Require(used == item.size() && std::isfinite(v) && v > 0 && v <= 4, option,
            "'" + item + "' is not a scale in (0, 4]");
    values.push_back(v);
  }
  Require(!values.empty(), option, "empty list");
  return values;
}

void SweepOptions::Check() const {
  Require(!Items(methods).empty(), "--sweep_methods", "empty list");
  for (const std::string& k : Items(num_sources))
    ParseNumSources(k, "--sweep_num_sources");
  Require(!Items(num_sources).empty(), "--sweep_num_sources", "empty list");
  ParseDoubleList(scales, "--sweep_scales");
  for (const std::string& p : Items(precisions)) {
    Require(KnownPrecision(p), "--sweep_precisions",
            "'" + p + "': must be fp32, bf16 or fp16");
  }
}

std::string WeightsVariant(const std::string& path) {
  const SafeTensorsFile file = ReadSafeTensors(path);
  const auto it = file.metadata.find("fvs_config");
  Require(it != file.metadata.end(), path,
          "no fvs_config in the metadata: not a weights file of this project");
  return ModelConfig::FromJson(it->second).variant;
}

SweepPlan PlanSweep(const SweepOptions& options) {
  options.Check();
  SweepPlan plan;
  std::map<std::string, std::string> weights;  // variant -> file
  for (const std::string& path : Items(options.model_paths)) {
    weights.emplace(WeightsVariant(path), path);
  }
  std::vector<int> ks;  // 0 = adaptive
  for (const std::string& k : Items(options.num_sources)) {
    ks.push_back(ParseNumSources(k, "--sweep_num_sources"));
  }
  const std::vector<double> scales = ParseDoubleList(options.scales, "--sweep_scales");
  for (const std::string& method : Items(options.methods)) {
    std::string model_path;
    if (TraitsOfMethod(method).needs_weights) {
      if (method == "fvs" && !weights.empty() && !weights.count("fvs")) {
        // "fvs" accepts any variant; but each file is swept under its own name below.
        plan.notes.push_back(
            "fvs: no weights of the reference variant; the given files "
            "are swept under their own variant names");
        continue;
      }
      const auto it = weights.find(method);
      if (it == weights.end()) {
        plan.notes.push_back(method +
                             ": skipped, no weights of this variant given "
                             "(--sweep_model_paths or --model_path)");
        continue;
      }
      model_path = it->second;
    }
    for (const std::string& precision : Items(options.precisions)) {
      // The classical methods compute in fp32 (double for geometry) only.
      if (model_path.empty() && precision != "fp32") continue;
      for (double scale : scales) {
        for (int k : ks) {
          const bool one_source = TraitsOfMethod(method).single_source;
          if (one_source && k != ks.front()) continue;
          EvalConfig c;
          c.method = method;
          c.num_sources = one_source ? 1 : k;
          c.scale = scale;
          c.precision = precision;
          c.model_path = model_path;
          plan.configs.push_back(c);
        }
      }
    }
  }
  Require(!plan.configs.empty(), "--sweep", "no configuration to run");
  return plan;
}

}  // namespace fvs::eval
