// Temporary files that a killed run left behind. Every file we write goes through a
// temporary `<path>.tmp-<pid>-<n>` (images: `<path>.tmp-<pid>-<n>.<ext>`) renamed into place (util/atomic_file.h); a process
// killed with SIGKILL between the two leaves the temporary. A rerun that resumes in the
// same folder removes them, so that a killed-then-finished run leaves what an
// uninterrupted one does.
#pragma once

#include <string>

namespace fvs {

// Removes the regular files directly in `dir` named `<anything>.tmp-<pid>-<n>[.<ext>]` whose
// process <pid> no longer runs (a live writer's temporaries are left alone). Returns how
// many were removed; a missing folder removes none. Never throws for files it cannot
// remove (they stay).
int RemoveStaleTempFiles(const std::string& dir);

}  // namespace fvs
