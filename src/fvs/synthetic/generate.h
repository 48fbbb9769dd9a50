// Writes a synthetic scene as a COLMAP dense workspace with its ground truth:
//   DIR/images/frame_NNNN.png                       rendered views (8-bit sRGB)
//   DIR/sparse/{cameras,images,points3D}.bin        ground-truth model (ground_truth.h)
//   DIR/ground_truth/depth_maps/<image name>.bin    exact depth, COLMAP array format
//   DIR/ground_truth/normal_maps/<image name>.bin   camera-frame normals, COLMAP format
//   DIR/ground_truth/mesh.ply                       the scene mesh with vertex colours
//   DIR/ground_truth/scene.json                     seed, options, scene size, primitives
//   DIR/meshed-delaunay.ply                         only with write_proxy_mesh
// DIR/stereo/ is not written (the stereo stage's job). Every file is written atomically
// and scene.json comes last, so a folder with scene.json is complete; a killed run is
// redone by running again (everything is regenerated, deterministically).
#pragma once

#include <string>
#include <utility>
#include <vector>

#include "fvs/synthetic/synthetic_scene.h"

namespace fvs {

// Throws fvs::Error on bad options or when a file cannot be written.
void GenerateSyntheticScene(const SyntheticSceneOptions& options,
                            const std::string& output_dir);

// Ground truth for a camera path (e.g. a video rendered from the workspace above, whose
// frame is the scene's): the scene the options make, rendered at every camera into
// DIR/<name>.png. The cameras must lie in the scene's world frame. Frames already there
// complete (right size, decodable) are kept (a killed run resumes).
void RenderSyntheticFrames(
    const SyntheticSceneOptions& options,
    const std::vector<std::pair<std::string, PinholeCamera>>& frames,
    const std::string& output_dir);

// Paths of the files above (for stages and tests that read them).
std::string SyntheticDepthMapPath(const std::string& output_dir, const std::string& name);
std::string SyntheticNormalMapPath(const std::string& output_dir,
                                   const std::string& name);
std::string SyntheticMeshPath(const std::string& output_dir);
std::string SyntheticSceneJsonPath(const std::string& output_dir);

}  // namespace fvs
