#include "colmap_ext/photo_metadata.h"

#include <OpenImageIO/imagebuf.h>
#include <OpenImageIO/imagebufalgo.h>
#include <OpenImageIO/imageio.h>

#include <cmath>
#include <cstdio>
#include <filesystem>

#include "fvs/util/atomic_file.h"
#include "fvs/util/error.h"
#include "fvs/util/string_util.h"

namespace fvs::colmap {
namespace {

namespace OIIO = OIIO_NAMESPACE;

std::string Attribute(const OIIO::ImageSpec& spec, const char* name) {
  return TrimString(spec.get_string_attribute(name));
}

}  // namespace

PhotoMetadata ReadPhotoMetadata(const std::string& path) {
  auto input = OIIO::ImageInput::open(path);
  if (!input) {
    std::string message = OIIO::geterror();
    if (message.empty()) message = "cannot open image";
    throw Error(path, "cannot read image (" + message + ")");
  }
  const OIIO::ImageSpec& spec = input->spec();
  PhotoMetadata m;
  m.stored_width = spec.width;
  m.stored_height = spec.height;
  m.format = input->format_name();
  const int orientation = spec.get_int_attribute("Orientation", 1);
  m.orientation = orientation >= 1 && orientation <= 8 ? orientation : 1;
  m.make = Attribute(spec, "Make");
  m.model = Attribute(spec, "Model");
  m.lens = Attribute(spec, "Exif:LensModel");
  const float focal = spec.get_float_attribute("Exif:FocalLength", 0.0f);
  m.focal_length_mm = std::isfinite(focal) && focal > 0 ? focal : 0.0;
  input->close();
  if (m.stored_width <= 0 || m.stored_height <= 0) {
    throw Error(path, "cannot read image (no pixels)");
  }
  return m;
}

void WriteUprightPhoto(const std::string& source, const std::string& target) {
  OIIO::ImageBuf in(source);
  if (!in.read(0, 0, true)) {
    throw Error(source, "cannot read image (" + in.geterror() + ")");
  }
  OIIO::ImageBuf upright = OIIO::ImageBufAlgo::reorient(in);
  if (upright.has_error()) {
    throw Error(source, "cannot turn the photo upright (" + upright.geterror() + ")");
  }
  OIIO::ImageSpec& spec = upright.specmod();
  spec.attribute("Orientation", 1);
  spec.attribute("CompressionQuality", 95);
  spec.attribute("Compression", "jpeg:95");
  // The temporary keeps the extension: OIIO chooses the format from it.
  const std::string ext = std::filesystem::path(target).extension().string();
  const std::string temp = TempPathFor(target) + ext;
  if (!upright.write(temp)) {
    const std::string message = upright.geterror();
    std::remove(temp.c_str());
    throw Error(target, "cannot write image (" + message + ")");
  }
  CommitTempFile(temp, target);
}

}  // namespace fvs::colmap
