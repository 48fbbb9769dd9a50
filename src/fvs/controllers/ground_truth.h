// Ground-truth frames of a render (view_synthesis --ground_truth_path G): the image of a
// frame named N is G/N.png, .jpg, .JPG or .jpeg. A ground truth of another size than its
// frame is an error (it is not the frame it claims to be), reported as one line naming
// the file.
#pragma once

#include <string>

#include "fvs/geometry/camera.h"
#include "fvs/util/image.h"

namespace fvs {

// The ground-truth image of frame `name` in `dir`; empty when `dir` is empty or has none.
std::string GroundTruthFile(const std::string& dir, const std::string& name);

// Checks from its header only that the ground truth of frame `name`, if there is one,
// has the size of `camera`: run on every target before the first frame, so that a bad
// one writes nothing. Throws fvs::Error otherwise.
void CheckGroundTruth(const std::string& dir, const std::string& name,
                      const PinholeCamera& camera);

// PSNR of a rendered frame against its ground truth; -1 without one. Throws fvs::Error
// for a ground truth of another size.
double FramePsnr(const std::string& dir, const std::string& name, const Image& color);

}  // namespace fvs
