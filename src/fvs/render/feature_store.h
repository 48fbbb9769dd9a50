// Encoded source features kept on disk (RenderOptions::feature_cache_dir), so that
// another run over the same workspace and weights (a second camera path, a re-render,
// the shards of an array job) reads them instead of encoding the sources again.
//
// One safetensors file per source photo, "<dir>/<variant>-<weights hash>-<precision>/
// <photo hash>.safetensors", holding the features exactly as encoded (the run's dtype,
// [1,C,H,W]): a render from stored features equals one from fresh features to the bit.
// Keys are content hashes (of the weights file, of the source's pixels as loaded), so
// changed weights or a changed photo never read stale features. Written atomically;
// a file that is unreadable or of the wrong shape or dtype is reported in one warning
// line and encoded again. The whole folder (all weights) is kept under a size limit, the
// least recently used files (by modification time, refreshed on every read) removed
// first. Included by fvs_method.cc only (LibTorch).
#pragma once

#include <torch/torch.h>

#include <cstdint>
#include <string>

#include "fvs/util/image.h"

namespace fvs {

class FeatureStore {
 public:
  // Hashes the weights file (tens of ms for the reference network's). max_bytes: the
  // limit for all of `dir`.
  FeatureStore(const std::string& dir, const std::string& model_path,
               const std::string& variant, const std::string& precision,
               int64_t max_bytes);

  // The file for a source photo (as the renderer loaded it).
  std::string PathFor(const Image& photo) const;
  // Stored features of shape [1, channels, photo height, photo width] and this dtype, or
  // an undefined tensor when there are none (or they do not fit: a warning).
  torch::Tensor Load(const std::string& path, int64_t channels, const Image& photo,
                     torch::ScalarType dtype) const;
  // Best effort: a full disk or a read-only folder gives a warning, not an error. Then
  // removes the least recently used files of the folder beyond the size limit (never
  // the one just written).
  void Save(const std::string& path, const torch::Tensor& features,
            const std::string& photo_name) const;

  const std::string& folder() const { return folder_; }

 private:
  void Prune(const std::string& keep) const;

  std::string dir_;
  std::string folder_;
  std::string weights_hash_;
  int64_t max_bytes_;
};

}  // namespace fvs
