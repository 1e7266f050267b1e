#include "agnocast/inspect.hpp"

#include <gtest/gtest.h>

#include <string>

#include "agnocast/errors.hpp"
#include "agnocast/supervise.hpp"

namespace agnocast {
namespace {

// Natively there is no module: every entry point must say so the same way.
class WithoutModule : public ::testing::Test {
 protected:
  void SetUp() override {
    if (module_loaded()) GTEST_SKIP() << "/dev/agnocast exists here";
  }
};

TEST_F(WithoutModule, VersionIsAbsent) { EXPECT_FALSE(module_version()); }

TEST_F(WithoutModule, QueriesThrowModuleNotLoadedWithAdvice) {
  try {
    list_topics();
    ADD_FAILURE() << "list_topics worked without a module";
  } catch (const ModuleNotLoaded& error) {
    const std::string message = error.what();
    EXPECT_NE(message.find("/dev/agnocast"), std::string::npos) << message;
    EXPECT_NE(message.find("systemctl start agnocastd"), std::string::npos) << message;
  }
  EXPECT_THROW(topic_info("/chatter"), ModuleNotLoaded);
  EXPECT_THROW(list_processes(), ModuleNotLoaded);
  EXPECT_THROW(ExitRecordReader{}, ModuleNotLoaded);
}

TEST(LibraryVersion, IsTheProjectVersionAndCompatibilityIsMajorMinor) {
  EXPECT_EQ(library_version.to_string(), std::string(library_version_string));
  EXPECT_TRUE(is_compatible({library_version.major, library_version.minor, 99}));
  EXPECT_FALSE(is_compatible({library_version.major, library_version.minor + 1, 0}));
  EXPECT_FALSE(is_compatible({library_version.major + 1, library_version.minor, 0}));
}

}  // namespace
}  // namespace agnocast
