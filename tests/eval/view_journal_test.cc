// The journal of finished views (eval/view_journal.h): a kept row comes back exactly,
// n/a included; other settings or --overwrite empty it; a damaged entry is not taken.
#include "fvs/eval/view_journal.h"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>

#include "support/test_support.h"

namespace fvs::eval {
namespace {

ViewResult Row(const std::string& target) {
  ViewResult r;
  r.scene = "room";
  r.config.method = "ulr";
  r.config.num_sources = 3;
  r.protocol = "holdout";
  r.target = target;
  r.geometry_holdout = true;
  r.psnr = 24.123456789012345;
  r.ssim = 0.1 + 0.2;  // not a short decimal
  r.seconds = 1.0 / 3.0;
  r.sources_used = 3;
  r.width = 40;
  r.height = 30;
  return r;  // lpips and the pixel origins stay n/a
}

TEST(ViewJournal, KeepsRowsExactlyAndThumbnails) {
  testing::TempDir dir;
  Image thumbnail(4, 3, 3);
  for (size_t i = 0; i < thumbnail.data.size(); ++i) thumbnail.data[i] = 0.1f * i / 7.f;
  {
    const ViewJournal journal(dir / "views", "settings A", false);
    journal.Record(Row("sub/a b.png"), thumbnail);
    ViewResult failed = Row("c.png");
    failed.error = "cannot read the photo";
    journal.Record(failed, Image());
  }
  const ViewJournal journal(dir / "views", "settings A", false);
  ViewResult r;
  Image kept;
  ASSERT_TRUE(journal.Find(Row("x").config, "sub/a b.png", &r, &kept));
  const ViewResult expected = Row("sub/a b.png");
  EXPECT_EQ(r.psnr, expected.psnr);
  EXPECT_EQ(r.ssim, expected.ssim);
  EXPECT_EQ(r.seconds, expected.seconds);
  EXPECT_TRUE(std::isnan(r.lpips));
  EXPECT_TRUE(std::isnan(r.mesh_pixels));
  EXPECT_EQ(r.target, "sub/a b.png");
  EXPECT_TRUE(r.geometry_holdout);
  EXPECT_EQ(r.width, 40);
  EXPECT_EQ(kept.data, thumbnail.data);
  // A failed view is not kept; another configuration has its own entries.
  EXPECT_FALSE(journal.Find(Row("x").config, "c.png", &r, nullptr));
  EvalConfig other = Row("x").config;
  other.num_sources = 2;
  EXPECT_FALSE(journal.Find(other, "sub/a b.png", &r, nullptr));
}

TEST(ViewJournal, OtherSettingsOrOverwriteStartAfresh) {
  testing::TempDir dir;
  ViewResult r;
  const EvalConfig config = Row("x").config;
  ViewJournal(dir / "views", "settings A", false).Record(Row("a.png"), Image());
  EXPECT_TRUE(
      ViewJournal(dir / "views", "settings A", false).Find(config, "a.png", &r, nullptr));
  EXPECT_FALSE(
      ViewJournal(dir / "views", "settings B", false).Find(config, "a.png", &r, nullptr));
  ViewJournal(dir / "views", "settings B", false).Record(Row("a.png"), Image());
  EXPECT_FALSE(
      ViewJournal(dir / "views", "settings B", true).Find(config, "a.png", &r, nullptr));
}

TEST(ViewJournal, DamagedEntryIsEvaluatedAgain) {
  testing::TempDir dir;
  const ViewJournal journal(dir / "views", "s", false);
  journal.Record(Row("a.png"), Image());
  const std::string entry = dir / ("views/" + Row("x").config.Slug() + "/a.png.json");
  ASSERT_TRUE(std::filesystem::exists(entry));
  const std::string text = testing::ReadTextFile(entry);
  testing::WriteTextFile(entry, text.substr(0, text.size() / 2));
  ViewResult r;
  EXPECT_FALSE(journal.Find(Row("x").config, "a.png", &r, nullptr));
  testing::WriteTextFile(entry, "{\"target\": 3}");
  EXPECT_FALSE(journal.Find(Row("x").config, "a.png", &r, nullptr));
}

}  // namespace
}  // namespace fvs::eval
