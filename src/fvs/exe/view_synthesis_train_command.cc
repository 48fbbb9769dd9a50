// colmap view_synthesis_train --scene_list L --output_path M: trains the view-synthesis
// network on packed scenes (view_synthesis_pack), resuming from the newest valid
// checkpoint in M. The options are shared with the standalone fvs_train_main
// (train/train_options.h), which has no OptionManager in the trainer-only build.
#include <iostream>

#include "fvs/exe/command_registry.h"
#include "fvs/train/train_options.h"
#include "fvs/util/folder_lock.h"

namespace fvs {
namespace {

int RunViewSynthesisTrain(int argc, char** argv) {
  TrainOptions options;
  if (!ParseTrainOptions(argc, argv, 2, &options)) return 0;
  const FolderLock lock(options.output_path, "view_synthesis_train");
  const TrainSummary summary = RunTraining(options);
  // 130 as a shell reports an interrupted program: a checkpoint was written, run again.
  return summary.interrupted ? 130 : 0;
}

}  // namespace

FVS_REGISTER_COMMAND("view_synthesis_train",
                     "train the view-synthesis network on packed scenes (resumable)",
                     RunViewSynthesisTrain);

}  // namespace fvs
