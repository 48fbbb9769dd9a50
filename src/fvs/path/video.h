// Frames -> H.264 mp4 through the ffmpeg program, when there is one: $FVS_FFMPEG if set,
// else `ffmpeg` on the PATH. Without it the frames stay as they are and the caller prints
// the note (nothing here is required for rendering).
#pragma once

#include <string>
#include <vector>

namespace fvs {

// The ffmpeg to use, or "" when none is executable ($FVS_FFMPEG set to a missing file
// means none: that is how tests force the frames-only path).
std::string FindFfmpeg();

struct VideoResult {
  bool written = false;
  std::string note;  // why not, or what was written
  double seconds = 0;
};

// Encodes the PNG frames (in this order) at fps into output_path (H.264, yuv420p, sizes
// padded to even numbers), atomically (temp file then rename). Throws fvs::Error when
// ffmpeg exists but fails, or a frame is missing; returns written = false with a note
// when there is no ffmpeg.
VideoResult EncodeVideo(const std::vector<std::string>& frame_paths, double fps,
                        const std::string& output_path);

}  // namespace fvs
