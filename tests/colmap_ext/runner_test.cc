// Finding, probing and running COLMAP: the real binary for probing and failures, small
// scripts standing in for a COLMAP that prints or dies in particular ways.
#include "colmap_ext/runner.h"

#include <gtest/gtest.h>
#include <sys/stat.h>

#include <cstdlib>
#include <filesystem>

#include "colmap_ext/workspace.h"
#include "fvs/util/error.h"
#include "support/test_support.h"

namespace fvs::colmap {
namespace {

using fvs::testing::RunShell;
using fvs::testing::ScopedEnv;
using fvs::testing::TempDir;
using fvs::testing::WriteTextFile;

std::string Dir(const std::string& path) {
  return path.substr(0, path.find_last_of('/'));
}

void WriteScript(const std::string& path, const std::string& body) {
  WriteTextFile(path, "#!/bin/sh\n" + body);
  ::chmod(path.c_str(), 0755);
}

std::string ErrorOf(const std::function<void()>& fn) {
  try {
    fn();
  } catch (const Error& e) {
    return e.what();
  }
  return "(no error)";
}

TEST(Runner, FindsColmapButNeverOurFrontDoor) {
  TempDir dir;
  const std::string real = fvs::testing::RealColmapBinary();
  // A front door: a `colmap` with the marker beside it, first on the PATH.
  CreateDirectories(dir / "build/bin");
  WriteScript(dir / "build/bin/colmap", "exit 0\n");
  WriteTextFile(dir / "build/bin/.fvs_front_door", "");
  {
    ScopedEnv no_override("FVS_COLMAP_BIN", nullptr);
    ScopedEnv path("PATH", (dir / "build/bin:" + Dir(real)).c_str());
    EXPECT_EQ(FindColmapExecutable(), Dir(real) + "/colmap");
  }
  {
    ScopedEnv no_override("FVS_COLMAP_BIN", nullptr);
    ScopedEnv path("PATH", (dir / "build/bin:" + dir.path()).c_str());
    EXPECT_NE(ErrorOf([] { FindColmapExecutable(); }).find("COLMAP executable not found"),
              std::string::npos);
  }
  {
    ScopedEnv front("FVS_COLMAP_BIN", (dir / "build/bin/colmap").c_str());
    EXPECT_NE(ErrorOf([] { FindColmapExecutable(); }).find("front door"),
              std::string::npos);
  }
  {
    ScopedEnv missing("FVS_COLMAP_BIN", (dir / "nothing").c_str());
    const std::string error = ErrorOf([] { FindColmapExecutable(); });
    EXPECT_NE(error.find(dir / "nothing"), std::string::npos) << error;
  }
  {
    ScopedEnv set("FVS_COLMAP_BIN", real.c_str());
    EXPECT_EQ(FindColmapExecutable(), real);
  }
}

TEST(Runner, ProbesWhatTheRealColmapCanDo) {
  ScopedEnv set("FVS_COLMAP_BIN", fvs::testing::RealColmapBinary().c_str());
  const ColmapCapabilities& caps = ProbeColmap();
  EXPECT_EQ(&caps, &ProbeColmap()) << "cached";
  EXPECT_EQ(caps.executable, fvs::testing::RealColmapBinary());
  // Compare with what the binary says, asked independently through the shell.
  std::string help;
  RunShell("QT_QPA_PLATFORM=offscreen '" + caps.executable + "' -h", &help);
  EXPECT_NE(help.find("COLMAP " + caps.version), std::string::npos) << caps.version;
  EXPECT_FALSE(caps.version.empty());
  EXPECT_EQ(caps.has_cuda, help.find("without CUDA") == std::string::npos);
  TempDir dir;
  std::string mesher;
  RunShell("QT_QPA_PLATFORM=offscreen '" + caps.executable +
               "' delaunay_mesher --input_path " + dir.path() + " --output_path " +
               dir.path() + "/m.ply",
           &mesher);
  EXPECT_EQ(caps.has_cgal, mesher.find("requires CGAL") == std::string::npos) << mesher;
  if (help.find("3.8 ") != std::string::npos &&
      help.find("without CUDA") != std::string::npos) {
    // Debian 12's package: no CUDA, no CGAL.
    EXPECT_FALSE(caps.has_cuda);
  }
}

TEST(Runner, RealColmapFailureBecomesOneLine) {
  ScopedEnv set("FVS_COLMAP_BIN", fvs::testing::RealColmapBinary().c_str());
  ScopedEnv quiet("FVS_QUIET", "1");
  TempDir dir;
  // model_converter CHECK-fails (abort) on a missing model.
  const std::string error = ErrorOf([&] {
    RunColmap({"model_converter", "--input_path", dir / "nothing", "--output_path",
               dir.path(), "--output_type", "TXT"});
  });
  EXPECT_EQ(error.find('\n'), std::string::npos) << error;
  EXPECT_EQ(error.rfind("colmap model_converter ", 0), 0u) << error;
  EXPECT_NE(error.find("do not exist"), std::string::npos) << error;
  const std::string unknown = ErrorOf([] { RunColmap({"no_such_command"}); });
  EXPECT_NE(unknown.find("failed (exit 1)"), std::string::npos) << unknown;
  EXPECT_NE(unknown.find("not recognized"), std::string::npos) << unknown;
}

TEST(Runner, LinesProgressAndErrorLines) {
  TempDir dir;
  const std::string fake = dir / "colmap";
  ScopedEnv set("FVS_COLMAP_BIN", fake.c_str());
  WriteScript(fake,
              "echo \"args: $*\"\n"
              "printf 'step 1\\rstep 2\\n'\n"
              "echo 'E20261121 10:00:00.123 99 x.cc:1] Something broke badly' >&2\n"
              "echo 'cleanup done'\n"
              "exit 3\n");
  std::vector<std::string> lines;
  RunColmapOptions options;
  options.on_line = [&](const std::string& line) { lines.push_back(line); };
  options.label = "fake stage";
  const std::string error = ErrorOf([&] { RunColmap({"cmd", "--a b", "c'd"}, options); });
  EXPECT_EQ(error, "fake stage failed (exit 3): Something broke badly");
  ASSERT_EQ(lines.size(), 5u);
  EXPECT_EQ(lines[0], "args: cmd --a b c'd");  // no shell: arguments arrive as given
  EXPECT_EQ(lines[1], "step 1");
  EXPECT_EQ(lines[2], "step 2");

  WriteScript(fake, "echo working\necho 'last words'\nkill -9 $$\n");
  const std::string killed = ErrorOf([&] { RunColmap({"cmd"}, options); });
  EXPECT_NE(killed.find("crashed (signal 9"), std::string::npos) << killed;
  EXPECT_NE(killed.find("last words"), std::string::npos) << killed;

  WriteScript(fake, "echo 'ok'\nexit 0\n");
  ScopedEnv quiet("FVS_QUIET", "1");
  ::testing::internal::CaptureStderr();
  RunColmap({"cmd"});
  EXPECT_EQ(::testing::internal::GetCapturedStderr(), "");
  ScopedEnv loud("FVS_QUIET", "0");
  ScopedEnv verbose("FVS_VERBOSE", "1");
  ::testing::internal::CaptureStderr();
  RunColmap({"cmd"});
  const std::string shown = ::testing::internal::GetCapturedStderr();
  EXPECT_NE(shown.find("ok\n"), std::string::npos) << shown;
  EXPECT_NE(shown.find("colmap cmd done"), std::string::npos) << shown;
}

}  // namespace
}  // namespace fvs::colmap
