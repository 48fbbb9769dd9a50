// fvs_train_main: the trainer on its own, for a GPU machine that has LibTorch but none of
// COLMAP, CGAL, Qt or OpenImageIO (doc/training.md). Same options as
// `colmap view_synthesis_train`.
#include <csignal>
#include <exception>
#include <iostream>

#include "fvs/train/train_options.h"
#include "fvs/util/error.h"

int main(int argc, char** argv) {
  // As in the front door (exe/main.cc): past a file-size limit a write fails with EFBIG
  // and is reported, instead of SIGXFSZ killing the process mid-checkpoint.
  std::signal(SIGXFSZ, SIG_IGN);
  try {
    fvs::TrainOptions options;
    if (!fvs::ParseTrainOptions(argc, argv, 1, &options)) return 0;
    const fvs::TrainSummary summary = fvs::RunTraining(options);
    return summary.interrupted ? 130 : 0;
  } catch (const std::exception& e) {
    std::cerr << "ERROR: " << e.what() << "\n";
    return 1;
  }
}
