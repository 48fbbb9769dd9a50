#include "colmap_ext/sparse_io.h"

#include <sys/stat.h>

#include "fvs/util/error.h"

namespace fvs::colmap {
namespace {

bool IsFile(const std::string& path) {
  struct stat st;
  return ::stat(path.c_str(), &st) == 0 && S_ISREG(st.st_mode);
}

}  // namespace

Reconstruction ReadSparseModel(const std::string& dir) {
  struct stat st;
  if (::stat(dir.c_str(), &st) != 0 || !S_ISDIR(st.st_mode)) {
    throw Error(dir, "sparse model folder does not exist");
  }
  if (IsFile(dir + "/cameras.bin") || IsFile(dir + "/images.bin") ||
      IsFile(dir + "/points3D.bin")) {
    return ReadSparseModelBinary(dir);
  }
  if (IsFile(dir + "/cameras.txt") || IsFile(dir + "/images.txt") ||
      IsFile(dir + "/points3D.txt")) {
    return ReadSparseModelText(dir);
  }
  throw Error(dir,
              "no sparse model here (neither cameras.bin/images.bin/points3D.bin nor "
              "the .txt files)");
}

}  // namespace fvs::colmap
