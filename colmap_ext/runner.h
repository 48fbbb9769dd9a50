// Finding and running the real COLMAP executable: $FVS_COLMAP_BIN, else `colmap` on the
// PATH that is not our own front door. Probing what it can do (version, CUDA, CGAL) by
// running it, never by assuming (Debian's COLMAP 3.8 has neither CUDA nor CGAL).
#pragma once

#include <functional>
#include <string>
#include <vector>

namespace fvs::colmap {

struct ColmapCapabilities {
  std::string executable;
  std::string version;    // e.g. "3.8"
  bool has_cuda = false;  // patch_match_stereo works
  bool has_cgal = false;  // delaunay_mesher works
};

// Throws fvs::Error when no COLMAP executable can be found.
std::string FindColmapExecutable();
// Cached per process after the first call.
const ColmapCapabilities& ProbeColmap();

struct RunColmapOptions {
  // Called with each line COLMAP prints (stdout and stderr merged); default: lines are
  // shown on stderr only when FVS_VERBOSE=1, else a compact progress line.
  std::function<void(const std::string&)> on_line;
  std::string label;  // shown in progress and error messages, defaults to the command
};

// Runs `colmap <args...>`. Throws fvs::Error with one line ("colmap <command> failed
// (exit N): <the last error-looking line COLMAP printed>") on a non-zero exit or signal.
void RunColmap(const std::vector<std::string>& args,
               const RunColmapOptions& options = {});

}  // namespace fvs::colmap
