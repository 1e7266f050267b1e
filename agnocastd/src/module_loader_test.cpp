#include "module_loader.hpp"

#include <gtest/gtest.h>

namespace agnocastd {
namespace {

TEST(VersionProblem, MajorAndMinorMustMatch) {
  EXPECT_EQ(version_problem({0, 1, 7}, {0, 1, 0}), "");
  EXPECT_EQ(version_problem({0, 2, 0}, {0, 1, 0}),
            "agnocast.ko 0.2.0 is incompatible with agnocastd 0.1.0 (major.minor must match): "
            "install the module of this release");
  EXPECT_NE(version_problem({1, 1, 0}, {0, 1, 0}), "");
}

TEST(ModuleParameterString, JoinsNameValuePairs) {
  EXPECT_EQ(module_parameter_string({}), "");
  EXPECT_EQ(module_parameter_string({{"pool_size", "1024"}, {"pool_count", "8"}}),
            "pool_count=8 pool_size=1024");
}

}  // namespace
}  // namespace agnocastd
