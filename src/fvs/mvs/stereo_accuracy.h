// Accuracy of depth maps against exact ground truth, as the stereo tests and the
// benchmark report it: the fraction of textured pixels within 1% relative depth error,
// and the full histogram of relative errors (pixels without depth counted in their own
// bin).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "fvs/util/image.h"

namespace fvs::mvs {

// Textured: the grey image has a central-difference gradient of at least `min_gradient`
// within `radius` pixels (the NCC window needs contrast to match anything).
std::vector<uint8_t> TexturedMask(const Image& grey, float min_gradient = 0.02f,
                                  int radius = 2);

class DepthErrorHistogram {
 public:
  static constexpr int kNumBins = 9;  // 7 edges, > last edge, no depth

  // Adds pixels where gt > 0 and (mask empty or mask[i]); depth and gt same size.
  void Add(const Image& depth, const Image& gt, const std::vector<uint8_t>& mask = {});
  void Add(double depth, double gt);

  int64_t total() const { return total_; }
  double Fraction(int bin) const;
  // Fraction of pixels with a depth within `relative_error` (an edge: 0.001 ... 0.1).
  double FractionWithin(double relative_error) const;
  double FractionWithoutDepth() const { return Fraction(kNumBins - 1); }
  // Multi-line table: "label: N pixels, within 1%: x" then one line per bin.
  std::string ToString(const std::string& label) const;

 private:
  int64_t counts_[kNumBins] = {0};
  int64_t total_ = 0;
};

}  // namespace fvs::mvs
