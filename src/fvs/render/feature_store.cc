#include "fvs/render/feature_store.h"

#include <algorithm>
#include <cstring>
#include <filesystem>
#include <iostream>

#include "fvs/util/atomic_file.h"
#include "fvs/util/error.h"
#include "fvs/util/hash.h"
#include "fvs/util/safetensors.h"
#include "fvs/util/string_util.h"

namespace fvs {
namespace {

bool ToSafeDtype(torch::ScalarType type, SafeDtype* out) {
  switch (type) {
    case torch::kFloat32:
      *out = SafeDtype::kF32;
      return true;
    case torch::kBFloat16:
      *out = SafeDtype::kBF16;
      return true;
    case torch::kHalf:
      *out = SafeDtype::kF16;
      return true;
    default:
      return false;
  }
}

}  // namespace

FeatureStore::FeatureStore(const std::string& dir, const std::string& model_path,
                           const std::string& variant, const std::string& precision,
                           int64_t max_bytes)
    : dir_(dir), max_bytes_(max_bytes) {
  weights_hash_ = HexHash(HashFile(model_path));
  folder_ = JoinPaths(dir, variant + "-" + weights_hash_ + "-" + precision);
  std::error_code ec;
  std::filesystem::create_directories(folder_, ec);
  Require(!ec, folder_, "cannot create the feature cache folder: " + ec.message());
}

std::string FeatureStore::PathFor(const Image& photo) const {
  const int64_t size[3] = {photo.width, photo.height, photo.channels};
  const uint64_t seed = Hash64(size, sizeof(size));
  return JoinPaths(folder_, HexHash(Hash64(photo.data.data(),
                                           photo.data.size() * sizeof(float), seed)) +
                                ".safetensors");
}

torch::Tensor FeatureStore::Load(const std::string& path, int64_t channels,
                                 const Image& photo, torch::ScalarType dtype) const {
  std::error_code ec;
  if (!std::filesystem::exists(path, ec)) return {};
  try {
    const SafeTensorsFile file = ReadSafeTensors(path);
    const SafeTensor* t = file.Find("features");
    Require(t != nullptr, path, "no tensor 'features'");
    SafeDtype want;
    Require(ToSafeDtype(dtype, &want) && t->dtype == want, path,
            "features are " + SafeDtypeName(t->dtype) + ", this run needs " +
                std::string(c10::toString(dtype)));
    const std::vector<int64_t> shape = {1, channels, photo.height, photo.width};
    Require(t->shape == shape, path,
            "features of shape " + ShapeString(t->shape) + ", expected " +
                ShapeString(shape));
    torch::Tensor out = torch::empty(shape, torch::TensorOptions().dtype(dtype));
    std::memcpy(out.data_ptr(), t->data.data(), t->data.size());
    // Recently used: the last to go when the folder is over its limit.
    std::filesystem::last_write_time(path, std::filesystem::file_time_type::clock::now(),
                                     ec);
    return out;
  } catch (const std::exception& e) {
    std::cerr << "WARNING: " << e.what() << "; encoding that source again\n";
    return {};
  }
}

void FeatureStore::Save(const std::string& path, const torch::Tensor& features,
                        const std::string& photo_name) const {
  try {
    const torch::Tensor cpu = features.detach().to(torch::kCPU).contiguous();
    SafeTensor t;
    t.name = "features";
    Require(ToSafeDtype(cpu.scalar_type(), &t.dtype), path, "unsupported feature dtype");
    t.shape = cpu.sizes().vec();
    t.data.resize(cpu.numel() * cpu.element_size());
    std::memcpy(t.data.data(), cpu.data_ptr(), t.data.size());
    SafeTensorsFile file;
    file.Add(std::move(t));
    file.metadata["photo"] = photo_name;
    file.metadata["weights_hash"] = weights_hash_;
    WriteSafeTensors(path, file);
  } catch (const std::exception& e) {
    std::cerr << "WARNING: " << e.what() << "; features of " << photo_name
              << " not kept on disk\n";
    return;
  }
  Prune(path);
}

void FeatureStore::Prune(const std::string& keep) const {
  struct Stored {
    std::filesystem::file_time_type time;
    std::string path;
    int64_t bytes;
  };
  std::vector<Stored> files;
  int64_t total = 0;
  std::error_code ec;
  for (auto it = std::filesystem::recursive_directory_iterator(dir_, ec);
       !ec && it != std::filesystem::recursive_directory_iterator(); it.increment(ec)) {
    if (!it->is_regular_file(ec) || it->path().extension() != ".safetensors") continue;
    // Either query fails when the file was removed meanwhile (another process pruning);
    // each is checked, as a later success clears the error code.
    Stored f{it->last_write_time(ec), it->path().string(), 0};
    if (ec) continue;
    f.bytes = static_cast<int64_t>(it->file_size(ec));
    if (ec) continue;
    total += f.bytes;
    if (f.path != keep) files.push_back(std::move(f));
  }
  std::sort(files.begin(), files.end(),
            [](const Stored& a, const Stored& b) { return a.time < b.time; });
  for (const Stored& f : files) {
    if (total <= max_bytes_) break;
    if (std::filesystem::remove(f.path, ec)) total -= f.bytes;
  }
}

}  // namespace fvs
