// FVS_CHECK: a failed internal invariant is one fvs::Error line naming the source file
// and line, and the condition; a holding one costs nothing and throws nothing.
#include "fvs/util/check.h"

#include <gtest/gtest.h>

namespace fvs {
namespace {

TEST(Check, FailureNamesFileLineAndCondition) {
  const int line = __LINE__ + 2;
  try {
    FVS_CHECK(1 + 1 == 3, "arithmetic broke");
    FAIL() << "no throw";
  } catch (const Error& e) {
    const std::string message = e.what();
    EXPECT_NE(message.find("internal error at "), std::string::npos) << message;
    EXPECT_NE(message.find("check_test.cc:" + std::to_string(line)), std::string::npos)
        << message;
    EXPECT_NE(message.find("'1 + 1 == 3'"), std::string::npos) << message;
    EXPECT_NE(message.find("arithmetic broke"), std::string::npos) << message;
    EXPECT_EQ(message.find('\n'), std::string::npos);
  }
  int evaluated = 0;
  FVS_CHECK(++evaluated == 1, "evaluated once");
  EXPECT_EQ(evaluated, 1);
}

}  // namespace
}  // namespace fvs
