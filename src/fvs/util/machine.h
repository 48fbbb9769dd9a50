// What machine a number was measured on: every benchmark and timing report prints it.
#pragma once

#include <string>

namespace fvs {

// "model name" of /proc/cpuinfo, or "unknown CPU".
std::string CpuModelName();
// "nproc N, CPU <model>".
std::string DescribeMachine();
// User + system CPU seconds of this process, all threads: on a shared machine wall time
// alone says little, so benchmarks print both.
double ProcessCpuSeconds();

}  // namespace fvs
