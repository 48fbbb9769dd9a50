// The trainer's side of the packed training set (pack.h): loading a scene.safetensors
// into tensors, leave-one-out source selection, the warp of a target crop into its
// sources (grid_sample grid and masks: the renderer's warp, geometry/warp.h), and the
// random sampler whose state a checkpoint stores. Reads only util/safetensors,
// geometry/warp.h and torch.
#pragma once

#include <torch/torch.h>

#include <cstdint>
#include <random>
#include <string>
#include <vector>

#include "fvs/geometry/warp.h"
#include "fvs/net/model_config.h"
#include "fvs/net/ulr_weights.h"

namespace fvs {

struct PackedScene {
  std::string path;  // the folder
  std::vector<std::string> names;
  torch::Tensor images;   // uint8 [N,3,H,W]
  torch::Tensor depths;   // float [N,H,W], 0 = no surface
  torch::Tensor K, R, t;  // double [N,3,3], [N,3,3], [N,3]
  torch::Tensor overlap;  // float [N,N], diagonal 0
  // Views held out of the geometry at prepare (the pack's "holdout" metadata): never a
  // source; a target only where IsTargetView says so.
  std::vector<bool> holdout;
  // World = scene frame + origin (the pack's "origin" metadata; zero when absent).
  Eigen::Vector3d origin = Eigen::Vector3d::Zero();
  bool HoldsViewsOut() const;

