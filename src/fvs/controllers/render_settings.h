// What decides the pixels of a rendered frame, as <output_path>/render_settings.json: a
// frame rendered with other settings, weights, workspace or targets (compared by content,
// not by path or time) is not resumed (render_targets.h).
#pragma once

#include <string>

#include "fvs/controllers/render_targets.h"

namespace fvs {

// Content hash of `paths` (files, or folders: every file below them, in name order),
// their names relative to `root` included: the same bytes wherever they lie give the same
// hash. A path that does not exist adds nothing.
std::string ContentHash(const std::vector<std::string>& paths, const std::string& root);

// Content hash of what the renderer takes from the workspace: the sparse model, the mesh
// and the undistorted photos (the source depths follow from the first two).
std::string WorkspaceContentHash(const std::string& workspace_path);

// The settings of `options` (after RunRenderTargets completed them) with the hashes of
// the weights, the workspace (sparse model, mesh, photos) and the target file, as
// indented JSON ending in a newline: equal text, equal frames.
std::string RenderSettingsJson(const RenderTargetsOptions& options);

}  // namespace fvs
