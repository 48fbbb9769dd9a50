// Photos as phones make them, before COLMAP sees them (issue 42): HEIC/HEIF, which
// COLMAP cannot read, and photos stored rotated with an EXIF orientation tag, which
// COLMAP would use on their side, are written upright into W/fvs/photos (once; the stage
// is skipped when done), beside links to the photos that need nothing. A folder that
// needs neither is used as it is, so workspaces of such folders stay as they were. The
// photos are also grouped by the camera that took them, one COLMAP camera per group.
#pragma once

#include <string>
#include <vector>

#include "colmap_ext/photo_metadata.h"

namespace fvs {

struct PlannedPhoto {
  std::string source;  // the file's name in the user's folder
  std::string name;    // its name where COLMAP reads it: `source`, or `source`.jpg for
                       // a HEIF photo (the format must show in the name)
  colmap::PhotoMetadata metadata;
  bool convert = false;  // written upright by the import (HEIF, or rotated)
  std::string camera;    // what identifies the camera: make, model, lens, focal, size
};

struct PhotoImportPlan {
  std::vector<PlannedPhoto> photos;  // in the order of the names given
  bool needed() const;               // some photo must be converted
  int num_converted() const;
  // Names (PlannedPhoto::name) per camera, in order of first appearance.
  std::vector<std::vector<std::string>> CameraGroups() const;
  // The name COLMAP reads for a user's photo name (a source name, or already a name).
  // Throws fvs::Error when it is neither.
  std::string NameOf(const std::string& user_name) const;
};

// Reads every photo's header (throws fvs::Error naming a photo that cannot be read).
PhotoImportPlan PlanPhotoImport(const std::string& folder,
                                const std::vector<std::string>& names);

// Fills `target_folder`: the converted photos written upright (JPEG for HEIF and JPEG
// sources, PNG otherwise), the others as symbolic links to the originals. Files already
// there are replaced. Throws fvs::Error naming the file.
void ImportPhotos(const PhotoImportPlan& plan, const std::string& source_folder,
                  const std::string& target_folder);

}  // namespace fvs
