// RemoveStaleTempFiles removes what a killed writer left (temporaries of dead processes)
// and nothing else: not a live process's temporaries, not ordinary files.
#include "fvs/util/stale_temp_files.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>

#include "support/test_support.h"

namespace fvs {
namespace {

TEST(StaleTempFiles, RemovesOnlyDeadWritersTemporaries) {
  testing::TempDir dir;
  const std::string live = std::to_string(::getpid());
  // pid 2^22 + 1 is above Linux's pid_max limit (2^22): no process has it.
  const std::string dead = "4194305";
  for (const std::string& name :
       {"frame_00003.png.tmp-" + dead + "-0", "report.json.tmp-" + dead + "-12",
        // Image temporaries keep their extension (colmap_ext/image_io.cc).
        "frame_00005.png.tmp-" + dead + "-3.png",
        "frame_00004.png.tmp-" + live + "-1", std::string("frame_00003.png"),
        std::string("notes.tmp-x-1"), "a.tmp-" + dead}) {
    testing::WriteTextFile(dir / name, "x");
  }
  EXPECT_EQ(RemoveStaleTempFiles(dir.path()), 3);
  EXPECT_FALSE(std::filesystem::exists(dir / ("frame_00003.png.tmp-" + dead + "-0")));
  EXPECT_FALSE(std::filesystem::exists(dir / ("frame_00005.png.tmp-" + dead + "-3.png")));
  EXPECT_TRUE(std::filesystem::exists(dir / ("frame_00004.png.tmp-" + live + "-1")));
  EXPECT_TRUE(std::filesystem::exists(dir / "frame_00003.png"));
  EXPECT_TRUE(std::filesystem::exists(dir / "notes.tmp-x-1"));
  EXPECT_TRUE(std::filesystem::exists(dir / ("a.tmp-" + dead)));
  EXPECT_EQ(RemoveStaleTempFiles(dir / "missing"), 0);
}

}  // namespace
}  // namespace fvs
