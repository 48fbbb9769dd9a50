// Blurry and duplicate photos (issue 42, item 4): prepare measures every registered
// photo's sharpness and finds near-duplicate poses, writes W/fvs/photo_quality.json and
// lists the worst; the renderers use a blurry photo as a source of last resort.
//
// Sharpness: the mean squared Laplacian of the photo in grey at a fixed size (longest
// side kSharpnessSize, area-averaged), which blur of either kind (focus, motion) lowers
// most. It depends on the content and the camera too, so it is compared within the set:
// a photo is blurry when its sharpness is below `blur_ratio` times the median of its
// camera's photos (of the whole set's where its camera took fewer than three). A
// near-duplicate pair: cameras whose centres lie closer than `duplicate_distance` times
// the median distance from a camera to its nearest neighbour and whose viewing
// directions differ by less than `duplicate_degrees` (a burst, a shot taken twice).
//
// The rule for rendering (render/prepare.cc): blurry photos rank after every other
// source, so the adaptive choice takes one only for pixels no sharp photo sees and a
// fixed K only when fewer than K sharp photos see the target; RenderOptions::
// use_blurry_sources ranks them as any other. Duplicates are listed, not excluded (a
// duplicate adds no blur).
#pragma once

#include <Eigen/Core>
#include <string>
#include <utility>
#include <vector>

#include "fvs/util/image.h"

namespace fvs {

constexpr int kSharpnessSize = 512;

struct PhotoQualityOptions {
  double blur_ratio = 0.35;
  double duplicate_distance = 0.05;
  double duplicate_degrees = 2.0;
  void Check() const;
  std::string ToString() const;  // the stage's fingerprint
};

struct PhotoQuality {
  std::string name;
  double sharpness = 0;  // mean squared Laplacian, grey in [0, 1], at kSharpnessSize
  double relative = 0;   // sharpness / the median it is compared with
  bool blurry = false;
  std::vector<std::string> duplicates;  // names of the near-duplicates of this photo
};

struct PhotoQualityReport {
  double median_sharpness = 0;
  std::vector<PhotoQuality> photos;  // in the model's image order
  int num_blurry() const;
  int num_with_duplicates() const;
  // One line for the log and the GUI: how many blurry, the worst few, the duplicates.
  std::string Summary(int max_names = 5) const;
};

// The sharpness of one photo (any size, RGB or grey); finite, >= 0.
double Sharpness(const Image& photo);

// Near-duplicate pairs (indices into `centres`, i < j) by the rule above; `directions`
// are the unit viewing directions.
std::vector<std::pair<int, int>> NearDuplicatePairs(
    const std::vector<Eigen::Vector3d>& centres,
    const std::vector<Eigen::Vector3d>& directions, const PhotoQualityOptions& options);

// Measures the photos of W/sparse in W/images (progress on stderr).
PhotoQualityReport MeasurePhotoQuality(const std::string& workspace_path,
                                       const PhotoQualityOptions& options);

// W/fvs/photo_quality.json (atomic) and back; reading a missing file gives an empty
// report, a broken one throws fvs::Error naming it.
void WritePhotoQualityReport(const std::string& path, const PhotoQualityReport& report);
PhotoQualityReport ReadPhotoQualityReport(const std::string& path);
std::string PhotoQualityPath(const std::string& workspace_path);

}  // namespace fvs
