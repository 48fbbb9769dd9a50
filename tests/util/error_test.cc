// Errors reach the user as one line, whatever a library put into the message.
#include "fvs/util/error.h"

#include <gtest/gtest.h>

namespace fvs {
namespace {

TEST(Error, MessagesFromOtherLibrariesBecomeOneLine) {
  EXPECT_STREQ(
      Error("a.png", "cannot read image (Read error\nPNG read error: oFFs)\n").what(),
      "a.png: cannot read image (Read error; PNG read error: oFFs)");
  EXPECT_STREQ(Error("\r\nfirst\r\n\r\nsecond").what(), "first; second");
  EXPECT_STREQ(Error("", "plain").what(), "plain");
  EXPECT_STREQ(Error("").what(), "");
}

TEST(Error, RequireThrowsOnlyWhenTheConditionFails) {
  EXPECT_NO_THROW(Require(true, "x", "y"));
  try {
    Require(false, "model.json", "no \"variant\" string");
    FAIL() << "no error thrown";
  } catch (const Error& e) {
    EXPECT_STREQ(e.what(), "model.json: no \"variant\" string");
  }
}

}  // namespace
}  // namespace fvs
