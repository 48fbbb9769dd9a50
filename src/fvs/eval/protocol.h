// Which registered views an evaluation renders, and which views each of them may not use
// as a source. Positions ("indices") count the registered images sorted by name, from 0.
//   holdout        the images of W/fvs/holdout.txt (prepare's --holdout_images): true
//                  held-out views, absent from the dense geometry too; none of them is a
//                  source of any target.
//   leave_one_out  every `every`-th image (positions 0, every, 2 every, ...); each target
//                  is only kept out of its own sources (the mesh may have seen it: say
//                  so).
//   subsequence    positions [start, start + length): a withheld contiguous stretch (the
//                  paper's Tanks and Temples protocol); none of them is a source.
//   indices        the given positions or names (DTU style: the paper renders 10 of 49,
//                  6 centre views for interpolation and 4 corners for extrapolation);
//                  none of them is a source.
// A name or position not in the model is kept as a target with an error, so that the
// report says what was asked and why it has no numbers, while the others are evaluated.
// A held-out image SfM did not register (prepare warned) is kept as a skipped target:
// it has no pose to render, which is the photos' fault, not the evaluation's.
#pragma once

#include <set>
#include <string>
#include <vector>

namespace fvs::eval {

struct ProtocolOptions {
  std::string protocol = "auto";  // auto (holdout if W/fvs/holdout.txt lists images,
                                  // else leave_one_out), holdout, leave_one_out,
                                  // subsequence, indices
  int every = 1;                  // leave_one_out
  std::string subsequence;        // "START:LENGTH" (positions)
  std::string target_indices;     // "0,5,9" (positions)
  std::string target_names;       // "a.png,b.png" (image names)

  // Throws fvs::Error("colmap view_synthesis_eval", ...) for unusable values.
  void Check() const;
};

struct EvalTarget {
  std::string name;   // image name as in the model (or as asked, when missing)
  int position = -1;  // in the name-sorted list; -1 when not in the model
  bool geometry_holdout = false;  // listed in W/fvs/holdout.txt: unseen by the mesh
  std::string error;     // non-empty: cannot be evaluated (not in the model, ...)
  bool skipped = false;  // not evaluated for the reason in `error`, not a failure
};

struct TargetSet {
  std::string protocol;  // the one used (auto resolved)
  std::vector<EvalTarget> targets;
  // Names no target may use as a source (the whole withheld set); each target also
  // excludes itself.
  std::set<std::string> excluded_sources;
};

// `names`: the registered image names (any order); `holdout`: W/fvs/holdout.txt's names.
TargetSet SelectTargets(const std::vector<std::string>& names,
                        const std::set<std::string>& holdout,
                        const ProtocolOptions& options);

// The names in W/fvs/holdout.txt (empty when the file does not exist).
std::set<std::string> ReadHoldoutNames(const std::string& workspace_path);

}  // namespace fvs::eval
