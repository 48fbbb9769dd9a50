#include "fvs/util/shard.h"

#include <gtest/gtest.h>

#include <set>

#include "fvs/util/error.h"

namespace fvs {
namespace {

TEST(Shard, ParsesAndDefaultsToEverything) {
  EXPECT_TRUE(Shard::Parse("").IsAll());
  const Shard s = Shard::Parse("2/5");
  EXPECT_EQ(s.index, 2);
  EXPECT_EQ(s.count, 5);
  EXPECT_EQ(s.ToString(), "2/5");
  EXPECT_TRUE(s.Contains(7));
  EXPECT_FALSE(s.Contains(8));
}

TEST(Shard, ShardsCoverEveryItemExactlyOnce) {
  for (int n : {1, 2, 3, 7, 40}) {
    std::multiset<int> seen;
    for (int i = 0; i < n; ++i) {
      for (int item :
           Shard::Parse(std::to_string(i) + "/" + std::to_string(n)).Items(23)) {
        seen.insert(item);
      }
    }
    ASSERT_EQ(seen.size(), 23u) << n;
    for (int item = 0; item < 23; ++item) EXPECT_EQ(seen.count(item), 1u);
  }
  EXPECT_TRUE(Shard::Parse("5/6").Items(3).empty());
}

TEST(Shard, RejectsMalformedSpecs) {
  for (const char* bad :
       {"3", "3/3", "-1/3", "1/0", "a/b", "1/ 2", "1/2/3", "/2", "1/"}) {
    try {
      Shard::Parse(bad);
      ADD_FAILURE() << bad;
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find("--shard"), std::string::npos) << bad;
    }
  }
}

}  // namespace
}  // namespace fvs
