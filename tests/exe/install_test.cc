// `cmake --install` as a user runs it (doc/install.md): the tree under a temporary prefix
// works on its own. The installed front door, run from another folder with no source or
// build path in its environment (and, where a private mount namespace can be made, with
// the source tree hidden under an empty tmpfs), generates a scene, renders it with ulr,
// finds the real COLMAP, and finds weights in <prefix>/share/colmap-fvs/models or
// $FVS_MODEL_DIR. Needs the colmap and fvs_train_main targets built (ctest builds them
// first).
#include <gtest/gtest.h>
#include <torch/torch.h>

#include <filesystem>
#include <string>

#include "fvs/net/model_config.h"
#include "fvs/net/net.h"
#include "support/test_support.h"

namespace fvs::testing {
namespace {

namespace fs = std::filesystem;

std::string Quote(const std::string& s) { return "'" + s + "'"; }

bool CanHideSourceTree() {
  static const bool can =
      RunShell("unshare -m sh -c 'mount -t tmpfs none " + std::string(FVS_SOURCE_DIR) +
               " && test ! -e " + std::string(FVS_SOURCE_DIR) +
               "/CMakeLists.txt' >/dev/null 2>&1") == 0;
  return can;
}

// Runs `command` in `cwd` with a plain environment: no FVS_* variables that point into
// the checkout, PATH without build/bin. The source tree (with build/ inside it, and the
// build tree wherever it is) is covered by an empty tmpfs in a private mount namespace
// when the test may make one.
int RunInstalled(const std::string& cwd, const std::string& command, std::string* output,
                 const std::string& extra_env = "") {
  std::string hide;
  if (CanHideSourceTree()) {
    hide = "unshare -m sh -c 'mount -t tmpfs none " + std::string(FVS_SOURCE_DIR) +
           " && mount -t tmpfs none " + std::string(FVS_BINARY_DIR) + " 2>/dev/null; " +
           "test ! -e " + std::string(FVS_SOURCE_DIR) +
           "/CMakeLists.txt && exec \"$@\"' sh ";
  }
  const std::string full =
      "cd " + Quote(cwd) +
      " && env -u FVS_SOURCE_DIR -u FVS_BINARY_DIR -u FVS_MODEL_DIR -u FVS_COLMAP_BIN " +
      "FVS_QUIET=1 QT_QPA_PLATFORM=offscreen OMP_WAIT_POLICY=PASSIVE " + extra_env + " " +
      hide + "timeout 300 sh -c " + Quote(command) + " 2>&1";
  return RunShell(full, output);
}

void SaveRandomModel(const std::string& path, const std::string& variant) {
  torch::manual_seed(3);
  const ModelConfig config = ModelConfig::ForVariant(variant);
  FvsNet net(config);
  fs::create_directories(fs::path(path).parent_path());
  SaveWeights(net, config, path, /*fp16=*/false);
}

class InstallTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    prefix_dir_ = new TempDir();
    prefix_ = prefix_dir_->path() + "/prefix";
    std::string output;
    install_status_ = RunShell("cmake --install " + Quote(FVS_BINARY_DIR) + " --prefix " +
                                   Quote(prefix_) + " 2>&1",
                               &output);
    install_output_ = output;
    std::printf("source tree hidden while the installed binaries run: %s\n",
                CanHideSourceTree() ? "yes (private tmpfs mounts)"
                                    : "no (no mount namespace; other cwd, clean env)");
  }
  static void TearDownTestSuite() {
    delete prefix_dir_;
    prefix_dir_ = nullptr;
  }
  void SetUp() override { ASSERT_EQ(install_status_, 0) << install_output_; }

  static TempDir* prefix_dir_;
  static std::string prefix_, install_output_;
  static int install_status_;
};

TempDir* InstallTest::prefix_dir_ = nullptr;
std::string InstallTest::prefix_;
std::string InstallTest::install_output_;
int InstallTest::install_status_ = -1;

TEST_F(InstallTest, LayoutHasBinariesModelsDocsAndManPage) {
  for (const char* file :
       {"bin/colmap-fvs", "bin/fvs_train_main", "bin/.fvs_front_door",
        "lib/colmap-fvs/bin/.fvs_front_door", "share/colmap-fvs/models/README.md",
        "share/doc/colmap-fvs/README.md", "share/doc/colmap-fvs/doc/install.md",
        "share/man/man1/colmap-fvs.1"}) {
    EXPECT_TRUE(fs::is_regular_file(prefix_ + "/" + file)) << file;
  }
  EXPECT_TRUE(fs::is_symlink(prefix_ + "/bin/colmap"));
  EXPECT_EQ(fs::read_symlink(prefix_ + "/bin/colmap").string(), "colmap-fvs");
  EXPECT_TRUE(fs::is_symlink(prefix_ + "/lib/colmap-fvs/bin/colmap"));
  EXPECT_TRUE(fs::equivalent(prefix_ + "/lib/colmap-fvs/bin/colmap",
                             prefix_ + "/bin/colmap-fvs"));
  // Every shipped weight file has its card beside it, installed together.
  for (const auto& entry :
       fs::directory_iterator(std::string(FVS_SOURCE_DIR) + "/models")) {
    const std::string name = entry.path().filename().string();
    EXPECT_TRUE(fs::exists(prefix_ + "/share/colmap-fvs/models/" + name)) << name;
  }
}