  int num_views() const { return static_cast<int>(names.size()); }
  int height() const { return static_cast<int>(images.size(2)); }
  int width() const { return static_cast<int>(images.size(3)); }
};

// A camera of the packed set (K [3,3], R [3,3], t [3], any floating type) as the warp's
// PinholeCamera (fx, fy, cx, cy of K) for an image of width x height.
PinholeCamera TensorCamera(const torch::Tensor& K, const torch::Tensor& R,
                           const torch::Tensor& t, int64_t width, int64_t height);

// Reads folder/scene.safetensors and checks every tensor (dtypes, shapes, finite values,
// depths >= 0, overlap in [0,1]); throws fvs::Error naming the file.
PackedScene LoadPackedScene(const std::string& folder);

// Every scene of a scene list (ReadSceneList, train_options.h), each with at least
// `min_views` views (training with k sources needs k + 1); throws fvs::Error naming the
// folder and the list otherwise.
std::vector<PackedScene> LoadPackedScenes(const std::string& list, int min_views, int k);

// Leave-one-out: the up to k views of highest overlap[target] (> 0 only), best first,
// ties by index; never the target itself nor a held-out view.
std::vector<int> SelectTrainingSources(const PackedScene& scene, int target, int k);

// Whether `view` may be a training or validation target. By default the views in the
// geometry (the held-out ones are kept for the reported evaluation). With
// `holdout_targets`, a scene that holds views out offers only those: like any novel view,
// no depth map of its own built the mesh they are rendered with. A scene holding none
// out offers all its views either way.
bool IsTargetView(const PackedScene& scene, int view, bool holdout_targets);

// The validation targets of a scene: `count` views evenly spaced over its target views
// (IsTargetView; fewer when the scene has fewer).
std::vector<int> ValidationTargets(const PackedScene& scene, int count,
                                   bool holdout_targets = false);

// How a training sample is warped: the renderer's warp (geometry/warp.h) and, for the
// prior and the baseline, the ULR log-weights.
struct SampleWarpOptions {
  WarpOptions geometry;  // occlusion test, what is at infinity
  // Also compute the ULR log-weights (the prior of ModelConfig::ulr_prior) with `ulr`.
  bool ulr_log_weights = false;
  UlrOptions ulr;
  void Check() const;  // throws fvs::Error
};

// The warp a network of `config` trains and validates with: at infinity when
// config.inf_depth, ULR log-weights with the config's ULR settings when it has a ULR
// prior (the trainer, the headroom and the render benchmark all warp this way).
SampleWarpOptions SampleWarpOptionsFor(const ModelConfig& config,
                                       double occlusion_tolerance);

struct TrainingWarp {
  torch::Tensor grid;         // float [K,h,w,2], grid_sample (align_corners = false)
  torch::Tensor valid_depth;  // float [1,1,h,w]
  torch::Tensor valid_warp;   // float [K,1,h,w]
  // float [K,1,h,w]: camera depth of each target pixel's point in each source (0 where
  // the target pixel has no surface), WarpMap::source_z.
  torch::Tensor source_z;
  // float [K,1,h,w], UlrLogWeights (only with SampleWarpOptions::ulr_log_weights).
  torch::Tensor ulr_log_weights;
};

// target_K/R/t: double [3,3], [3,3], [3]; target_depth float [h,w] (its camera's image
// size); source_K/R/t: double [K,3,3], [K,3,3], [K,3]; source_depths float [K,H,W].
// This is fvs::ComputeWarpMap (geometry/warp.h), the renderer's warp, run per source
// with these settings on the cameras and depths the tensors hold; its maps come back as
// tensors: grid = GridSampleCoordinates of the map, the masks as they are. So training
// and rendering warp alike by construction (pixel centres at +0.5, the occlusion test,
// the relative poses in double precision). Target pixels without a surface are warped
// at infinity when inf_depth, else are invalid (WarpOptions::at_infinity). The ULR
// log-weights weigh them at UlrPointAtInfinity, as the renderer does.
TrainingWarp ComputeTrainingWarp(
    const torch::Tensor& target_K, const torch::Tensor& target_R,
    const torch::Tensor& target_t, const torch::Tensor& target_depth,
    const torch::Tensor& source_K, const torch::Tensor& source_R,
    const torch::Tensor& source_t, const torch::Tensor& source_depths,
    const SampleWarpOptions& settings);

struct TrainingSample {
  int scene = 0, target = 0, x0 = 0, y0 = 0;
  std::vector<int> sources;
  torch::Tensor target_rgb;  // float [1,3,h,w] in [0,1]
  torch::Tensor source_rgb;  // float [K,3,H,W] in [-1,1] (the net's input range)
  TrainingWarp warp;
};

// The sample of target view `target` cropped to [x0, x0+w) x [y0, y0+h) (intrinsics moved
// by the crop origin), with the given sources at full size.
TrainingSample MakeSample(const PackedScene& scene, int target,
                          const std::vector<int>& sources, int x0, int y0, int crop_width,
                          int crop_height, const SampleWarpOptions& settings);

// FillHoles (util/hole_filling.h) on a [1,3,H,W] image in [0,1], as the renderer fills
// pixels no source sees; covered and surface are [1,1,H,W] (> 0 = yes).
torch::Tensor FillHolesOf(const torch::Tensor& rgb, const torch::Tensor& covered,
                          const torch::Tensor& surface);

// Photometric augmentation, the same for the target and all its sources so that the
// colours stay consistent across views (no geometric change: the cameras stay valid).
struct ColorJitter {
  double brightness = 0;       // added, in [0,1] units
  double contrast = 1;         // around 0.5
  double saturation = 1;       // around the grey value
  double gain[3] = {1, 1, 1};  // per channel (white balance)
};
void ApplyColorJitter(const ColorJitter& jitter, TrainingSample* sample);

// Crops every source of a sample to the part its target crop samples (plus `margin`
// pixels; one common size, a multiple of `multiple`, per-source offsets) and rewrites the
// grid to match, so the encoder runs on that part only. Bilinear samples of the cropped
// sources equal those of the full ones exactly; the encoded features differ only within
// the encoder's receptive field of a crop border that is not an image border. A sample
// whose grid has no finite position near any source is left as it is.
void CropSourcesToFootprint(TrainingSample* sample, int margin, int multiple);

struct SamplerOptions {
  int num_sources = 5;
  int crop = 192;
  bool augment = true;
  // >= 0: CropSourcesToFootprint with this margin (the trainer's default, 16); < 0: full
  // sources.
  int source_margin = -1;
  bool holdout_targets = false;  // IsTargetView
  SampleWarpOptions warp;
};

// Random leave-one-out samples: a target uniformly over the target views (IsTargetView)
// of all scenes that have a source, a uniform crop, jitter when augment. Everything
// random comes from one std::mt19937_64 whose state State() / SetState() carry through a
// checkpoint, so a resumed run draws exactly the samples an uninterrupted run would.
class TrainingSampler {
 public:
  TrainingSampler(const std::vector<PackedScene>* scenes, const SamplerOptions& options,
                  uint64_t seed);
  TrainingSample Next();
  std::string State() const;
  void SetState(const std::string& state);  // throws fvs::Error on a malformed state

 private:
  double Uniform(double lo, double hi);
  const std::vector<PackedScene>* scenes_;
  SamplerOptions options_;
  std::vector<std::pair<int, int>> targets_;  // (scene, view) with at least one source
  std::mt19937_64 rng_;
};

}  // namespace fvs
