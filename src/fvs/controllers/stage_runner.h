// How view_synthesis_prepare runs its stages (prepare_workspace.h): each records a
// fingerprint of its inputs and options, chained to the one before it, in
// W/fvs/manifest.json and is skipped when that is unchanged and its outputs exist; each
// writes into W/fvs/tmp/ and moves its output into place, so kill -9 at any point loses
// at most the stage that was running.
#pragma once

#include <functional>
#include <string>
#include <vector>

#include "fvs/util/manifest.h"

namespace fvs {

// Removes `path` (a file or a folder) if it exists; never throws.
void RemoveAll(const std::string& path);

// Replaces `to` by `from` (both folders or files) as atomically as the file system
// allows: the old output is moved aside first, so at every instant either the old or the
// new one is complete. Throws fvs::Error naming `to` when the move fails.
void MoveIntoPlace(const std::string& from, const std::string& to);

class StageRunner {
 public:
  // `total`: the number of stages, for the "[i/total]" log lines.
  StageRunner(Manifest manifest, int total);

  // Runs `run` unless the manifest says the stage is up to date: its chained fingerprint
  // (of `inputs`, `options` and the stages before) is recorded and `outputs` exist. Logs
  // the stage and its time on stderr; the manifest is saved before and after.
  void Run(const std::string& name, const std::vector<std::string>& inputs,
           const std::string& options, const std::vector<std::string>& outputs,
           const std::function<void()>& run);

 private:
  Manifest manifest_;
  std::string previous_;  // chained fingerprint digest
  int index_ = 0;
  int total_ = 0;
};

}  // namespace fvs
