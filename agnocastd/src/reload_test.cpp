#include "reload.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

namespace agnocastd {
namespace {

using ::testing::ElementsAre;
using ::testing::IsEmpty;

TEST(RestartOnlyDifferences, NoneWhenOnlyRunTimeKeysChange) {
  const Config in_force = parse_config(R"({"module_parameters": {"pool_size": 1}})");
  const Config next = parse_config(R"({"module_parameters": {"pool_size": 1},
    "log_level": "debug", "sweep_interval_s": 1, "mqueue": {"msg_max": 64},
    "access": {"default": "deny"}})");
  EXPECT_THAT(restart_only_differences(in_force, next), IsEmpty());
}

TEST(RestartOnlyDifferences, NamesEachChangedModuleParameter) {
  const Config in_force =
      parse_config(R"({"module_parameters": {"pool_size": 1, "max_topics": 8, "gone": true}})");
  const Config next = parse_config(R"({"module_parameters": {"pool_size": 2, "max_topics": 8,
    "added": "x"}, "module_path": "/a.ko", "device_timeout_s": 1})");
  EXPECT_THAT(
      restart_only_differences(in_force, next),
      ElementsAre("module_parameters.added changed from unset to 'x': the loaded module keeps "
                  "its value until it is reloaded",
                  "module_parameters.gone changed from '1' to unset: the loaded module keeps its "
                  "value until it is reloaded",
                  "module_parameters.pool_size changed from '1' to '2': the loaded module keeps "
                  "its value until it is reloaded",
                  "module_path changed from unset to '/a.ko': used only when agnocastd loads the "
                  "module",
                  "device_timeout_s changed: used only when agnocastd starts"));
}

}  // namespace
}  // namespace agnocastd
