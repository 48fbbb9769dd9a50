// The structure-from-motion steps of view_synthesis_prepare (prepare_workspace.h), run
// through the COLMAP binary (colmap_ext/runner.h): matching, mapping and the report of
// what SfM registered.
#pragma once

#include <set>
#include <string>
#include <vector>

namespace fvs {

// Matches the images of `database` with `type` (exhaustive, or sequential with loop
// closure: SequentialPairs through COLMAP's matches_importer, whose pair list is written
// to `pairs_path`; COLMAP's own sequential matcher when a name has a space). Pairs
// already matched in the database are not matched again. `gpu` and `threads` are the
// SiftMatching values ("0"/"1", a count).
void RunMatcher(const std::string& type, const std::string& database,
                const std::vector<std::string>& images, const std::string& pairs_path,
                const std::string& gpu, const std::string& threads);

struct MappedModel {
  std::string path;  // the largest model COLMAP's mapper made; empty: none
  int registered = 0;
};

// Runs COLMAP's mapper into `out` and picks the model with most registered images
// (COLMAP numbers models by discovery, not size).
MappedModel MapLargestModel(const std::string& image_path, const std::string& database,
                            const std::string& out, const std::string& threads);

// W/fvs/registration.json: how many of the photos SfM registered (in the model at
// `model_path`), which not, and how they were matched.
void WriteRegistrationReport(const std::string& path,
                             const std::vector<std::string>& images,
                             const std::string& model_path, const std::string& matcher,
                             bool retried);

// Registered of total photos on stderr, and a warning for each held-out photo SfM did
// not register: it has no pose, so it cannot be a target (view_synthesis_eval skips it).
// An unreadable report is a warning, not an error.
void ReportRegistration(const std::string& path, const std::set<std::string>& holdout);

}  // namespace fvs
