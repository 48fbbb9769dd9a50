// What prepare needs to know of a user's photo before COLMAP reads it: its size, the
// EXIF orientation, the camera that took it; and an upright copy for the photos COLMAP
// cannot use as they are (HEIC/HEIF, which COLMAP cannot read; a stored-rotated photo,
// which COLMAP would use on its side).
#pragma once

#include <string>

namespace fvs::colmap {

struct PhotoMetadata {
  int stored_width = 0, stored_height = 0;  // the pixels as the file stores them
  // EXIF orientation 1-8 (1: upright as stored; 5-8 swap width and height). HEIF
  // decoders apply the file's own transforms, so HEIF photos read as 1.
  int orientation = 1;
  std::string format;            // the reader's name: "jpeg", "png", "heif", ...
  std::string make, model;       // EXIF camera make and model, trimmed; empty if absent
  std::string lens;              // EXIF lens model (a phone's wide / tele lens)
  double focal_length_mm = 0.0;  // EXIF FocalLength; 0 if absent

  int width() const { return orientation >= 5 ? stored_height : stored_width; }
  int height() const { return orientation >= 5 ? stored_width : stored_height; }
};

// Reads the header only. Throws fvs::Error(path, "cannot read image (...)").
PhotoMetadata ReadPhotoMetadata(const std::string& path);

// Writes the photo at `source` upright (its EXIF orientation applied) to `target`,
// JPEG at quality 95 or PNG by `target`'s extension, keeping its EXIF (camera make and
// model, focal lengths: COLMAP's first guess of the intrinsics) with orientation 1.
// Atomic (temporary + rename). Throws fvs::Error naming the file.
void WriteUprightPhoto(const std::string& source, const std::string& target);

}  // namespace fvs::colmap
