#include "fvs/path/video.h"

#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>

#include "fvs/util/atomic_file.h"
#include "fvs/util/error.h"
#include "fvs/util/progress.h"
#include "fvs/util/string_util.h"

namespace fvs {

namespace fs = std::filesystem;

namespace {

bool Executable(const std::string& path) {
  return !path.empty() && fs::is_regular_file(path) && access(path.c_str(), X_OK) == 0;
}

std::string ShellQuote(const std::string& s) {
  std::string out = "'";
  for (char c : s) {
    if (c == '\'') {
      out += "'\\''";
    } else {
      out += c;
    }
  }
  return out + "'";
}

}  // namespace

std::string FindFfmpeg() {
  if (const char* env = std::getenv("FVS_FFMPEG")) {
    return Executable(env) ? std::string(env) : std::string();
  }
  const char* path = std::getenv("PATH");
  if (!path) return "";
  for (const std::string& dir : SplitString(path, ":")) {
    if (dir.empty()) continue;
    const std::string candidate = JoinPaths(dir, "ffmpeg");
    if (Executable(candidate)) return candidate;
  }
  return "";
}

VideoResult EncodeVideo(const std::vector<std::string>& frame_paths, double fps,
                        const std::string& output_path) {
  VideoResult result;
  Require(!frame_paths.empty(), output_path, "no frames to encode");
  Require(std::isfinite(fps) && fps > 0, output_path, "fps must be positive");
  for (const std::string& f : frame_paths) Require(fs::exists(f), f, "frame missing");
  const std::string ffmpeg = FindFfmpeg();
  if (ffmpeg.empty()) {
    result.note = "ffmpeg not found (install it, or set FVS_FFMPEG): no " + output_path +
                  " written; the frames are the PNGs";
    return result;
  }
  Timer timer;
  // ffmpeg wants numbered names: links in a scratch folder beside the output.
  const fs::path out = fs::absolute(output_path);
  if (!out.parent_path().empty()) fs::create_directories(out.parent_path());
  const fs::path scratch = out.parent_path() / (".fvs_video_" + std::to_string(getpid()));
  fs::remove_all(scratch);
  fs::create_directories(scratch);
  struct Cleanup {
    fs::path dir;
    ~Cleanup() {
      std::error_code ec;
      fs::remove_all(dir, ec);
    }
  } cleanup{scratch};
  for (size_t i = 0; i < frame_paths.size(); ++i) {
    char name[32];
    std::snprintf(name, sizeof(name), "%06zu.png", i);
    fs::create_symlink(fs::absolute(frame_paths[i]), scratch / name);
  }
  const std::string temp = (scratch / ("video" + out.extension().string())).string();
  char rate[64];
  std::snprintf(rate, sizeof(rate), "%.9g", fps);
  const std::string log = (scratch / "ffmpeg.log").string();
  const std::string command = ShellQuote(ffmpeg) +
                              " -nostdin -y -loglevel error -framerate " + rate + " -i " +
                              ShellQuote((scratch / "%06d.png").string()) + " -vf " +
                              ShellQuote("pad=ceil(iw/2)*2:ceil(ih/2)*2") +
                              " -c:v libx264 -pix_fmt yuv420p -crf 18 " +
                              ShellQuote(temp) + " > " + ShellQuote(log) + " 2>&1";
  const int status = std::system(command.c_str());
  if (status != 0 || !fs::exists(temp) || fs::file_size(temp) == 0) {
    std::string message;
    try {
      message = TrimString(ReadFileToString(log));
    } catch (const Error&) {
    }
    if (message.size() > 300) message = message.substr(message.size() - 300);
    for (char& c : message) {
      if (c == '\n') c = ' ';
    }
    throw Error(output_path, "ffmpeg (" + ffmpeg + ") failed: " + message);
  }
  fs::rename(temp, out);
  result.written = true;
  result.seconds = timer.Seconds();
  result.note = "wrote " + output_path + " (" + std::to_string(frame_paths.size()) +
                " frames, H.264, " + rate + " fps)";
  return result;
}

}  // namespace fvs
