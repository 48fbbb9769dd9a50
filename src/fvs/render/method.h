// Novel-view rendering methods behind one interface, chosen by name (`--method`): the
// classical baselines `ulr` and `nearest` live here; the network (`fvs`) registers itself
// the same way from its own library. Every method shares the geometric front end
// (PrepareTarget in prepare.h): target depth, source selection, warping maps.
#pragma once

#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "fvs/geometry/camera.h"
#include "fvs/scene/source_selection.h"
#include "fvs/util/image.h"

namespace fvs {

class Scene;

// A camera to render, in the scene's (centred) frame; name is used for output files.
struct TargetView {
  std::string name;
  PinholeCamera camera;
  // Views of the scene never used as sources (e.g. the held-out view in an evaluation).
  std::vector<int> exclude_views;
  // Sources of the previous frame of a video (view indices): with
  // RenderOptions::source_hysteresis > 0 they are favoured in the top-K choice, so the
  // source set does not flip back and forth between frames (flicker).
  std::vector<int> preferred_sources;
};

// The precisions a network method can run in (RenderOptions::precision): fp32, bf16,
// fp16.
bool KnownPrecision(const std::string& name);

struct RenderOptions {
  // K sources per target; 0 (the default) = adaptive: per target, sources are taken in
  // order of overlap while they add coverage, at most max_num_sources
  // (scene/source_selection.h; doc/evaluation.md compares it with fixed K).
  int num_sources = 0;
  int max_num_sources = 10;
  double selection_tolerance = 0.10;  // relative depth tolerance for ranking sources
  double warp_tolerance = 0.01;       // relative occlusion tolerance when warping
  int selection_stride = 1;           // test every n-th target pixel when ranking
  double ulr_resolution_weight =
      0.2;                // weight of the resolution penalty vs the angle (rad)
  int ulr_num_blend = 4;  // ULR k-nearest: best sources blended per pixel
  // How ulr and nearest sample a source photo's colour at a warped position: bicubic
  // (geometry/warp.h SampleBicubic) or bilinear. Bicubic gave lower LPIPS on 4 of the 5
  // tuning scenes' held-out views at level PSNR (doc/real_scenes.md, session 29). The
  // network methods sample their features bilinearly (grid_sample) whatever this says.
  std::string interpolation = "bicubic";
  int num_threads = 0;     // <= 0: DefaultNumThreads()
  std::string model_path;  // weights, for methods that need them
  // Network methods without model_path: <variant>.safetensors in this folder (a scene's
  // fine-tuned weights, WorkspaceFinetunedModelDir(W)) comes before the shipped model.
  std::string scene_model_dir;
  // Temporal stability (videos). A preferred source (TargetView::preferred_sources) ranks
  // with its count times (1 + source_hysteresis): it stays in the top K until another
  // source sees that much more. 0 = off (each frame on its own).
  double source_hysteresis = 0;
  // Feed the selected sources in view order rather than best first, so that the
  // recurrent blend sees a fixed order while the set does not change.
  bool stable_source_order = false;
  // Pixels no source sees, not even at infinity, get colours pushed and pulled from the
  // covered pixels around them (util/hole_filling.h) instead of black; coverage and
  // confidence stay 0 there.
  bool fill_holes = true;
  // Photos prepare found blurry (SceneView::blurry) rank after every other source: taken
  // only for pixels no sharp photo sees (scene/photo_quality.h). true: ranked as any
  // other.
  bool use_blurry_sources = false;
  // Network methods: where and in what precision the network runs. device: auto (CUDA
  // when this build and machine have it, else the CPU), cpu or cuda. precision: fp32,
  // bf16 or fp16 (fp16 on CUDA only: LibTorch's CPU convolutions have none). Warping
  // (sampling positions) and the softmax blend weights stay in fp32 whatever the choice.
  std::string device = "auto";
  std::string precision = "fp32";
  // Network methods: memory for encoded source features kept across targets (a camera
  // path encodes each source once). 64 channels of a 640x480 photo take 79 MB, of a
  // 1920x1080 one 530 MB. 0 = encode every source anew for every target.
  int feature_cache_mb = 2048;
  // Network methods: also keep encoded source features in this folder (one file per
  // source photo, weights and precision; render/feature_store.h), so that another run
  // reads them instead of encoding. As large as the photos' features (64 channels of
  // fp32: 79 MB for a 640x480 photo). Empty = memory only. view_synthesis
  // --disk_feature_cache 1 and the GUI use WorkspaceFeatureCacheDir(W). The folder is
  // kept within feature_cache_disk_mb (least recently used files removed first).
  std::string feature_cache_dir;
  int feature_cache_disk_mb = 8192;
  // Network methods: a target wider or taller than tile_size pixels is blended in tiles
  // of at most tile_size x tile_size, each computed with tile_overlap more pixels of
  // context on every side and cropped, so that memory stays bounded for any target size
  // (the blending U-Net's activations and the warped features scale with the pixels of a
  // tile, not of the target). Also faster on a CPU: tiles stay in cache (doc/network.md,
  // "Large targets: tiles", has the figures: time and peak memory per tile size).
  // 0 = never tile; -1 (default) = the network's own (fvs_agg 160 and
  // 24, the others 512 and 32; render/fvs_method.cc).
  int tile_size = -1;
  int tile_overlap = -1;
  void Check() const;
};

struct RenderTimings {
  double depth_s = 0;      // target depth from the mesh
  double selection_s = 0;  // ranking the sources
  double warp_s = 0;       // warping maps (+ loading the source photos)
  double encode_s = 0;     // encoding source features (network; 0 when cached)
  double blend_s = 0;      // the method's own work
  double total() const { return depth_s + selection_s + warp_s + encode_s + blend_s; }
};

struct RenderResult {
  Image color;       // 3 channels in [0, 1]; where no source sees the pixel: black, or
                     // filled from around it (RenderOptions::fill_holes)
  Image depth;       // 1 channel, target depth from the mesh (0 = no surface)
  Image confidence;  // 1 channel in [0, 1]; 0 where not covered
  Image coverage;    // 1 channel, 1 where at least one source contributed
  // 1 channel, 1 where the pixel has no surface (depth 0) but some source sees it at
  // infinity (geometry/warp.h), so it was rendered from the background beyond the mesh;
  // AtInfinityMask of depth and coverage.
  Image infinity;
  std::vector<SourceScore> sources;  // used, best first
  RenderTimings timings;
};

// 1 where depth has no surface (<= 0 or non-finite) and coverage > 0, else 0; empty when
// the sizes differ.
Image AtInfinityMask(const Image& depth, const Image& coverage);

class Method {
 public:
  virtual ~Method() = default;
  virtual std::string name() const = 0;
  virtual RenderResult Render(const Scene& scene, const TargetView& target) = 0;
};

using MethodFactory = std::function<std::unique_ptr<Method>(const RenderOptions&)>;

// What a method needs and does beyond the shared front end, declared once where it is
// registered, so that the commands, the sweep and the GUI ask here instead of testing
// names.
struct MethodTraits {
  // A network: weights from --model_path, the scene's fine-tuned ones or the shipped
  // model (RenderOptions::model_path, scene_model_dir).
  bool needs_weights = false;
  // Renders from one source whatever K (`nearest`): a sweep over K runs it once, at K 1.
  bool single_source = false;
};

// Adds (or replaces) a method. Thread-safe.
void RegisterMethod(const std::string& name, MethodFactory factory,
                    MethodTraits traits = {});
// The traits a method was registered with. A name that is not registered can only be a
// network this build lacks (CreateMethod says so): it needs weights.
MethodTraits TraitsOfMethod(const std::string& name);
// Names of the available methods, sorted; `ulr` and `nearest` are always there.
std::vector<std::string> RegisteredMethods();
// A workspace's folder for encoded source features (RenderOptions::feature_cache_dir):
// W/fvs/features.
std::string WorkspaceFeatureCacheDir(const std::string& workspace_path);

// Throws fvs::Error for an unknown name, or for `fvs` when the network is not available.
std::unique_ptr<Method> CreateMethod(const std::string& name,
                                     const RenderOptions& options);

}  // namespace fvs
