#include "fvs/util/machine.h"

#include <sys/resource.h>

#include <fstream>
#include <thread>

#include "fvs/util/string_util.h"

namespace fvs {

std::string CpuModelName() {
  std::ifstream in("/proc/cpuinfo");
  std::string line;
  while (std::getline(in, line)) {
    if (StartsWith(line, "model name")) {
      const size_t colon = line.find(':');
      if (colon != std::string::npos) return TrimString(line.substr(colon + 1));
    }
  }
  return "unknown CPU";
}

std::string DescribeMachine() {
  return "nproc " + std::to_string(std::thread::hardware_concurrency()) + ", CPU " +
         CpuModelName();
}

double ProcessCpuSeconds() {
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  return usage.ru_utime.tv_sec + usage.ru_stime.tv_sec +
         1e-6 * (usage.ru_utime.tv_usec + usage.ru_stime.tv_usec);
}

}  // namespace fvs