// No RPATH/RUNPATH and no string in the installed binaries names the source or build tree
// (such a path would be looked up at run time, or leak into messages). Debug sections are
// left out of the search: a RelWithDebInfo build (the sanitized suite's) records its
// compilation folder there for debuggers, which nothing reads at run time.
TEST_F(InstallTest, BinariesDoNotReferToTheSourceOrBuildTree) {
  for (const char* binary : {"bin/colmap-fvs", "bin/fvs_train_main"}) {
    const std::string path = prefix_ + "/" + binary;
    std::string dynamic;
    ASSERT_EQ(RunShell("readelf -d " + Quote(path), &dynamic), 0);
    EXPECT_EQ(dynamic.find("RPATH"), std::string::npos) << binary << "\n" << dynamic;
    EXPECT_EQ(dynamic.find("RUNPATH"), std::string::npos) << binary << "\n" << dynamic;
    const std::string loaded = prefix_ + "/without-debug-sections";
    ASSERT_EQ(
        RunShell("strip --strip-debug -o " + Quote(loaded) + " " + Quote(path), nullptr),
        0);
    for (const std::string& tree :
         {std::string(FVS_SOURCE_DIR), std::string(FVS_BINARY_DIR)}) {
      std::string hits;
      RunShell("grep -a -o -F " + Quote(tree) + " " + Quote(loaded) + " | head -n 3",
               &hits);
      EXPECT_EQ(hits, "") << binary << " names " << tree;
    }
  }
}

TEST_F(InstallTest, InstalledFrontDoorGeneratesAndRendersAway) {
  TempDir work;
  std::string output;
  ASSERT_EQ(
      RunInstalled(work.path(),
                   prefix_ + "/bin/colmap view_synthesis_synthetic --output_path ws "
                             "--SyntheticScene.num_views 6 --SyntheticScene.width 96 "
                             "--SyntheticScene.height 72 "
                             "--SyntheticScene.write_proxy_mesh 1",
                   &output),
      0)
      << output;
  ASSERT_TRUE(fs::exists(work / "ws/meshed-delaunay.ply")) << output;
  ASSERT_EQ(RunInstalled(work.path(),
                         prefix_ + "/bin/colmap view_synthesis --workspace_path ws "
                                   "--output_path ulr --method ulr --orbit 2",
                         &output),
            0)
      << output;
  int images = 0;
  for (const auto& entry : fs::directory_iterator(work / "ulr")) {
    images += entry.path().extension() == ".png";
  }
  EXPECT_EQ(images, 2) << output;

  // Weights under <prefix>/share/colmap-fvs/models are found without --model_path ...
  const std::string shipped = prefix_ + "/share/colmap-fvs/models/fvs_agg.safetensors";
  SaveRandomModel(shipped, "fvs_agg");
  const std::string render_agg = prefix_ +
                                 "/bin/colmap view_synthesis --workspace_path ws "
                                 "--output_path agg --method fvs_agg --orbit 1";
  ASSERT_EQ(RunInstalled(work.path(), render_agg, &output), 0) << output;
  EXPECT_NE(output.find("using the shipped model " + shipped), std::string::npos)
      << output;
  // ... and $FVS_MODEL_DIR comes first.
  const std::string own = work / "own_models/fvs_agg.safetensors";
  SaveRandomModel(own, "fvs_agg");
  ASSERT_EQ(RunInstalled(work.path(), render_agg, &output,
                         "FVS_MODEL_DIR=" + Quote(work / "own_models")),
            0)
      << output;
  EXPECT_NE(output.find("using the shipped model " + own), std::string::npos) << output;
  fs::remove(shipped);
}

// The installed front door finds the real COLMAP by itself: with its own bin/ first on
// the PATH (bin/colmap is the front door, marked), and as a user's unmarked `colmap` link
// to bin/colmap-fvs (the Debian layout: /usr/bin holds Debian's colmap, no marker).
TEST_F(InstallTest, InstalledFrontDoorFindsTheRealColmap) {
  if (!fs::exists(RealColmapBinary())) GTEST_SKIP() << "no COLMAP installed";
  TempDir work;
  fs::create_directories(work / "mine");
  fs::create_symlink(prefix_ + "/bin/colmap-fvs", work / "mine/colmap");
  const std::string real_dir = fs::path(RealColmapBinary()).parent_path().string();
  for (const std::string& run :
       {"PATH=" + prefix_ + "/bin:" + real_dir + ":/usr/bin:/bin " + prefix_ +
            "/bin/colmap help",
        "PATH=" + work.path() + "/mine:" + real_dir + ":/usr/bin:/bin " + work.path() +
            "/mine/colmap help",
        "PATH=" + prefix_ + "/lib/colmap-fvs/bin:" + real_dir +
            ":/usr/bin:/bin colmap help"}) {
    std::string output;
    EXPECT_EQ(RunInstalled(work.path(), run, &output), 0) << run << "\n" << output;
    EXPECT_NE(output.find("feature_extractor"), std::string::npos) << run << "\n"
                                                                   << output;
    EXPECT_NE(output.find("view_synthesis_prepare"), std::string::npos) << run << "\n"
                                                                        << output;
  }
}

}  // namespace
}  // namespace fvs::testing
