// Reading and writing COLMAP sparse models (cameras, images, points3D) in the binary
// (.bin) and text (.txt) formats of COLMAP 3.8, bit-exact both ways. Bad files throw
// fvs::Error naming the file and the fault (truncated, unknown camera model, wrong
// parameter count, non-finite pose, dangling ids). Writers are atomic per file.
#pragma once

#include <string>

#include "colmap_ext/reconstruction.h"

namespace fvs::colmap {

// Reads <dir>/{cameras,images,points3D}.bin if present, else the .txt files.
Reconstruction ReadSparseModel(const std::string& dir);
Reconstruction ReadSparseModelBinary(const std::string& dir);
Reconstruction ReadSparseModelText(const std::string& dir);

// Creates `dir` if needed.
void WriteSparseModelBinary(const std::string& dir, const Reconstruction& reconstruction);
void WriteSparseModelText(const std::string& dir, const Reconstruction& reconstruction);

}  // namespace fvs::colmap
