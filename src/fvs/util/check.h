// Internal invariants: conditions that only a bug in our own code can break (user input
// gets fvs::Error naming the file at fault, util/error.h). FVS_CHECK(condition, what)
// throws fvs::Error("internal error at <file>:<line>", ...) when the condition fails, so
// a broken invariant is still one line and a non-zero exit, never an abort, and the line
// says where to look. <file> is the base name (__FILE_NAME__, GCC 12 and clang): __FILE__
// would put the absolute path of the checkout into the binaries of any build that does not
// go through ccache's base_dir rewriting, and installed binaries must not name the build
// machine's folders (install_test).
#pragma once

#include <string>

#include "fvs/util/error.h"

namespace fvs::internal {

[[noreturn]] inline void CheckFailed(const char* file, int line, const char* condition,
                                     const std::string& what) {
  throw Error("internal error at " + std::string(file) + ":" + std::to_string(line),
              what + " (check '" + condition + "' failed; please report this)");
}

}  // namespace fvs::internal

#ifdef __FILE_NAME__
#define FVS_CHECK_FILE_ __FILE_NAME__
#else
#define FVS_CHECK_FILE_ __FILE__
#endif

#define FVS_CHECK(condition, what)    \
  ((condition) ? static_cast<void>(0) \
               : ::fvs::internal::CheckFailed(FVS_CHECK_FILE_, __LINE__, #condition, (what)))
