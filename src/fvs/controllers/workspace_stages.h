// The built-in stages of a workspace that run both as commands of their own
// (view_synthesis_stereo, view_synthesis_mesher, view_synthesis_depth_cache) and inside
// view_synthesis_prepare: one call each, printing the same summary on stderr (stereo,
// depth cache) or stdout (mesher) wherever it runs.
#pragma once

#include <string>

#include "fvs/mvs/delaunay.h"
#include "fvs/mvs/face_consistency.h"
#include "fvs/mvs/mesh_refinement.h"
#include "fvs/mvs/patch_match_stereo.h"
#include "fvs/scene/backdrop.h"

namespace fvs {

// CPU PatchMatch stereo of the dense workspace (mvs/patch_match_stereo.h): depth and
// normal maps in COLMAP's format. Throws fvs::Error for an unusable workspace.
void RunBuiltinStereo(const std::string& workspace_path,
                      const mvs::PatchMatchStereoOptions& options);

// The built-in Delaunay graph-cut mesher (mvs/delaunay.h): W/fused.ply, its visibility
// and W/sparse -> `output_path`. Throws fvs::Error with one line when this build has no
// CGAL or Boost.Graph, or for bad input (nothing written then).
void RunBuiltinMesher(const std::string& workspace_path, const std::string& output_path,
                      const mvs::DelaunayMeshingOptions& options);

// Refines W/meshed-delaunay.ply by photo-consistency against the photos of W that are not
// held out (W/fvs/holdout.txt): first the faces the photos contradict are removed
// (mvs/face_consistency.h), then, if asked, the vertices move to where the photos agree
// (mvs/mesh_refinement.h). Writes W/meshed-refined.ply, which the renderers then use,
// and W/fvs/refinement.json. With both off it removes W/meshed-refined.ply. Throws
// fvs::Error for bad options or unreadable input.
void RefineProxyMesh(const std::string& workspace_path,
                     const mvs::MeshRefinementOptions& options,
                     const mvs::FaceConsistencyOptions& consistency);

// Fits the backdrop (scene/backdrop.h) to the photos of W that are not held out
// (W/fvs/holdout.txt) around the proxy mesh: W/fvs/backdrop.ply (world frame; no
// file when nothing was kept) and its summary W/fvs/backdrop.json. Throws fvs::Error for
// an unusable workspace.
void BuildBackdrop(const std::string& workspace_path, const BackdropOptions& options);

// Renders the depth of every source view from the mesh into W/fvs/depth/ (reusing what
// is current: scene/depth_cache.h) and writes how much of the photos the mesh covers to
// W/fvs/depth/coverage.json. num_threads -1: all cores.
void BuildDepthCache(const std::string& workspace_path, int num_threads);

}  // namespace fvs
