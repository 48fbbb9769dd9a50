#include "fvs/util/option_manager.h"

#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "fvs/util/error.h"

namespace fvs {
namespace {

// argv as the front door passes it: program, command, options...
struct Argv {
  explicit Argv(std::vector<std::string> a) : args(std::move(a)) {
    for (auto& s : args) ptrs.push_back(s.data());
  }
  int argc() const { return static_cast<int>(ptrs.size()); }
  char** argv() { return ptrs.data(); }
  std::vector<std::string> args;
  std::vector<char*> ptrs;
};

struct Values {
  std::string path;
  std::string backend = "auto";
  int k = 5;
  double tolerance = 0.1;
  bool flag = false;
};

OptionManager MakeOptions(Values* v) {
  OptionManager options("view_synthesis_test", "A test command.");
  options.AddRequired("workspace_path", &v->path, "workspace");
  options.AddDefault("Stereo.backend", &v->backend, "backend");
  options.AddDefault("num_sources", &v->k, "K");
  options.AddDefault("Render.tolerance", &v->tolerance, "tolerance");
  options.AddDefault("flag", &v->flag, "a flag");
  return options;
}

TEST(OptionManager, ParsesColmapStyleOptions) {
  Values v;
  OptionManager options = MakeOptions(&v);
  Argv a({"colmap", "view_synthesis_test", "--workspace_path", "/w", "--Stereo.backend",
          "builtin", "--num_sources", "7", "--Render.tolerance=0.25", "--flag", "true"});
  ASSERT_TRUE(options.Parse(a.argc(), a.argv()));
  EXPECT_EQ(v.path, "/w");
  EXPECT_EQ(v.backend, "builtin");
  EXPECT_EQ(v.k, 7);
  EXPECT_DOUBLE_EQ(v.tolerance, 0.25);
  EXPECT_TRUE(v.flag);
  EXPECT_NE(options.Describe().find("--num_sources 7"), std::string::npos);
}

TEST(OptionManager, DefaultsStayWhenNotGiven) {
  Values v;
  OptionManager options = MakeOptions(&v);
  Argv a({"colmap", "view_synthesis_test", "--workspace_path", "w"});
  ASSERT_TRUE(options.Parse(a.argc(), a.argv()));
  EXPECT_EQ(v.backend, "auto");
  EXPECT_EQ(v.k, 5);
}

TEST(OptionManager, HelpReturnsFalseAndListsOptions) {
  Values v;
  OptionManager options = MakeOptions(&v);
  Argv a({"colmap", "view_synthesis_test", "-h"});
  testing::internal::CaptureStdout();
  EXPECT_FALSE(options.Parse(a.argc(), a.argv()));
  const std::string out = testing::internal::GetCapturedStdout();
  EXPECT_NE(out.find("--Stereo.backend"), std::string::npos);
  EXPECT_NE(out.find("(required)"), std::string::npos);
}

TEST(OptionManager, ShortFormsAndBooleanWords) {
  Values v;
  OptionManager options = MakeOptions(&v);
  Argv a({"colmap", "view_synthesis_test", "--workspace_path", "w", "--backend", "colmap",
          "--tolerance=0.5", "--flag", "Yes"});
  ASSERT_TRUE(options.Parse(a.argc(), a.argv()));
  EXPECT_EQ(v.backend, "colmap");
  EXPECT_DOUBLE_EQ(v.tolerance, 0.5);
  EXPECT_TRUE(v.flag);
  Argv off({"colmap", "view_synthesis_test", "--workspace_path", "w", "--flag", "off"});
  ASSERT_TRUE(options.Parse(off.argc(), off.argv()));
  EXPECT_FALSE(v.flag);

  // Two sections with the same option: the short form is ambiguous.
  double other = 0;
  options.AddDefault("Stereo.tolerance", &other, "another tolerance");
  Argv ambiguous({"colmap", "view_synthesis_test", "--workspace_path", "w", "--tolerance",
                  "1"});
  try {
    options.Parse(ambiguous.argc(), ambiguous.argv());
    ADD_FAILURE() << "no error for an ambiguous short form";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("ambiguous"), std::string::npos) << e.what();
  }
}

TEST(OptionManager, ProgramNamesUsageAndErrors) {
  Values v;
  OptionManager options = MakeOptions(&v);
  options.SetProgram("fvs_train_main");
  Argv a({"fvs_train_main", "-h"});
  testing::internal::CaptureStdout();
  EXPECT_FALSE(options.Parse(a.argc(), a.argv(), 1));
  EXPECT_NE(testing::internal::GetCapturedStdout().find("Usage: fvs_train_main [options]"),
            std::string::npos);
  Argv bad({"fvs_train_main", "--nope", "1"});
  try {
    options.Parse(bad.argc(), bad.argv(), 1);
    ADD_FAILURE() << "no error";
  } catch (const Error& e) {
    EXPECT_EQ(std::string(e.what()).rfind("fvs_train_main", 0), 0u) << e.what();
  }
}

TEST(OptionManager, BadInputThrowsOneLine) {
  const std::vector<std::vector<std::string>> bad = {
      {"colmap", "c"},                                                 // missing required
      {"colmap", "c", "--workspace_path", "w", "--unknown", "1"},      // unknown option
      {"colmap", "c", "--workspace_path"},                             // missing value
      {"colmap", "c", "--workspace_path", "w", "--num_sources", "x"},  // not an int
      {"colmap", "c", "--workspace_path", "w", "--num_sources", "99999999999"},
      {"colmap", "c", "--workspace_path", "w", "--Render.tolerance", "nan"},
      {"colmap", "c", "--workspace_path", "w", "--flag", "maybe"},
      {"colmap", "c", "stray"},
  };
  for (const auto& args : bad) {
    Values v;
    OptionManager options = MakeOptions(&v);
    Argv a(args);
    try {
      options.Parse(a.argc(), a.argv());
      ADD_FAILURE() << "no error for " << args.back();
    } catch (const Error& e) {
      EXPECT_EQ(std::string(e.what()).find('\n'), std::string::npos);
      EXPECT_NE(std::string(e.what()).find("view_synthesis_test"), std::string::npos);
    }
  }
}

}  // namespace
}  // namespace fvs
