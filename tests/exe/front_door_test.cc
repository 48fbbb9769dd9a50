// The front door as a user meets it: build/bin/colmap runs our commands and forwards the
// rest to the real COLMAP.
#include <gtest/gtest.h>

#include <string>

#include "support/test_support.h"

namespace fvs::testing {
namespace {

std::string RunFrontDoor(const std::string& args, int* status) {
  std::string out;
  *status =
      RunShell("QT_QPA_PLATFORM=offscreen '" + FrontDoorBinary() + "' " + args, &out);
  return out;
}

TEST(FrontDoor, HelpListsColmapCommandsThenOurs) {
  int status = -1;
  const std::string out = RunFrontDoor("help", &status);
  EXPECT_EQ(status, 0);
  const size_t colmap_pos = out.find("COLMAP");
  const size_t ours_pos = out.find("view_synthesis_");
  ASSERT_NE(colmap_pos, std::string::npos) << out;
  ASSERT_NE(ours_pos, std::string::npos) << out;
  EXPECT_LT(colmap_pos, ours_pos);
  EXPECT_NE(out.find("feature_extractor"), std::string::npos);
}

TEST(FrontDoor, ForwardsOtherCommandsToRealColmap) {
  TempDir dir;
  int status = -1;
  // model_converter on an empty folder fails inside COLMAP: the exit code and COLMAP's
  // own message come through unchanged.
  const std::string out =
      RunFrontDoor("model_converter --input_path " + dir.path() + " --output_path " +
                       dir.path() + " --output_type TXT",
                   &status);
  EXPECT_NE(status, 0);
  int help_status = -1;
  const std::string help = RunFrontDoor("model_converter -h", &help_status);
  EXPECT_EQ(help_status, 0);
  EXPECT_NE(help.find("--output_type"), std::string::npos) << help;
}

TEST(FrontDoor, UnknownOptionOfOurCommandIsOneErrorLine) {
  int status = -1;
  const std::string out =
      RunFrontDoor("view_synthesis_synthetic --no_such_option 1", &status);
  if (out.find("unknown command") != std::string::npos) GTEST_SKIP();
  EXPECT_EQ(status, 1);
  EXPECT_NE(out.find("ERROR: "), std::string::npos) << out;
  EXPECT_NE(out.find("--no_such_option"), std::string::npos) << out;
}

}  // namespace
}  // namespace fvs::testing
